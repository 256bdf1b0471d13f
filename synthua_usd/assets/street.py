"""Street furniture and fixtures: light poles with luminaires, benches, signs, manhole covers, railings,
steps, bus shelter, bicycle rack. Front faces +X; footprint centre at the origin on z = 0."""

from __future__ import annotations

import numpy as np

from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart


def light_pole(height: float = 4.5, arm: float = 0.0) -> tuple[list[TwinPart], list[TwinPart]]:
    """(pole pieces, luminaire pieces): a colonial lantern on a post, or, with ``arm`` > 0, a street
    light whose lamp hangs ``arm`` metres out along +X."""
    pole = [geo.cylinder((0, 0, height / 2), 0.07, height, sections=12), geo.cylinder((0, 0, 0.3), 0.14, 0.6, sections=12)]
    if arm > 0:
        pole.append(geo.box((0.0, -0.03, height - 0.08), (arm, 0.03, height)))
        lamp = geo.box((arm - 0.35, -0.18, height - 0.22), (arm + 0.1, 0.18, height - 0.08))
    else:
        lamp = geo.merge(geo.box((-0.16, -0.16, height), (0.16, 0.16, height + 0.45)),
                         geo.box((-0.22, -0.22, height + 0.45), (0.22, 0.22, height + 0.52)))
    return [TwinPart.of("Pole", geo.merge(*pole), "Iron")], [TwinPart.of("Lamp", lamp, "LampGlass")]


def bench(length: float = 1.8) -> list[TwinPart]:
    h = length / 2
    return [TwinPart.of("Seat", geo.merge(geo.box((-0.22, -h, 0.42), (0.22, h, 0.47)),
                                    geo.box((-0.27, -h, 0.5), (-0.22, h, 0.9))), "Wood"),
            TwinPart.of("Legs", geo.merge(*[geo.box((-0.22, y - 0.03, 0.0), (0.22, y + 0.03, 0.42)) for y in (-h + 0.1, h - 0.1)]),
                  "Iron")]


def sign(height: float = 2.6, kind: str = "street") -> list[TwinPart]:
    """A post with a plate facing +X: ``street`` (name plate), ``stop`` (octagon), ``bus`` (bus-stop)."""
    post = geo.cylinder((0, 0, height / 2), 0.03, height, sections=8)
    if kind == "stop":
        plate = geo.cylinder((0.04, 0, height - 0.35), 0.35, 0.02, axis="x", sections=8)
        mat = "SignRed"
    elif kind == "bus":
        plate = geo.box((0.03, -0.25, height - 0.6), (0.05, 0.25, height))
        mat = "SignBlue"
    else:
        plate = geo.box((0.03, -0.45, height - 0.25), (0.05, 0.45, height))
        mat = "SignBlue"
    return [TwinPart.of("Post", post, "Iron"), TwinPart.of("Plate", plate, mat)]


def manhole_cover(radius: float = 0.33) -> list[TwinPart]:
    """A cast-iron disc 1 cm proud of the surface it lies on."""
    return [TwinPart.of("Cover", geo.cylinder((0, 0, 0.005), radius, 0.01, sections=20), "Iron")]


def railing(start, end, height: float = 1.0, post_spacing: float = 1.2) -> list[TwinPart]:
    """Posts and a handrail between two points (x, y, z) of the ground."""
    a, b = np.asarray(start, float), np.asarray(end, float)
    n = max(int(np.linalg.norm(b[:2] - a[:2]) / post_spacing), 1)
    posts = [geo.cylinder(a + (b - a) * t + [0, 0, height / 2], 0.025, height, sections=8) for t in np.linspace(0, 1, n + 1)]
    rail = _bar(a + [0, 0, height], b + [0, 0, height], 0.03)
    mid = _bar(a + [0, 0, height / 2], b + [0, 0, height / 2], 0.02)
    return [TwinPart.of("Rail", geo.merge(*posts, rail, mid), "Iron")]


def _bar(p, q, r):
    """A square bar of half-width r from p to q."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    d = q - p
    length = np.linalg.norm(d)
    pts, tris = geo.box((0.0, -r, -r), (length, r, r))
    x = d / length
    y = np.cross([0.0, 0.0, 1.0], x)
    y = y / np.linalg.norm(y) if np.linalg.norm(y) > 1e-9 else np.array([0.0, 1.0, 0.0])
    z = np.cross(x, y)
    return pts @ np.stack([x, y, z]) + p, tris


def steps(width: float, count: int, rise: float, tread: float) -> list[TwinPart]:
    """A flight rising along +X from z = 0: ``count`` steps of ``rise`` x ``tread``, ``width`` across."""
    blocks = [geo.box((i * tread, -width / 2, -0.3), ((i + 1) * tread, width / 2, (i + 1) * rise)) for i in range(count)]
    return [TwinPart.of("Steps", geo.merge(*blocks), "Granite")]


def bus_shelter() -> list[TwinPart]:
    return [TwinPart.of("Roof", geo.box((-0.8, -2.0, 2.4), (0.8, 2.0, 2.5)), "Iron"),
            TwinPart.of("Back", geo.box((-0.8, -2.0, 0.1), (-0.75, 2.0, 2.4)), "Glass"),
            TwinPart.of("Posts", geo.merge(*[geo.box((-0.8, y - 0.04, 0.0), (-0.72, y + 0.04, 2.4)) for y in (-1.95, 1.95)]), "Iron"),
            TwinPart.of("Seat", geo.box((-0.75, -1.5, 0.45), (-0.4, 1.5, 0.5)), "Wood")]


def bike_rack(length: float = 3.0) -> list[TwinPart]:
    hoops = [_bar((0, y, 0), (0, y, 0.8), 0.02) for y in np.arange(-length / 2, length / 2 + 1e-6, 0.75)]
    return [TwinPart.of("Rack", geo.merge(*hoops), "Iron")]
