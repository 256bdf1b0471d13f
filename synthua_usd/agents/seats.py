"""Seats: where on a twin's benches people can sit, found from its triangles.

A seat is an upward-facing, level patch of a ``furniture`` object 0.35-0.60 m above the walkable ground in
front of it, 0.3-0.7 m deep and at least 0.5 m long; it faces away from furniture that rises behind it (a
backrest), or, without one, towards the side with walkable ground. It offers one place per 0.6 m of length.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd.agents.walkable import WalkableGrid

SEAT_HEIGHT_M = (0.35, 0.60)
SEAT_DEPTH_M = (0.3, 0.7)
MIN_SEAT_LENGTH_M = 0.5
PLACE_WIDTH_M = 0.6
#: The sitter's origin lies this far in front of the seat's back edge (the body's back is 0.15 m behind its
#: origin in :mod:`synthua_usd.assets.postures`: 2 cm from the backrest).
ORIGIN_FROM_BACK_M = 0.17


@dataclass(frozen=True)
class SeatPlace:
    """One place to sit: ``origin`` (3,) the sitter's origin on the ground (world metres, Z up), ``heading_deg``
    the way the sitter faces (0 = +X), ``seat_height_m`` the seat's top above that ground."""

    origin: tuple[float, float, float]
    heading_deg: float
    seat_height_m: float


def find_seat_places(vertices: np.ndarray, faces: np.ndarray, face_class: np.ndarray, grid: WalkableGrid,
                     furniture: str = "furniture") -> list[SeatPlace]:
    """Places on every seat of ``furniture`` objects (see the module's docstring), in a fixed order."""
    import trimesh
    mask = face_class == furniture
    if not mask.any():
        return []
    tri = vertices[faces[mask]]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    up = (length > 0) & (normal[:, 2] > 0.98 * np.maximum(length, 1e-12))
    if not up.any():
        return []
    furniture_pts = vertices[np.unique(faces[mask])]
    patches = trimesh.Trimesh(vertices, faces[mask][up], process=True).split(only_watertight=False)
    places = []
    for patch in sorted(patches, key=lambda m: tuple(np.round(m.vertices.mean(axis=0), 3))):
        xy, top = patch.vertices[:, :2], float(patch.vertices[:, 2].max())
        mean = xy.mean(axis=0)
        _, _, axes = np.linalg.svd(xy - mean)
        along, across = axes[0], axes[1]
        pa, pc = (xy - mean) @ along, (xy - mean) @ across
        seat_len, depth = float(np.ptp(pa)), float(np.ptp(pc))
        if not (SEAT_DEPTH_M[0] <= depth <= SEAT_DEPTH_M[1] and seat_len >= MIN_SEAT_LENGTH_M):
            continue
        centre = mean + along * (pa.min() + pa.max()) / 2 + across * (pc.min() + pc.max()) / 2
        rel = furniture_pts[:, :2] - centre
        behind = furniture_pts[(np.abs(rel @ along) < seat_len / 2 + 0.05) & (np.abs(rel @ across) < depth / 2 + 0.3)
                               & (furniture_pts[:, 2] > top + 0.15)]
        facing = across if len(behind) == 0 or float(np.mean((behind[:, :2] - centre) @ across)) < 0 else -across
        ground = _ground_in_front(grid, centre + facing * (depth / 2 + 0.4))
        if ground is None or not (SEAT_HEIGHT_M[0] <= top - ground <= SEAT_HEIGHT_M[1]):
            if len(behind) == 0:  # no backrest: try the other side
                facing = -facing
                ground = _ground_in_front(grid, centre + facing * (depth / 2 + 0.4))
            if ground is None or not (SEAT_HEIGHT_M[0] <= top - ground <= SEAT_HEIGHT_M[1]):
                continue
        back = centre - facing * depth / 2
        count = int(seat_len // PLACE_WIDTH_M)
        for k in range(count):
            xy_k = back + facing * ORIGIN_FROM_BACK_M + along * (k - (count - 1) / 2) * PLACE_WIDTH_M
            places.append(SeatPlace((float(xy_k[0]), float(xy_k[1]), float(ground)),
                                    float(np.degrees(np.arctan2(facing[1], facing[0]))), float(top - ground)))
    return places


def _ground_in_front(grid: WalkableGrid, xy: np.ndarray) -> float | None:
    """The walkable surface's height at ``xy`` (the nearest walkable cell within one cell), or None."""
    i0, j0 = grid.cell_of(float(xy[0]), float(xy[1]))
    best = None
    for i in range(i0 - 1, i0 + 2):
        for j in range(j0 - 1, j0 + 2):
            if 0 <= i < grid.z.shape[0] and 0 <= j < grid.z.shape[1] and not np.isnan(grid.z[i, j]):
                d = np.linalg.norm(grid.centre(i, j)[:2] - xy)
                if best is None or d < best[0]:
                    best = (d, float(grid.z[i, j]))
    return None if best is None else best[1]
