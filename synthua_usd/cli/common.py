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


def parse_time_codes(ctx, param, values: tuple[str, ...]) -> tuple[float, ...]:
    """``--time-code 24 --time-code 1:48:8 --frame 1,12``: single time codes, comma lists, and START:END[:STEP]
    ranges with END included when the steps reach it."""
    out: list[float] = []
    for value in values:
        for item in value.split(","):
            item = item.strip()
            try:
                if ":" in item:
                    parts = [float(x) for x in item.split(":")]
                    if len(parts) not in (2, 3):
                        raise ValueError
                    start, end, step = parts[0], parts[1], parts[2] if len(parts) == 3 else 1.0
                    if not (all(map(math.isfinite, parts)) and step > 0 and end >= start):
                        raise ValueError
                    count = int(math.floor((end - start) / step + 1e-9)) + 1
                    if count > 100_000:
                        raise click.BadParameter(f"{item!r} holds {count} time codes; at most 100000", ctx, param)
                    out += [start + k * step for k in range(count)]
                else:
                    number = float(item)
                    if not math.isfinite(number):
                        raise ValueError
                    out.append(number)
            except ValueError:
                raise click.BadParameter(f"{item!r} is not a time code, a comma list or START:END[:STEP] with "
                                         f"finite numbers, STEP > 0 and END >= START", ctx, param) from None
    return tuple(dict.fromkeys(out))
