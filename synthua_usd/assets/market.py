"""The Sunday market (Feira do Largo da Ordem): tents, stands, tables, chairs, umbrellas."""

from __future__ import annotations

from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart


def tent(size: float = 3.0, height: float = 2.4, canvas: str = "CanvasWhite") -> list[TwinPart]:
    h = size / 2
    poles = [geo.box((x - 0.025, y - 0.025, 0.0), (x + 0.025, y + 0.025, height)) for x in (-h, h) for y in (-h, h)]
    roof = geo.merge(geo.box((-h - 0.05, -h - 0.05, height), (h + 0.05, h + 0.05, height + 0.05)),
                     geo.ramp(-h - 0.05, h + 0.05, -h - 0.05, 0.0, height + 0.05, height + 0.6, height + 0.05),
                     geo.ramp(-h - 0.05, h + 0.05, h + 0.05, 0.0, height + 0.05, height + 0.6, height + 0.05))
    return [TwinPart.of("Poles", geo.merge(*poles), "Iron"), TwinPart.of("Canvas", roof, canvas)]


def stand(length: float = 2.4) -> list[TwinPart]:
    """A market stall counter with goods on it."""
    l = length / 2
    goods = [geo.box((-0.3 + 0.05, y - 0.15, 0.92), (0.3 - 0.05, y + 0.15, 1.05)) for y in (-l + 0.4, 0.0, l - 0.4)]
    return [TwinPart.of("Counter", geo.box((-0.35, -l, 0.0), (0.35, l, 0.9)), "Wood"),
            TwinPart.of("Goods", geo.merge(*goods), "Goods")]


#: Height of a café table's top surface, metres above the ground.
TABLE_TOP_M = 0.745


def table(radius: float = 0.4) -> list[TwinPart]:
    return [TwinPart.of("Top", geo.cylinder((0, 0, TABLE_TOP_M - 0.015), radius, 0.03, sections=16), "PlasticWhite"),
            TwinPart.of("Leg", geo.merge(geo.cylinder((0, 0, 0.36), 0.025, 0.72, sections=8),
                                   geo.cylinder((0, 0, 0.01), 0.25, 0.02, sections=12)), "Iron")]


def chair() -> list[TwinPart]:
    legs = [geo.box((x - 0.015, y - 0.015, 0.0), (x + 0.015, y + 0.015, 0.45)) for x in (-0.2, 0.2) for y in (-0.2, 0.2)]
    return [TwinPart.of("Seat", geo.merge(geo.box((-0.22, -0.22, 0.45), (0.22, 0.22, 0.48)),
                                    geo.box((-0.22, -0.22, 0.48), (-0.19, 0.22, 0.9))), "PlasticWhite"),
            TwinPart.of("Legs", geo.merge(*legs), "Iron")]


def umbrella(radius: float = 1.2, height: float = 2.3, canvas: str = "CanvasRed", foot_m: float = 0.0) -> list[TwinPart]:
    """A parasol whose pole rises from ``foot_m`` above the ground to the canopy's centre, ``height`` + 0.2 m.

    At a table, pass :data:`TABLE_TOP_M`: the pole then stands on the table top instead of running through
    the table and its leg (the part below the top was hidden anyway, and made the two objects overlap)."""
    top = height + 0.2
    canopy = geo.cone(radius, 0.45, sections=12)
    canopy = (canopy[0] + (0, 0, top), canopy[1])
    return [TwinPart.of("Pole", geo.cylinder((0, 0, (foot_m + top) / 2), 0.02, top - foot_m, sections=8), "Iron"),
            TwinPart.of("Canopy", canopy, canvas)]
