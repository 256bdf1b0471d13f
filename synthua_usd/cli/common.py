"""What every ``synthua`` subcommand module shares: exit statuses and the class-map option's loader."""

from __future__ import annotations

import math
from pathlib import Path

import click

from synthua_usd.cli.failures import EXIT_FINDINGS, EXIT_INPUT, EXIT_OK  # noqa: F401 (re-exported)


def load_class_map(path: Path | None):
    """The class map at ``path``, or the bundled one."""
    from synthua_usd.taxonomy import ClassMap

    return ClassMap.load(path) if path else ClassMap.default()


class FiniteFloat(click.ParamType):
    """A float option within [low, high] (``open_low``: low itself excluded); NaN and infinities refused,
    with the range in the message (click's FloatRange lets NaN through)."""

    name = "number"

    def __init__(self, low: float, high: float, open_low: bool = False) -> None:
        self.low, self.high, self.open_low = low, high, open_low

    def convert(self, value, param, ctx):
        if isinstance(value, float):
            number = value
        else:
            try:
                number = float(value)
            except (TypeError, ValueError):
                self.fail(f"{value!r} is not a number", param, ctx)
        low_ok = number > self.low if self.open_low else number >= self.low
        if not (math.isfinite(number) and low_ok and number <= self.high):
            bracket = "(" if self.open_low else "["
            self.fail(f"{value!r} is not a finite number in {bracket}{self.low:g}, {self.high:g}]", param, ctx)
        return number

    def get_metavar(self, param, ctx=None) -> str:
        return "NUMBER"
