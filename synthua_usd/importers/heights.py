"""Building heights from footprint properties or OpenStreetMap tags: lengths with units, and the order of
sources a height is taken from.

OpenStreetMap (Simple 3D Buildings) measures ``height`` from the ground to the top of the roof, and
``min_height`` from the ground to the bottom of a raised part; both in metres unless a unit is written.
Real extracts write ``'12'``, ``'12.13 m'``, ``'12,5'`` (a decimal comma), ``'40 ft'`` or ``40'6"``, and most
buildings carry no height at all (292 of 446 in one city). :func:`building_height` takes, in this order:

1. ``height`` (:data:`SOURCES` ``height``);
2. ``building:levels`` (or ``levels``) x the storey height, plus the roof: ``roof:height``, else
   ``roof:levels`` x the storey height (``building:levels``);
3. ``roof:height`` where it is the only height given: the building is as tall as its roof
   (``roof:height``);
4. the default height (``default``).

The base is ``min_height``, else ``building:min_level`` x the storey height, else 0; the top is measured from
the ground in every case. A value that is present but not a length in its range (``'tall'``, ``-5``,
``1e308``, ``true``) is skipped for the next source and recorded (:attr:`BuildingHeight.ignored`), or, with
``strict``, refused; so is a building that needs the default.
"""

from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass

from synthua_usd.core.errors import InputError
from synthua_usd.importers.limits import HEIGHT, LEVELS, MIN_BLOCK_HEIGHT_M, MIN_HEIGHT, ROOF_LEVELS
from synthua_usd.model.ranges import Range, _show

#: The sources of a building's top, in the order they are tried.
SOURCES = ("height", "building:levels", "roof:height", "default")
HEIGHT_KEYS = ("height",)
LEVEL_KEYS = ("building:levels", "levels")
#: Metres per unit of the length units OpenStreetMap writes (``'`` and ``"``: feet and inches).
UNITS_M = {"": 1.0, "m": 1.0, "metre": 1.0, "metres": 1.0, "meter": 1.0, "meters": 1.0, "cm": 0.01, "mm": 0.001,
           "km": 1000.0, "ft": 0.3048, "feet": 0.3048, "foot": 0.3048, "'": 0.3048, "in": 0.0254, '"': 0.0254}
_NUMBER = r"[+-]?(?:[0-9]+(?:[.,][0-9]*)?|[.,][0-9]+)(?:[eE][+-]?[0-9]+)?"
_LENGTH = re.compile(rf"({_NUMBER})\s*([a-z]*|'|\")\Z")
_PLAIN = re.compile(rf"{_NUMBER}\Z")
_FEET_INCHES = re.compile(rf"({_NUMBER})\s*'\s*({_NUMBER})\s*\"\Z")


def parse_length(value) -> float | None:
    """``value`` in metres: a number (metres), or text such as ``'12'``, ``'12.13 m'``, ``'12,5'``, ``'40 ft'``,
    ``'40\\''`` or ``'40\\'6"'``; None for anything else (booleans, other text, other JSON values). The result
    may be any float, infinities included: ranges are the caller's."""
    if isinstance(value, bool):
        return None
    if isinstance(value, numbers.Real):
        try:
            return float(value)
        except OverflowError:  # an integer beyond double range
            return math.inf
    if not isinstance(value, str):
        return None
    text = value.strip().lower()
    both = _FEET_INCHES.match(text)
    if both:
        return _number(both.group(1)) * UNITS_M["ft"] + _number(both.group(2)) * UNITS_M["in"]
    found = _LENGTH.match(text)
    if not found or found.group(2) not in UNITS_M:
        return None
    return _number(found.group(1)) * UNITS_M[found.group(2)]


def _number(text: str) -> float:
    """A decimal number with a decimal point or comma ('12,5' is 12.5)."""
    try:
        return float(text.replace(",", "."))
    except OverflowError:
        return math.inf


@dataclass(frozen=True)
class BuildingHeight:
    """A building's ``base_m`` and ``top_m`` (metres above the ground), the :data:`SOURCES` entry its top came
    from and the messages of values that were skipped."""

    base_m: float
    top_m: float
    source: str
    ignored: tuple[str, ...] = ()

    def as_report(self) -> dict:
        return {"height_m": self.top_m, "min_height_m": self.base_m, "height_source": self.source,
                **({"ignored": list(self.ignored)} if self.ignored else {})}


class _Tags:
    """Reads one building's values, skipping (or, when strict, refusing) those that are not lengths in range."""

    def __init__(self, tags: dict, where: str, field: str, strict: bool) -> None:
        self.tags, self.where, self.field, self.strict = tags, where, field, strict
        self.ignored: list[str] = []

    def given(self, key: str) -> bool:
        return self.tags.get(key) not in (None, "")

    def reject(self, message: str) -> None:
        if self.strict:
            raise InputError(f"{self.where}: {message}")
        self.ignored.append(message)

    def length(self, key: str, allowed: Range) -> float | None:
        if not self.given(key):
            return None
        value = self.tags[key]
        metres = parse_length(value)
        if metres is None:
            self.reject(f"{self.field}{key}: {_show(value)} is not a length; expected {allowed} (a number of metres, "
                        f"or with a unit: '12.5 m', '12,5', '40 ft')")
            return None
        if not allowed.contains(metres):
            self.reject(f"{self.field}{key}: {_show(value)}; expected {allowed}")
            return None
        return metres

    def count(self, key: str, allowed: Range) -> float | None:
        """A number of levels: a number, or text of a plain number (no unit)."""
        if not self.given(key):
            return None
        value = self.tags[key]
        plain = isinstance(value, numbers.Real) or (isinstance(value, str) and _PLAIN.match(value.strip()))
        number = parse_length(value) if plain else None
        if number is None or not allowed.contains(number):
            self.reject(f"{self.field}{key}: {_show(value)}; expected {allowed}")
            return None
        return number


def building_height(tags: dict, where: str, storey_height_m: float, default_height_m: float,
                    field: str = "properties.", strict: bool = False) -> BuildingHeight:
    """The base and top (metres) of one building from its ``tags`` (GeoJSON properties or OSM tags, numbers or
    text), in the order of the module's docstring; ``where`` and ``field`` (``properties.`` or ``tag ``) name
    it in messages. With ``strict``, a value that is not a length in its range, or a building that has no
    height of its own, raises :class:`InputError`."""
    read = _Tags(tags, where, field, strict)
    base = read.length("min_height", MIN_HEIGHT)
    if base is None:
        min_level = read.count("building:min_level", ROOF_LEVELS)
        base = min_level * storey_height_m if min_level is not None else 0.0
    top, source = None, None
    for key in HEIGHT_KEYS:
        top = read.length(key, HEIGHT)
        if top is not None:
            source = "height"
            break
    roof = read.length("roof:height", MIN_HEIGHT) if top is None else None
    if top is None:
        for key in LEVEL_KEYS:
            levels = read.count(key, LEVELS)
            if levels is not None:
                roof_levels = read.count("roof:levels", ROOF_LEVELS) if roof is None else None
                top = levels * storey_height_m + (roof if roof is not None else (roof_levels or 0.0) * storey_height_m)
                if HEIGHT.contains(top):
                    source = "building:levels"
                    break
                read.reject(f"{field}{key}: {levels:g} levels x storey height {storey_height_m:g} m = {top:g} m; "
                            f"expected {HEIGHT}")
                top = None
    if top is None and roof is not None and roof > 0:
        top, source = base + roof, "roof:height"
    if top is None:
        if strict:
            raise InputError(f"{where}: no height; expected a 'height' (m), 'building:levels' or 'roof:height' "
                             f"{'property' if field.startswith('properties') else 'tag'} (without --strict, "
                             f"--default-height-m is used)")
        top, source = base + default_height_m, "default"
    if not top - base >= MIN_BLOCK_HEIGHT_M:
        read.reject(f"{field}min_height {base:g} m is not below the height {top:g} m; expected min_height at least "
                    f"{MIN_BLOCK_HEIGHT_M:g} m below the height")
        base = 0.0
    return BuildingHeight(base, top, source, tuple(read.ignored))


def heights_report(heights: dict[str, BuildingHeight], where: str, storey_height_m: float,
                   default_height_m: float) -> tuple[dict, list[dict]]:
    """The import report's ``heights`` (the storey and default heights, how many buildings took each source,
    and every building's height and source, keyed by its object path) and its findings: one for the
    buildings that took the default height, one for those with skipped values."""
    from synthua_usd.core.findings import Finding, Severity

    counts = {s: sum(h.source == s for h in heights.values()) for s in SOURCES}
    report = {"storey_height_m": storey_height_m, "default_height_m": default_height_m, "sources": counts,
              "buildings": {path: h.as_report() for path, h in heights.items()}}
    findings = []
    if counts["default"]:
        first = next(p for p, h in heights.items() if h.source == "default")
        findings.append(Finding(
            "building-height", where,
            f"{counts['default']} of {len(heights)} buildings (e.g. {first}) have no height, levels or roof "
            f"height; they are {default_height_m:g} m tall (--default-height-m); expected a height for every "
            f"building (import_report.json: heights.buildings)", Severity.WARNING).to_dict())
    skipped = {p: h.ignored for p, h in heights.items() if h.ignored}
    if skipped:
        first = next(iter(skipped))
        findings.append(Finding(
            "building-height", where,
            f"{len(skipped)} buildings have values that are not usable heights and were skipped for the next "
            f"source (e.g. {first}: {skipped[first][0]}); see heights.buildings.*.ignored", Severity.WARNING).to_dict())
    return report, findings
