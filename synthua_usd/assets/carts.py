"""Wheeled things that are not mobility aids: a pushchair (stroller) and a shopping trolley. A detector that
learns wheelchairs from images without them learns "wheels and a seat near a person"; these are the hard
negatives domain-randomisation papers scatter (the class map has no class for them: they are unlabelled, void).

Sizes follow common products: a pushchair about 0.58 x 0.85 m with its handle at 1.05 m (EN 1888 folding
pushchairs), a supermarket trolley about 0.56 x 0.95 m with its handle at 1.0 m and its basket from 0.45 m up.
Front faces +X; footprint centre at the origin on z = 0.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart

TUBE_M = 0.012
WIRE_M = 0.004


def _tubes(radius: float, *polylines, sections: int = 8) -> geo.Mesh:
    return geo.merge(*[geo.tube(line, radius, sections) for line in polylines])


def stroller() -> list[TwinPart]:
    """A pushchair: four wheels (0.14 m at the front, 0.2 m at the back), a frame of tubes from the front axle up
    to the handle behind, a fabric seat with a backrest and a hood over it."""
    tyres, frame = [], []
    for s in (-1, 1):
        y = s * 0.26
        tyres += [geo.torus((0.32, y, 0.07), 0.055, 0.015, axis="y", major_sections=16, minor_sections=6),
                  geo.torus((-0.3, y, 0.1), 0.083, 0.017, axis="y", major_sections=20, minor_sections=6)]
        frame.append(_tubes(TUBE_M, [(0.32, y, 0.07), (0.05, y, 0.55), (-0.28, y, 1.02)],
                            [(-0.3, y, 0.1), (0.0, y, 0.5)]))
    frame.append(_tubes(0.014, [(-0.28, -0.27, 1.02), (-0.28, 0.27, 1.02)]))  # the handle bar
    frame.append(_tubes(TUBE_M, [(-0.3, -0.26, 0.1), (-0.3, 0.26, 0.1)], [(0.32, -0.26, 0.07), (0.32, 0.26, 0.07)]))
    seat = geo.merge(geo.box((-0.08, -0.2, 0.44), (0.2, 0.2, 0.5)),                # the seat
                     geo.box((-0.16, -0.2, 0.48), (-0.1, 0.2, 0.9)),               # the backrest
                     geo.box((0.16, -0.2, 0.25), (0.2, 0.2, 0.46)))                # the leg rest
    hood = geo.merge(*[geo.box((-0.16 + 0.12 * k, -0.22, 0.92 - 0.05 * k * k), (-0.04 + 0.12 * k, 0.22, 0.95 - 0.05 * k * k))
                       for k in range(3)])
    return [TwinPart.of("Frame", geo.merge(*frame), "Frame"), TwinPart.of("Wheels", geo.merge(*tyres), "Tyre"),
            TwinPart.of("Seat", seat, "Seat"), TwinPart.of("Hood", hood, "CanvasBlue")]


def shopping_trolley() -> list[TwinPart]:
    """A supermarket trolley: four castors (0.125 m), a chassis of tubes, a wire basket (its bottom at 0.45 m, a
    grid of wires on four sides and the bottom, the back a little higher) and a handle at 1.0 m."""
    x0, x1, y, z0, z1 = -0.42, 0.4, 0.26, 0.45, 0.82
    wires = []
    for x in np.linspace(x0, x1, 9):                                                     # across the bottom and up the sides
        wires.append([(x, -y, z1), (x, -y, z0), (x, y, z0), (x, y, z1)])
    for z in np.linspace(z0 + 0.07, z1, 5):                                              # round the basket
        wires.append([(x0, -y, z + 0.02), (x1, -y, z), (x1, y, z), (x0, y, z + 0.02), (x0, -y, z + 0.02)])
    for yy in np.linspace(-y, y, 7):                                                     # front and back
        wires += [[(x1, yy, z0), (x1, yy, z1)], [(x0, yy, z0), (x0, yy, z1 + 0.02)]]
    basket = _tubes(WIRE_M, *wires, sections=4)
    chassis = _tubes(TUBE_M, [(x1, -0.2, 0.13), (x0, -0.2, 0.13), (x0 - 0.02, -0.24, 1.0)],
                     [(x1, 0.2, 0.13), (x0, 0.2, 0.13), (x0 - 0.02, 0.24, 1.0)],
                     [(x1, -0.2, 0.13), (x1, 0.2, 0.13)], [(x0, -0.2, 0.13), (x0, 0.2, 0.13)])
    castors = geo.merge(*[geo.cylinder((x, s * 0.2, 0.0625), 0.0625, 0.03, axis="y", sections=12)
                          for x in (x0 + 0.04, x1 - 0.04) for s in (-1, 1)])
    handle = geo.tube([(x0 - 0.03, -0.27, 1.0), (x0 - 0.03, 0.27, 1.0)], 0.016, 8)
    return [TwinPart.of("Basket", geo.merge(basket, chassis), "Metal"), TwinPart.of("Castors", castors, "Tyre"),
            TwinPart.of("Handle", handle, "SignRed")]


#: Name -> builder of each cart (no arguments), as the distractor catalogue lists them.
CARTS = {"stroller": stroller, "shopping_trolley": shopping_trolley}
