"""Buildings: colonial row houses and a church. The street façade faces +X at x = depth / 2; the
footprint is centred on the origin; a foundation reaches below z = 0 so that houses sit on slopes.

Builders return a :class:`BuildingParts`: the structure (one ``building`` instance) and the doors,
windows and murals, each of which is its own instance.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart

STOREY_M = 3.2


@dataclass
class BuildingParts:
    structure: list[TwinPart]
    doors: list[list[TwinPart]] = field(default_factory=list)
    windows: list[list[TwinPart]] = field(default_factory=list)
    murals: list[list[TwinPart]] = field(default_factory=list)


def _facade_box(front_x, y0, y1, z0, z1, proud=0.06):
    return geo.box((front_x, y0, z0), (front_x + proud, y1, z1))


def row_house(rng: np.random.Generator, width: float, depth: float, storeys: int, wall: str,
              foundation_m: float = 3.0, mural: bool = False) -> BuildingParts:
    """A house of ``storeys`` floors: door on the ground floor, a window per bay and floor, a pitched
    tiled roof; optionally a painted mural panel on the upper façade."""
    d, w = depth / 2, width / 2
    height = storeys * STOREY_M
    structure = [TwinPart.of("Walls", geo.box((-d, -w, -foundation_m), (d, w, height)), wall),
                 TwinPart.of("Cornice", geo.box((d, -w, height - 0.3), (d + 0.25, w, height)), "Stucco"),
                 TwinPart.of("Roof", geo.merge(geo.ramp(-w, w, -d - 0.3, 0.0, height, height + 2.2, height),
                                         geo.ramp(-w, w, d + 0.3, 0.0, height, height + 2.2, height)), "RoofTile")]
    # The ramp builder rises along y; turn the roof so its ridge runs along the street (y).
    pts, tris = structure[2].mesh
    structure[2] = TwinPart.of("Roof", (pts[:, [1, 0, 2]], tris[:, ::-1]), "RoofTile")
    bays = max(int(width // 2.6), 1)
    centres = np.linspace(-w + width / (2 * bays), w - width / (2 * bays), bays)
    door_bay = int(rng.integers(bays))
    parts = BuildingParts(structure)
    for floor in range(storeys):
        z0 = floor * STOREY_M
        for k, cy in enumerate(centres):
            if floor == 0 and k == door_bay:
                parts.doors.append([TwinPart.of("Door", _facade_box(d, cy - 0.55, cy + 0.55, 0.0, 2.4), "DoorWood")])
            elif floor == 0:
                parts.windows.append([TwinPart.of("Window", _facade_box(d, cy - 0.5, cy + 0.5, z0 + 0.9, z0 + 2.3), "Glass")])
            elif not (mural and floor == storeys - 1 and k == bays // 2):
                parts.windows.append([TwinPart.of("Window", _facade_box(d, cy - 0.45, cy + 0.45, z0 + 0.8, z0 + 2.4), "Glass")])
    if mural and storeys >= 2:
        cy = centres[bays // 2]
        z0 = (storeys - 1) * STOREY_M
        parts.murals.append([TwinPart.of("Mural", _facade_box(d, cy - 1.1, cy + 1.1, z0 + 0.4, z0 + 2.6, 0.03),
                                   f"Mural{int(rng.integers(3))}")])
    return parts


def church(width: float = 16.0, depth: float = 24.0, foundation_m: float = 1.0) -> BuildingParts:
    """A colonial church: nave, a front tower with a spire, a large door and tall windows (front at +X)."""
    d, w = depth / 2, width / 2
    nave_h, tower_w, tower_h = 11.0, 5.0, 22.0
    tx0 = d - tower_w
    structure = [
        TwinPart.of("Nave", geo.box((-d, -w, -foundation_m), (d, w, nave_h)), "Whitewash"),
        TwinPart.of("NaveRoof", _gable(-d, d, w + 0.3, nave_h, nave_h + 4.0), "RoofTile"),
        TwinPart.of("Tower", geo.box((tx0, -tower_w / 2, -foundation_m), (d + 0.5, tower_w / 2, tower_h)), "Whitewash"),
        TwinPart.of("Spire", _pyramid((d + 0.5 + tx0) / 2, 0.0, tower_h, tower_w / 2 + 0.2, 5.0), "RoofTile"),
    ]
    parts = BuildingParts(structure)
    parts.doors.append([TwinPart.of("Door", _facade_box(d + 0.5, -1.0, 1.0, 0.0, 4.0), "DoorWood")])
    for y in (-w + 2.0, w - 2.0):
        parts.doors.append([TwinPart.of("Door", _facade_box(d, y - 0.6, y + 0.6, 0.0, 2.8), "DoorWood")])
    for z0 in (6.0, 14.0):
        parts.windows.append([TwinPart.of("Window", _facade_box(d + 0.5, -0.7, 0.7, z0, z0 + 2.5), "Glass")])
    # Tall windows along both side walls, 1.4 m wide with at least 1.6 m of wall between them, and 2 m
    # of wall at each corner: as many as fit, so that no two windows overlap on a short nave.
    count = max(int((depth - 2.4) // 3.0), 1)
    for x in np.linspace(-d + 2.7, d - 2.7, count) if count > 1 else [0.0]:
        for y, sign in ((-w, -1), (w, 1)):
            lo, hi = sorted((y, y + sign * 0.06))
            parts.windows.append([TwinPart.of("Window", geo.box((x - 0.7, lo, 4.0), (x + 0.7, hi, 8.5)), "Glass")])
    return parts


def _gable(x0, x1, half_width, z0, z1):
    pts = np.array([[x0, -half_width, z0], [x1, -half_width, z0], [x1, half_width, z0], [x0, half_width, z0],
                    [x0, 0.0, z1], [x1, 0.0, z1]], float)
    import trimesh

    hull = trimesh.Trimesh(pts).convex_hull
    return np.asarray(hull.vertices, float), np.asarray(hull.faces, np.int64)


def _pyramid(cx, cy, z0, half, height):
    import trimesh

    pts = np.array([[cx - half, cy - half, z0], [cx + half, cy - half, z0], [cx + half, cy + half, z0],
                    [cx - half, cy + half, z0], [cx, cy, z0 + height]], float)
    hull = trimesh.Trimesh(pts).convex_hull
    return np.asarray(hull.vertices, float), np.asarray(hull.faces, np.int64)
