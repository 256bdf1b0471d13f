"""Fittings of rooms: shelving, counters, rows of seats, ceiling light panels, signs on walls, lift doors,
handrails, pillars and potted plants. Front faces +X; footprint centre at the origin on z = 0 (wall-mounted
fittings: the wall's face at x = 0, the fitting in front of it).

Sizes follow common products: gondola shelving 0.5 m deep and 1.6-2.0 m high with boards every 0.4 m; a shop or
reception counter 1.0-1.1 m high; waiting-room seats 0.45 m high and 0.5 m apart; a 0.6 m ceiling panel;
handrails 0.9 m above the floor (EN 81-70, ISO 21542); lift doors 0.9-1.1 m wide and 2.1 m high.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart


def shelf(length: float = 2.0, height: float = 1.8, depth: float = 0.5, boards: int = 4,
          goods: str = "Goods") -> list[TwinPart]:
    """Double-sided gondola shelving along y: uprights at the ends, a back panel along its middle, ``boards``
    boards a side (the lowest 0.15 m up, the others from 0.65 m), a block of goods on each board (a box per board
    side filling 60 % of the height to the next board)."""
    l, d = length / 2, depth / 2
    frame = [geo.box((-d, y - 0.02, 0.0), (d, y + 0.02, height)) for y in (-l, l)]
    frame.append(geo.box((-0.01, -l, 0.05), (0.01, l, height)))
    stock = []
    # the bottom board low, the others from 0.65 m up: no board top at a seat's height (0.35-0.6 m), where the
    # crowd's bench sitters would be seated on it
    zs = [0.12] + list(np.linspace(0.62, height - 0.38, boards - 1)) if boards > 1 else [0.12]
    for k, z in enumerate(zs):
        frame.append(geo.box((-d, -l + 0.02, z), (d, l - 0.02, z + 0.03)))
        top = min(z + 0.03 + 0.6 * ((zs[k + 1] if k + 1 < len(zs) else height) - z), height - 0.02)
        for x0, x1 in ((-d + 0.04, -0.03), (0.03, d - 0.04)):
            stock.append(geo.box((x0, -l + 0.06, z + 0.03), (x1, l - 0.06, top)))
    return [TwinPart.of("Frame", geo.merge(*frame), "Metal"), TwinPart.of("Stock", geo.merge(*stock), goods)]


def counter(length: float = 2.4, height: float = 1.05, depth: float = 0.6, top: str = "Wood",
            body: str = "PlasticWhite") -> list[TwinPart]:
    """A counter along y (a shop's till, a clinic's reception): a closed body and a top overhanging it by
    3 cm, and a screen on it."""
    l, d = length / 2, depth / 2
    return [TwinPart.of("Body", geo.box((-d, -l, 0.0), (d, l, height - 0.04)), body),
            TwinPart.of("Top", geo.box((-d - 0.03, -l - 0.03, height - 0.04), (d + 0.03, l + 0.03, height)), top),
            TwinPart.of("Screen", geo.merge(geo.box((-0.22, -0.25, height), (-0.18, 0.25, height + 0.32)),
                                            geo.box((-0.1, -0.05, height), (-0.02, 0.05, height + 0.02))), "Iron")]


def seat_row(seats: int = 4, pitch: float = 0.65, seat: str = "Seat") -> list[TwinPart]:
    """A row of ``seats`` seats along y on a beam (a waiting room's): seat tops 0.45 m up, 0.45 m deep and
    ``pitch`` - 4 cm wide (a sitter's 0.6 m, :mod:`synthua_usd.agents.seats`), facing +X, each with a
    backrest; legs at the ends."""
    l = seats * pitch / 2
    pans = [geo.box((-0.2, -l + k * pitch + 0.02, 0.42), (0.25, -l + (k + 1) * pitch - 0.02, 0.45)) for k in range(seats)]
    backs = [geo.box((-0.25, -l + k * pitch + 0.02, 0.48), (-0.21, -l + (k + 1) * pitch - 0.02, 0.85))
             for k in range(seats)]
    frame = [geo.box((-0.05, -l, 0.34), (0.05, l, 0.4))]
    frame += [geo.box((-0.05, y - 0.03, 0.0), (0.05, y + 0.03, 0.34)) for y in (-l + 0.1, l - 0.1)]
    frame += [geo.box((-0.25, y - 0.03, 0.0), (0.25, y + 0.03, 0.02)) for y in (-l + 0.1, l - 0.1)]
    return [TwinPart.of("Seats", geo.merge(*pans, *backs), seat), TwinPart.of("Frame", geo.merge(*frame), "Iron")]


def ceiling_panel(size: float = 0.6, drop: float = 0.02) -> list[TwinPart]:
    """A square LED panel hanging ``drop`` below a ceiling at z = 0 (its glowing face down), on a rim: the
    diffuser is a lamp of role ``ceiling`` (:mod:`synthua_usd.model.lamps`), on under every condition."""
    h = size / 2
    return [TwinPart.of("Rim", geo.box((-h, -h, -drop - 0.04), (h, h, -drop)), "Metal"),
            TwinPart.of("Diffuser", geo.box((-h + 0.02, -h + 0.02, -drop - 0.05), (h - 0.02, h - 0.02, -drop - 0.04)),
                        "LampGlass", lamp="ceiling")]


def wall_sign(width: float = 0.6, height: float = 0.25, plate: str = "SignBlue") -> list[TwinPart]:
    """A plate on a wall at x = 0 (its face 2 cm in front of it), its centre at z = 0."""
    w, h = width / 2, height / 2
    return [TwinPart.of("Plate", geo.box((0.0, -w, -h), (0.02, w, h)), plate)]


def hanging_sign(width: float = 1.0, height: float = 0.3, drop: float = 0.6, plate: str = "SignBlue") -> list[TwinPart]:
    """A double-sided sign across x hanging ``drop`` below a ceiling at z = 0 on two wires."""
    w, h = width / 2, height / 2
    z = -drop
    wires = geo.merge(*[geo.box((-0.004, y - 0.004, z + h), (0.004, y + 0.004, 0.0)) for y in (-w + 0.05, w - 0.05)])
    return [TwinPart.of("Plate", geo.box((-0.015, -w, z - h), (0.015, w, z + h)), plate),
            TwinPart.of("Wires", wires, "Iron")]


def lift_door(width: float = 1.0, height: float = 2.1) -> list[TwinPart]:
    """Closed two-panel lift doors in a wall at x = 0: brushed-steel panels 3 cm proud with a joint between them
    (the frame round them is the wall's, a ``building`` part)."""
    w = width / 2
    return [TwinPart.of("Panels", geo.merge(geo.box((0.0, -w, 0.0), (0.03, -0.005, height)),
                                            geo.box((0.0, 0.005, 0.0), (0.03, w, height))), "Frame")]


def lift_frame(width: float = 1.0, height: float = 2.1) -> list[TwinPart]:
    """The steel surround of lift doors of ``width`` in a wall at x = 0, 4 cm proud, and a call panel beside it."""
    w = width / 2
    return [TwinPart.of("Surround", geo.merge(geo.box((0.0, -w - 0.12, 0.0), (0.04, -w, height + 0.12)),
                                              geo.box((0.0, w, 0.0), (0.04, w + 0.12, height + 0.12)),
                                              geo.box((0.0, -w, height), (0.04, w, height + 0.12))), "Metal")]


def handrail(length: float, height: float = 0.9) -> list[TwinPart]:
    """A handrail along y on a wall at x = 0: a 4 cm rail 6 cm out from the wall on brackets every 1.2 m."""
    l = length / 2
    count = max(int(length // 1.2), 1)
    brackets = [geo.box((0.0, -l + 0.1 + k * (length - 0.2) / count - 0.01, height - 0.06),
                        (0.06, -l + 0.1 + k * (length - 0.2) / count + 0.01, height - 0.02)) for k in range(count + 1)]
    rail = geo.cylinder((0.08, 0.0, height), 0.02, length - 0.1, axis="y", sections=10)
    return [TwinPart.of("Rail", geo.merge(rail, *brackets), "Metal")]


def pillar(width: float = 0.5, height: float = 4.0, material: str = "Stucco") -> list[TwinPart]:
    w = width / 2
    return [TwinPart.of("Shaft", geo.box((-w, -w, 0.0), (w, w, height)), material)]


def potted_plant(height: float = 1.3) -> list[TwinPart]:
    """A pot 0.4 m wide and 0.45 m high with a bushy plant (three ellipsoids of leaves) up to ``height``."""
    crown = height - 0.45
    leaves = geo.merge(geo.ellipsoid((0.0, 0.0, 0.45 + crown * 0.45), (0.3, 0.3, crown * 0.45), subdivisions=1),
                       geo.ellipsoid((0.08, -0.05, 0.45 + crown * 0.7), (0.2, 0.2, crown * 0.3), subdivisions=1))
    return [TwinPart.of("Pot", geo.cylinder((0, 0, 0.225), 0.2, 0.45, sections=14), "RoofTile"),
            TwinPart.of("Leaves", leaves, "Leaves")]
