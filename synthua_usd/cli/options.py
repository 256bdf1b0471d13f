"""Numeric option types built from the library's stated ranges (:class:`synthua_usd.model.ranges.Range`).

click's ``FloatRange`` lets NaN through (every comparison with NaN is false) and accepts infinities when a
bound is open; :class:`InRange` refuses both, and its message names the option as typed and states the
range, e.g. ``synthua survey flight-plan: --altitude-m: 'nan'; expected a number in [1, 20000] m``.
"""

from __future__ import annotations

import click

from synthua_usd.core.errors import echo
from synthua_usd.model.ranges import SEED, Range


class InRange(click.ParamType):
    """A float (or, for an integer range, an int) inside ``allowed``."""

    def __init__(self, allowed: Range) -> None:
        self.allowed = allowed
        self.name = "integer" if allowed.integer else "float"

    def get_metavar(self, param, ctx=None) -> str:  # click < 8.2 passes only param
        left = "(" if self.allowed.low_open else "["
        return f"{left}{self.allowed.bound(self.allowed.low)}..{self.allowed.bound(self.allowed.high)}]"

    def convert(self, value, param, ctx):
        if isinstance(value, bool):
            self.fail(f"{value!r}; expected {self.allowed}", param, ctx)
        if isinstance(value, (int, float)):
            number = value
        else:
            text = str(value).strip()
            try:
                number = int(text, 10) if self.allowed.integer else float(text)
            except ValueError:
                self.fail(f"'{echo(text)}' is not {'an integer' if self.allowed.integer else 'a number'}; "
                          f"expected {self.allowed}", param, ctx)
        if not self.allowed.contains(number):
            shown = f"{number:g}" if isinstance(number, float) else str(number)
            self.fail(f"{echo(shown)}; expected {self.allowed}", param, ctx)
        return int(number) if self.allowed.integer else float(number)


#: Crowd options shared by ``agents populate`` and ``twin import --populate`` (defaults: CrowdParams's).
DENSITY = Range(0.0, 1e6, "persons/m²", low_open=True)
AID_SHARE = Range(0.0, 1.0)


def seed_option(help: str, default: int | None = 0):
    """The ``--seed`` option of every command: an integer of :data:`synthua_usd.model.ranges.SEED`, the one seed
    range (``synthua randomise`` prints ``synthua render --seed`` with a dataset image's seed)."""
    return click.option("--seed", type=InRange(SEED), default=default, show_default=default is not None, help=help)
