"""Projected extents of triangle meshes and their truncation by the image frame, in plain geometry.

Definitions
-----------
*Projected box*: the axis-aligned box, in pixels of the camera's **ideal pinhole** image (``K`` of
:meth:`PinholeCamera.intrinsics`, pixel (0, 0) covering ``[0, 1] x [0, 1]``, y down), of the instance's
triangles after clipping them against the camera's near plane (OpenCV depth ``z >= clip_near_m``).
Clipping first makes geometry behind the camera harmless: a triangle crossing the near plane contributes
its part in front (whose projection can reach far outside the frame, as the object then passes beside the
camera), and one wholly behind contributes nothing. The box of a clipped triangle soup is the box of the
vertices in front and of the points where triangle edges cross the near plane (straight lines project to
straight lines, so no other point can extend it).

*Truncation* (KITTI's "share of the object outside the image", measured on the box)::

    truncation = 1 - area(box ∩ frame) / area(box)

with ``frame`` the part of the ideal pinhole image plane that the camera images onto its W x H pixels:
the rectangle ``[0, W] x [0, H]`` for an ideal pinhole; with Brown–Conrady distortion, the polygon that
the distorted frame's border maps to when undistorted (:meth:`BrownConrady.undistort` of
``BORDER_SAMPLES`` points per side), so the measure stays in the plane where the triangles' box is exact
and still counts what the real (distorted) frame shows. 0 is wholly inside, 1 wholly outside (or behind
the camera: nothing in front of the near plane). A box of zero area (a mesh seen edge-on) counts as 0
when it lies inside the frame's bounding rectangle, else 1. The far clipping plane is ignored.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.core.errors import InputError
from synthua_usd.model.cameras import PinholeCamera

#: Points per side of the frame's border undistorted to outline the frame of a distorted camera.
BORDER_SAMPLES = 64
#: Points moved into the camera frame per matrix product. OpenBLAS runs a larger (n, 3) x (3, 3) product on
#: all its threads, which on a busy machine (a render, the background writer) cost ten times more than one
#: thread doing it (60 ms against 5 ms for a 166k-point ground); each row is its own three dot products, so
#: the blocks give the same numbers.
PRODUCT_ROWS = 8192


def projected_box(points_world: np.ndarray, triangles: np.ndarray, camera: PinholeCamera, width: int,
                  height: int) -> np.ndarray | None:
    """(4,) float64 ``[x_min, y_min, x_max, y_max]`` ideal-pinhole pixels of the triangles clipped to the near
    plane (module docstring), or None when nothing of them lies in front of it.

    ``points_world`` (n, 3) float, world metres; ``triangles`` (m, 3) int indices into it."""
    return projected_boxes([(points_world, triangles)], camera, width, height)[0]


def projected_boxes(parts, camera: PinholeCamera, width: int, height: int) -> list[np.ndarray | None]:
    """:func:`projected_box` of each ``(points_world, triangles)`` of ``parts``, computed together: the
    per-part work is one matrix product, the rest runs once over all triangles (an image's 230 instances
    one by one cost 0.3 s at 1280x960)."""
    checked = [_checked(points, triangles) for points, triangles in parts]
    ext = camera.world_to_camera_opencv()
    near = camera.clip_near_m
    k = camera.intrinsics(width, height)
    offsets = np.cumsum([0] + [len(points) for points, _ in checked])
    pc = np.concatenate([_to_camera(points, ext) for points, _ in checked] + [np.zeros((0, 3))])
    triangles = np.concatenate([tris + offset for (_, tris), offset in zip(checked, offsets)]
                               + [np.zeros((0, 3), np.int64)])
    owner = np.repeat(np.arange(len(checked)), [len(tris) for _, tris in checked])
    front = pc[:, 2] >= near
    used = np.zeros(len(pc), bool)
    used[triangles.reshape(-1)] = True
    # the points of the triangles in front of the near plane (a part's points follow the part before's)
    kept = np.flatnonzero(used & front)
    x, y, z = pc[kept, 0], pc[kept, 1], pc[kept, 2]
    u, v = k[0, 0] * x / z + k[0, 2], k[1, 1] * y / z + k[1, 2]
    bounds = np.searchsorted(kept, offsets)
    found = np.diff(bounds) > 0
    low = np.full((len(checked), 2), np.inf)
    high = np.full((len(checked), 2), -np.inf)
    if kept.size:
        for axis, coord in ((0, u), (1, v)):  # each part with points: from its first to the next part's
            low[found, axis] = np.minimum.reduceat(coord, bounds[:-1][found])
            high[found, axis] = np.maximum.reduceat(coord, bounds[:-1][found])
    sides = front[triangles]
    # and where edges cross it: only a triangle with corners on both sides of the plane has such edges
    straddling = np.flatnonzero(sides.any(axis=1) & ~sides.all(axis=1))
    edges = np.concatenate([triangles[straddling][:, [0, 1]], triangles[straddling][:, [1, 2]],
                            triangles[straddling][:, [2, 0]]])
    edge_owner = np.tile(owner[straddling], 3)
    crossing = front[edges[:, 0]] != front[edges[:, 1]]
    a, b, edge_owner = pc[edges[crossing, 0]], pc[edges[crossing, 1]], edge_owner[crossing]
    t = (near - a[:, 2]) / (b[:, 2] - a[:, 2])
    clipped = a + t[:, None] * (b - a)
    found[edge_owner] = True
    for axis, f, c in ((0, k[0, 0], k[0, 2]), (1, k[1, 1], k[1, 2])):
        coord = f * clipped[:, axis] / clipped[:, 2] + c
        np.minimum.at(low[:, axis], edge_owner, coord)
        np.maximum.at(high[:, axis], edge_owner, coord)
    return [np.array([lo[0], lo[1], hi[0], hi[1]]) if any_found else None
            for lo, hi, any_found in zip(low, high, found)]


def truncation(points_world: np.ndarray, triangles: np.ndarray, camera: PinholeCamera, width: int,
               height: int) -> float:
    """Share 0..1 of the instance's projected box outside the frame (module docstring for the definition)."""
    return truncations([(points_world, triangles)], camera, width, height)[0]


def truncations(parts, camera: PinholeCamera, width: int, height: int) -> list[float]:
    """:func:`truncation` of each ``(points_world, triangles)`` of ``parts`` (one per instance)."""
    frame = frame_outline(camera, width, height)
    return [_box_truncation(box, frame) for box in projected_boxes(parts, camera, width, height)]


def _box_truncation(box: np.ndarray | None, frame: np.ndarray) -> float:
    if box is None:
        return 1.0
    box_area = (box[2] - box[0]) * (box[3] - box[1])
    if box_area <= 0.0:
        lo, hi = frame.min(axis=0), frame.max(axis=0)
        return 0.0 if (box[0] >= lo[0] and box[1] >= lo[1] and box[2] <= hi[0] and box[3] <= hi[1]) else 1.0
    inside = _polygon_area(_clip_to_box(frame, box))
    return float(min(1.0, max(0.0, 1.0 - inside / box_area)))


def _to_camera(points: np.ndarray, ext: np.ndarray) -> np.ndarray:
    """(n, 3) world points in OpenCV camera coordinates, by blocks of :data:`PRODUCT_ROWS`."""
    rotation = ext[:3, :3].T
    return np.concatenate([points[i:i + PRODUCT_ROWS] @ rotation for i in range(0, len(points), PRODUCT_ROWS)]
                          or [points @ rotation]) + ext[:3, 3]


def frame_outline(camera: PinholeCamera, width: int, height: int) -> np.ndarray:
    """(k, 2) float64 polygon (ideal-pinhole pixels, clockwise on screen) of what the camera images onto its
    W x H frame: the rectangle's 4 corners without distortion, else its undistorted border."""
    if camera.distortion is None:
        return np.array([[0.0, 0.0], [width, 0.0], [width, height], [0.0, height]])
    s = np.linspace(0.0, 1.0, BORDER_SAMPLES, endpoint=False)
    xs = np.concatenate([s * width, np.full_like(s, width), (1 - s) * width, np.zeros_like(s)])
    ys = np.concatenate([np.zeros_like(s), s * height, np.full_like(s, height), (1 - s) * height])
    k = camera.intrinsics(width, height)
    x, y = camera.distortion.undistort((xs - k[0, 2]) / k[0, 0], (ys - k[1, 2]) / k[1, 1],
                                       where=f"camera {camera.path}")
    return np.column_stack([k[0, 0] * x + k[0, 2], k[1, 1] * y + k[1, 2]])


def _clip_to_box(polygon: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Sutherland–Hodgman: ``polygon`` (k, 2) clipped to the box ``[x0, y0, x1, y1]`` (a convex window)."""
    for axis, bound, keep_below in ((0, box[0], False), (0, box[2], True), (1, box[1], False), (1, box[3], True)):
        if not len(polygon):
            break
        inside = polygon[:, axis] <= bound if keep_below else polygon[:, axis] >= bound
        out = []
        for i in range(len(polygon)):
            p, q = polygon[i - 1], polygon[i]
            pin, qin = inside[i - 1], inside[i]
            if pin != qin:
                t = (bound - p[axis]) / (q[axis] - p[axis])
                out.append(p + t * (q - p))
            if qin:
                out.append(q)
        polygon = np.array(out).reshape(-1, 2)
    return polygon


def _polygon_area(polygon: np.ndarray) -> float:
    if len(polygon) < 3:
        return 0.0
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _checked(points_world, triangles) -> tuple[np.ndarray, np.ndarray]:
    points = np.asarray(points_world, np.float64)
    tris = np.asarray(triangles)
    if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise InputError(f"projection: points of shape {points.shape}; expected finite (n, 3) world metres")
    if tris.ndim != 2 or tris.shape[1] != 3 or not np.issubdtype(tris.dtype, np.integer):
        raise InputError(f"projection: triangles of shape {tris.shape} and dtype {tris.dtype}; expected (m, 3) "
                         f"integer indices")
    if len(tris) and (tris.min() < 0 or tris.max() >= len(points)):
        raise InputError(f"projection: triangle indices span {tris.min()}..{tris.max()}; expected 0..{len(points) - 1}")
    return points, tris.astype(np.int64)
