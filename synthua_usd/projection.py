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

from synthua_usd.cameras import PinholeCamera
from synthua_usd.errors import InputError

#: Points per side of the frame's border undistorted to outline the frame of a distorted camera.
BORDER_SAMPLES = 64


def projected_box(points_world: np.ndarray, triangles: np.ndarray, camera: PinholeCamera, width: int,
                  height: int) -> np.ndarray | None:
    """(4,) float64 ``[x_min, y_min, x_max, y_max]`` ideal-pinhole pixels of the triangles clipped to the near
    plane (module docstring), or None when nothing of them lies in front of it.

    ``points_world`` (n, 3) float, world metres; ``triangles`` (m, 3) int indices into it."""
    points, triangles = _checked(points_world, triangles)
    ext = camera.world_to_camera_opencv()
    pc = points @ ext[:3, :3].T + ext[:3, 3]
    near = camera.clip_near_m
    front = pc[:, 2] >= near
    used = np.zeros(len(pc), bool)
    used[triangles.ravel()] = True
    kept = [pc[used & front]]
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    a, b = pc[edges[:, 0]], pc[edges[:, 1]]
    crossing = front[edges[:, 0]] != front[edges[:, 1]]
    a, b = a[crossing], b[crossing]
    t = (near - a[:, 2]) / (b[:, 2] - a[:, 2])
    kept.append(a + t[:, None] * (b - a))
    clipped = np.concatenate(kept)
    if not len(clipped):
        return None
    k = camera.intrinsics(width, height)
    u = k[0, 0] * clipped[:, 0] / clipped[:, 2] + k[0, 2]
    v = k[1, 1] * clipped[:, 1] / clipped[:, 2] + k[1, 2]
    return np.array([u.min(), v.min(), u.max(), v.max()])


def truncation(points_world: np.ndarray, triangles: np.ndarray, camera: PinholeCamera, width: int,
               height: int) -> float:
    """Share 0..1 of the instance's projected box outside the frame (module docstring for the definition)."""
    box = projected_box(points_world, triangles, camera, width, height)
    if box is None:
        return 1.0
    frame = frame_outline(camera, width, height)
    box_area = (box[2] - box[0]) * (box[3] - box[1])
    if box_area <= 0.0:
        lo, hi = frame.min(axis=0), frame.max(axis=0)
        return 0.0 if (box[0] >= lo[0] and box[1] >= lo[1] and box[2] <= hi[0] and box[3] <= hi[1]) else 1.0
    inside = _polygon_area(_clip_to_box(frame, box))
    return float(min(1.0, max(0.0, 1.0 - inside / box_area)))


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
