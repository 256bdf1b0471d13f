"""Low-poly geometry builders for procedural assets: arrays in, arrays out, no USD.

Every builder returns ``(points, triangles)``: points (n, 3) float64 in metres, triangles (m, 3) int64 with
counter-clockwise winding seen from outside. Z is up.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # imported where used (with scipy.spatial, ~0.6 s that most processes never need)
    import trimesh

Mesh = tuple[np.ndarray, np.ndarray]


def _arrays(mesh: trimesh.Trimesh) -> Mesh:
    return np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)


#: The unit cube's corners and outward-wound triangles, as ``trimesh.creation.box`` has them. Boxes are
#: built from these directly: the district has tens of thousands (cobbles, pavers), and a Trimesh object
#: per box made building it ten times slower for the same arrays.
_UNIT_BOX_POINTS = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1], [1, 0, 0], [1, 0, 1], [1, 1, 0], [1, 1, 1]], np.float64)
_UNIT_BOX_TRIANGLES = np.array([[1, 3, 0], [4, 1, 0], [0, 3, 2], [2, 4, 0], [1, 7, 3], [5, 1, 4], [5, 7, 1], [3, 7, 2],
                                [6, 4, 2], [2, 7, 6], [6, 5, 4], [7, 5, 6]], np.int64)


def box(min_corner, max_corner) -> Mesh:
    """Axis-aligned box between two corners (3,) metres."""
    lo, hi = np.asarray(min_corner, float), np.asarray(max_corner, float)
    if np.any(hi <= lo):
        raise ValueError(f"box corners should satisfy min < max on every axis, but were {lo} and {hi}")
    return _UNIT_BOX_POINTS * (hi - lo) + lo, _UNIT_BOX_TRIANGLES.copy()


def cylinder(center, radius: float, height: float, axis: str = "z", sections: int = 16) -> Mesh:
    """Closed cylinder of ``radius`` and ``height`` (metres) centred at ``center`` along ``axis``."""
    import trimesh
    points, tris = _along(trimesh.creation.cylinder(radius=radius, height=height, sections=sections), axis)
    return points + np.asarray(center, float), tris


def sphere(center, radius: float, subdivisions: int = 2) -> Mesh:
    import trimesh
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    mesh.apply_translation(center)
    return _arrays(mesh)


def ellipsoid(center, radii, subdivisions: int = 2) -> Mesh:
    points, tris = sphere((0, 0, 0), 1.0, subdivisions)
    return points * np.asarray(radii, float) + np.asarray(center, float), tris


def ramp(x0: float, x1: float, y_low: float, y_high: float, z_low: float, z_high: float, z_base: float) -> Mesh:
    """A wedge rising along y from ``z_low`` at ``y_low`` to ``z_high`` at ``y_high``, between x0 and x1.

    The base is at ``z_base``. Used for curb ramps. ``y_low`` may be greater than ``y_high``.
    """
    import trimesh
    pts = np.array([
        [x0, y_low, z_base], [x1, y_low, z_base], [x1, y_high, z_base], [x0, y_high, z_base],
        [x0, y_low, z_low], [x1, y_low, z_low], [x1, y_high, z_high], [x0, y_high, z_high],
    ], float)
    hull = trimesh.Trimesh(pts, process=True).convex_hull
    return _arrays(hull)


def tube(polyline, radius: float, sections: int = 8) -> Mesh:
    """Closed tube of ``radius`` along a polyline (k, 3) of k >= 2 points, metres: a ring of ``sections``
    points at each polyline point, square to the mean direction of its segments (frames carried along by
    parallel transport, so the tube does not twist), capped flat at both ends."""
    line = np.asarray(polyline, float)
    steps = np.diff(line, axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    if line.ndim != 2 or line.shape[1] != 3 or len(line) < 2 or np.any(lengths < 1e-9):
        raise ValueError(f"tube: a polyline of shape {line.shape} with segment lengths {lengths}; expected (k >= 2, 3) "
                         f"points, no two consecutive ones equal")
    steps /= lengths[:, None]
    directions = np.concatenate([steps[:1], steps[:-1] + steps[1:], steps[-1:]])
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    normal = np.cross(directions[0], [0.0, 0.0, 1.0] if abs(directions[0][2]) < 0.9 else [1.0, 0.0, 0.0])
    rings = []
    angles = np.linspace(0.0, 2 * np.pi, sections, endpoint=False)
    for point, direction in zip(line, directions):
        normal = normal - normal.dot(direction) * direction
        normal /= np.linalg.norm(normal)
        binormal = np.cross(direction, normal)
        rings.append(point + radius * (np.cos(angles)[:, None] * normal + np.sin(angles)[:, None] * binormal))
    k, j = len(line), np.arange(sections)
    quads = [(r * sections + j, r * sections + (j + 1) % sections, (r + 1) * sections + (j + 1) % sections,
              (r + 1) * sections + j) for r in range(k - 1)]
    sides = np.concatenate([np.stack([a, b, c], 1) for a, b, c, _ in quads] + [np.stack([a, c, d], 1) for a, _, c, d in quads])
    start, end = k * sections, k * sections + 1
    caps = np.concatenate([np.stack([np.full(sections, start), (j + 1) % sections, j], 1),
                           np.stack([np.full(sections, end), (k - 1) * sections + j, (k - 1) * sections + (j + 1) % sections], 1)])
    return np.concatenate(rings + [line[:1], line[-1:]]), np.concatenate([sides, caps]).astype(np.int64)


def torus(center, major_radius: float, minor_radius: float, axis: str = "z", major_sections: int = 32,
          minor_sections: int = 8) -> Mesh:
    """Closed torus centred at ``center`` around ``axis`` (a tyre, a rim), metres. With ``major_sections`` a
    multiple of 4 its points reach exactly ``major_radius + minor_radius`` from the axis along the other two
    axes (a wheel of that radius touches the ground)."""
    import trimesh
    u = np.linspace(0.0, 2 * np.pi, major_sections, endpoint=False)[:, None]
    v = np.linspace(0.0, 2 * np.pi, minor_sections, endpoint=False)[None, :]
    ring = major_radius + minor_radius * np.cos(v)
    points = np.stack([ring * np.cos(u), ring * np.sin(u), minor_radius * np.sin(v) + 0 * u], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(major_sections), np.arange(minor_sections), indexing="ij")
    a, b = i * minor_sections + j, ((i + 1) % major_sections) * minor_sections + j
    c, d = ((i + 1) % major_sections) * minor_sections + (j + 1) % minor_sections, i * minor_sections + (j + 1) % minor_sections
    tris = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    points, tris = _along(trimesh.Trimesh(points, tris, process=False), axis)
    return points + np.asarray(center, float), tris


def vertex_normals(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(n, 3) float64 area-weighted unit vertex normals of the outward-wound mesh ``points`` (n, 3),
    ``triangles`` (m, 3); a point no triangle uses gets (0, 0, 0)."""
    tri = np.asarray(points, np.float64)[triangles]
    face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    out = np.zeros((len(points), 3))
    for k in range(3):
        np.add.at(out, triangles[:, k], face)
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-12)


def merge(*parts: Mesh) -> Mesh:
    """Concatenate meshes into one (no welding)."""
    points, tris, offset = [], [], 0
    for p, t in parts:
        points.append(np.asarray(p, float))
        tris.append(np.asarray(t, np.int64) + offset)
        offset += len(p)
    return np.concatenate(points), np.concatenate(tris)


def translate(mesh: Mesh, offset) -> Mesh:
    return mesh[0] + np.asarray(offset, float), mesh[1]


def look_at(eye, target, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """(4, 4) camera-to-world matrix, column-vector convention, for a camera at ``eye`` looking at
    ``target`` down its local -Z axis with local +Y towards ``up``."""
    eye, target, up = (np.asarray(v, float) for v in (eye, target, up))
    forward = target - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, up)
    if np.linalg.norm(right) < 1e-9:
        raise ValueError("look_at: view direction is parallel to the up vector")
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, true_up, -forward, eye
    return m


def cone(radius: float, height: float, axis: str = "z", sections: int = 16) -> Mesh:
    """Closed cone centred at the origin along ``axis``, apex towards +axis (USD's UsdGeom.Cone)."""
    import trimesh
    mesh = trimesh.creation.cone(radius=radius, height=height, sections=sections)
    mesh.apply_translation((0.0, 0.0, -height / 2.0))
    return _along(mesh, axis)


def capsule(radius: float, height: float, axis: str = "z", sections: int = 16) -> Mesh:
    """Capsule centred at the origin: a cylinder of ``height`` capped by hemispheres (USD's UsdGeom.Capsule)."""
    import trimesh
    mesh = trimesh.creation.capsule(height=height, radius=radius, count=[sections, sections])
    return _along(mesh, axis)


def _along(mesh: trimesh.Trimesh, axis: str) -> Mesh:
    import trimesh
    if axis == "x":
        mesh.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    elif axis == "y":
        mesh.apply_transform(trimesh.transformations.rotation_matrix(-np.pi / 2, [1, 0, 0]))
    elif axis != "z":
        raise ValueError(f"axis should be 'X', 'Y' or 'Z', but was {axis!r}")
    return _arrays(mesh)


def split_corners(points: np.ndarray, triangles: np.ndarray, corner_uvs: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-corner data ``corner_uvs`` (m, 3, c) float32 of ``triangles`` (m, 3) (texture coordinates, c = 2, or
    those and normals side by side) → (points, triangles, data (k, c)) with one point per distinct (point, data)
    pair, in first-use order: points split only at seams, every triangle keeps its three positions."""
    corner_uvs = np.asarray(corner_uvs, np.float32)
    flat_uv = np.ascontiguousarray(corner_uvs.reshape(-1, corner_uvs.shape[-1]))
    keys = np.concatenate([triangles.reshape(-1, 1).astype(np.uint32), flat_uv.view(np.uint32)], axis=1)
    rows = np.ascontiguousarray(keys).view(np.dtype((np.void, keys.shape[1] * 4))).ravel()  # a corner as bytes
    order = np.argsort(rows, kind="stable")
    ordered = rows[order]
    starts = np.ones(len(rows), bool)
    starts[1:] = ordered[1:] != ordered[:-1]
    first = order[starts]  # each distinct corner's first use (the sort is stable)
    inverse = np.empty(len(rows), np.int64)
    inverse[order] = np.cumsum(starts) - 1
    # renumber in order of first use, so that a mesh without seams keeps its point order
    by_use = np.argsort(first, kind="stable")
    rank = np.empty_like(by_use)
    rank[by_use] = np.arange(len(by_use))
    chosen = first[by_use]
    new_triangles = rank[inverse].reshape(-1, 3).astype(np.int64)
    return points[triangles.reshape(-1)[chosen]], new_triangles, flat_uv[chosen]
