"""Vehicles: car, bus, motorcycle, bicycle. Front faces +X; footprint centre at the origin on z = 0.

Head and tail lamps are parts of their own, tagged ``lamp=headlamp|taillamp`` (authored as ``synthua:lamp``),
that stand 1 cm proud of the body: a night condition makes them emitters (:mod:`synthua_usd.model.lamps`).
"""

from __future__ import annotations

from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart


def _wheels(xs, half_track, radius, width, sections=16):
    return geo.merge(*[geo.cylinder((x, y, radius), radius, width, axis="y", sections=sections)
                       for x in xs for y in (-half_track, half_track)])


def _lamps(front_x: float, back_x: float, half_gap: float, z0: float, z1: float, half_width: float = 0.12):
    """Head lamps on the front face at ``front_x`` and tail lamps on the back face at ``back_x``, a pair each
    at y = ±``half_gap``."""
    def pair(x0, x1):
        return geo.merge(*[geo.box((x0, y - half_width, z0), (x1, y + half_width, z1)) for y in (-half_gap, half_gap)])
    return [TwinPart.of("HeadLamps", pair(front_x - 0.02, front_x + 0.01), "HeadLamp", lamp="headlamp"),
            TwinPart.of("TailLamps", pair(back_x - 0.01, back_x + 0.02), "TailLamp", lamp="taillamp")]


def car(length: float = 4.2, width: float = 1.75, paint: str = "PaintRed") -> list[TwinPart]:
    l, w = length / 2, width / 2
    return [TwinPart.of("Body", geo.merge(geo.box((-l, -w, 0.3), (l, w, 0.95)),
                                    geo.box((-l * 0.55, -w * 0.92, 0.95), (l * 0.35, w * 0.92, 1.45))), paint),
            TwinPart.of("Windows", geo.merge(geo.box((l * 0.35, -w * 0.85, 0.98), (l * 0.36, w * 0.85, 1.4)),
                                       geo.box((-l * 0.56, -w * 0.85, 0.98), (-l * 0.55, w * 0.85, 1.4))), "Glass"),
            TwinPart.of("Wheels", _wheels((-l * 0.65, l * 0.65), w - 0.1, 0.31, 0.2), "Tyre"),
            *_lamps(l, -l, w - 0.3, 0.68, 0.82)]


def bus(length: float = 12.0, width: float = 2.55) -> list[TwinPart]:
    l, w = length / 2, width / 2
    return [TwinPart.of("Body", geo.box((-l, -w, 0.35), (l, w, 3.1)), "PaintOrange"),
            TwinPart.of("Windows", geo.merge(geo.box((-l * 0.9, -w - 0.01, 1.4), (l * 0.95, w + 0.01, 2.6)),
                                       geo.box((l, -w * 0.9, 1.1), (l + 0.01, w * 0.9, 2.8))), "Glass"),
            TwinPart.of("Wheels", _wheels((-l * 0.6, l * 0.55), w - 0.15, 0.5, 0.3), "Tyre"),
            *_lamps(l, -l, w - 0.35, 0.6, 0.85, half_width=0.15)]


def motorcycle() -> list[TwinPart]:
    return [TwinPart.of("Body", geo.merge(geo.box((-0.5, -0.15, 0.4), (0.55, 0.15, 0.75)),
                                    geo.box((0.45, -0.35, 0.95), (0.5, 0.35, 1.0)),
                                    geo.box((0.45, -0.03, 0.4), (0.5, 0.03, 0.98))), "PaintBlack"),
            TwinPart.of("Wheels", geo.merge(geo.cylinder((-0.7, 0, 0.32), 0.32, 0.12, axis="y", sections=16),
                                      geo.cylinder((0.75, 0, 0.32), 0.32, 0.12, axis="y", sections=16)), "Tyre"),
            TwinPart.of("HeadLamp", geo.box((0.5, -0.06, 0.85), (0.56, 0.06, 0.93)), "HeadLamp", lamp="headlamp")]


def bicycle() -> list[TwinPart]:
    return [TwinPart.of("Frame", geo.merge(geo.box((-0.45, -0.015, 0.33), (0.45, 0.015, 0.36)),
                                     geo.box((-0.2, -0.015, 0.36), (-0.17, 0.015, 0.85)),
                                     geo.box((-0.28, -0.1, 0.85), (-0.08, 0.1, 0.9)),
                                     geo.box((0.38, -0.015, 0.36), (0.41, 0.015, 0.95)),
                                     geo.box((0.38, -0.25, 0.95), (0.41, 0.25, 0.98))), "PaintBlue"),
            TwinPart.of("Wheels", geo.merge(geo.cylinder((-0.55, 0, 0.34), 0.34, 0.03, axis="y", sections=16),
                                      geo.cylinder((0.55, 0, 0.34), 0.34, 0.03, axis="y", sections=16)), "Tyre")]
