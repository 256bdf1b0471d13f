"""Stated ranges of numbers a user gives: command options, parameters, and numeric fields of input files.

Every number synthua takes from outside has a finite range, and a refusal states it:

    blocks.geojson: features[3].properties.height: 1e+308; expected a number in (0, 1000] m

The module that owns a parameter owns its :class:`Range` (the importers, :mod:`synthua_usd.model.survey`); the
command line builds its option types from the same objects (:mod:`synthua_usd.cli.options`), so that an
option and the library check can never disagree.
"""

from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass

from synthua_usd.core.errors import InputError, echo


@dataclass(frozen=True)
class Range:
    """A finite interval, closed unless ``low_open``; ``unit`` is printed after it (``m``, ``deg``, ``px``)."""

    low: float
    high: float
    unit: str = ""
    low_open: bool = False
    integer: bool = False

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low <= self.high):
            raise ValueError(f"a range needs finite low <= high, but was [{self.low}, {self.high}]")

    def bound(self, value: float) -> str:
        """An end of the range as messages show it: integers whole (4294967295, not 4.29497e+09), else %g."""
        return str(int(value)) if self.integer else f"{value:g}"

    def __str__(self) -> str:
        kind = "an integer" if self.integer else "a number"
        left = "(" if self.low_open else "["
        return f"{kind} in {left}{self.bound(self.low)}, {self.bound(self.high)}]" + (f" {self.unit}" if self.unit else "")

    def contains(self, value: float) -> bool:
        """Finite and inside (NaN, infinities and non-numbers never are)."""
        try:
            if isinstance(value, bool) or not math.isfinite(value):
                return False
        except (TypeError, OverflowError):  # not a number, or an int beyond double range
            return False
        above = value > self.low if self.low_open else value >= self.low
        return above and value <= self.high and (not self.integer or float(value).is_integer())

    def check(self, value: float, where: str) -> float:
        """``value`` when it is inside; else :class:`InputError` ``where: value; expected <range>``."""
        if not self.contains(value):
            raise InputError(f"{where}: {_show(value)}; expected {self}")
        return value


def _show(value) -> str:
    """A value as a message shows it: numbers as %g, text quoted, other JSON values by kind."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return f"{str(value).lower()} (a boolean)"
    if isinstance(value, numbers.Integral):
        return echo(int(value))
    if isinstance(value, numbers.Real):
        return f"{float(value):g}"
    if isinstance(value, str):
        return f"'{echo(value)}'"
    return {list: "an array", dict: "an object"}.get(type(value), type(value).__name__)


#: Every seed synthua takes, the one range of every command's --seed and every seed of a config
#: (``schemas/generate.schema.json`` states the same maximum; a test holds it to this): an unsigned 32-bit integer,
#: what NumPy's legacy seeding (Ultralytics') takes. ``synthua randomise`` prints ``synthua render --seed`` with a
#: dataset image's seed, so the two must accept the same seeds; Mitsuba's 32-bit sampler seeds are derived from it
#: (:func:`synthua_usd.model.render_config.sampler_seed`).
SEED = Range(0, 2**32 - 1, integer=True)

#: Projected coordinates (metres) of any input (CityJSON, GeoJSON with a CRS, meshes, point clouds, GCPs):
#: UTM northings reach 1e7, so 1e8 leaves room and keeps squares and sums far from overflow.
COORDINATE = Range(-1e8, 1e8, "m")

#: A decimal number as text: no NaN, infinity, hexadecimal or underscores.
_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?\Z")


def number_field(value, where: str, allowed: Range, text: bool = False) -> float:
    """A numeric field of an input file as a float, checked against ``allowed``.

    JSON numbers are accepted; booleans never (``true`` is no height); numeric strings only when ``text``
    (GeoJSON properties from OpenStreetMap carry ``"height": "12.5"``). Anything else, or a value outside
    ``allowed``, raises :class:`InputError` naming ``where`` and the range."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, str)) or (isinstance(value, str) and not text):
        raise InputError(f"{where}: {_show(value)}; expected {allowed}")
    if isinstance(value, str) and not _DECIMAL.match(value.strip()):
        raise InputError(f"{where}: {_show(value)} is not a number; expected {allowed}")
    try:
        number = float(value)
    except OverflowError:  # an int beyond double range
        number = math.inf
    if not allowed.contains(number):
        raise InputError(f"{where}: {_show(value)}; expected {allowed}")
    return number

