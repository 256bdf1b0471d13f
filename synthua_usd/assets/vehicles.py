"""Vehicles: car, van, bus, motorcycle, bicycle. Front faces +X; footprint centre at the origin on z = 0.

A bus and a van can have their wheelchair ramp down (``ramp_m`` > 0): a bus's folds out of its front door on the
right (-Y) side down to a kerb of ``kerb_m``; a van's from its floor at the back, its rear doors open. The ramp is a
part of the vehicle (one labelled instance, as Cityscapes labels what is attached to a vehicle).

Head and tail lamps are parts of their own, tagged ``lamp=headlamp|taillamp`` (authored as ``synthua:lamp``),
that stand 1 cm proud of the body: a night condition makes them emitters (:mod:`synthua_usd.model.lamps`).
"""

from __future__ import annotations

import numpy as np

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


def _plate(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, along: str,
           thickness: float = 0.04) -> geo.Mesh:
    """A ramp plate ``thickness`` thick whose top runs from ``z0`` at the low end of ``along`` (``x`` from x0 to
    x1, ``y`` from y0 to y1) to ``z1`` at the high end: a box sheared along that axis."""
    pts, tris = geo.box((x0, y0, -thickness), (x1, y1, 0.0))
    axis, (a, b) = (0, (x0, x1)) if along == "x" else (1, (y0, y1))
    t = (pts[:, axis] - a) / (b - a)
    return pts + np.column_stack([np.zeros((len(pts), 2)), z0 + t * (z1 - z0)]), tris


def bus(length: float = 12.0, width: float = 2.55, ramp_m: float = 0.0, kerb_m: float = 0.15) -> list[TwinPart]:
    """A low-floor city bus (floor 0.35 m); with ``ramp_m`` > 0 its front door's ramp (0.9 m wide) reaches out
    ``ramp_m`` from its right side, down to a kerb ``kerb_m`` high."""
    l, w = length / 2, width / 2
    parts = [TwinPart.of("Body", geo.box((-l, -w, 0.35), (l, w, 3.1)), "PaintOrange"),
             TwinPart.of("Windows", geo.merge(geo.box((-l * 0.9, -w - 0.01, 1.4), (l * 0.95, w + 0.01, 2.6)),
                                        geo.box((l, -w * 0.9, 1.1), (l + 0.01, w * 0.9, 2.8))), "Glass"),
             TwinPart.of("Wheels", _wheels((-l * 0.6, l * 0.55), w - 0.15, 0.5, 0.3), "Tyre"),
             *_lamps(l, -l, w - 0.35, 0.6, 0.85, half_width=0.15)]
    if ramp_m > 0:
        door = l * 0.75
        parts.append(TwinPart.of("Ramp", _plate(door - 0.45, door + 0.45, -w - ramp_m, -w, kerb_m + 0.005, 0.35, "y"),
                                 "Metal"))
    return parts


def van(length: float = 5.2, width: float = 2.0, paint: str = "PaintWhite", ramp_m: float = 0.0) -> list[TwinPart]:
    """A panel van (floor 0.55 m, roof 2.4 m) with a sloped windscreen; with ``ramp_m`` > 0 its rear doors stand
    open at 90 degrees and a ramp (0.8 m wide) runs ``ramp_m`` back from its floor to the ground."""
    l, w = length / 2, width / 2
    pts, tris = geo.ramp(-w, w, l * 0.8, l * 0.45, 1.1, 2.4, 1.1)  # rises along y: turned to rise along -x
    screen = (pts[:, [1, 0, 2]], tris[:, ::-1])
    parts = [TwinPart.of("Body", geo.merge(geo.box((-l, -w, 0.4), (l * 0.45, w, 2.4)),
                                          geo.box((l * 0.45, -w, 0.4), (l, w, 1.1)), screen), paint),
             TwinPart.of("Windows", geo.merge(*[geo.box((l * 0.47, s * w - 0.01, 1.25), (l * 0.55, s * w + 0.01, 1.95))
                                                for s in (-1, 1)]), "Glass"),
             TwinPart.of("Wheels", _wheels((-l * 0.62, l * 0.62), w - 0.12, 0.34, 0.22), "Tyre"),
             *_lamps(l, -l, w - 0.25, 0.75, 0.9)]
    if ramp_m > 0:
        doors = geo.merge(geo.box((-l - w, w, 0.45), (-l, w + 0.04, 2.3)), geo.box((-l - w, -w - 0.04, 0.45), (-l, -w, 2.3)))
        parts.append(TwinPart.of("RearDoors", doors, paint))
        parts.append(TwinPart.of("Ramp", _plate(-l - ramp_m, -l, -0.4, 0.4, 0.005, 0.55, "x"), "Metal"))
    return parts


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
