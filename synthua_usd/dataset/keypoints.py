"""COCO keypoints of an image's instances: their world keypoints projected by the camera, with visibility
flags from the exact label pass.

For each keypoint (world point ``p`` of instance ``i``), with the camera's projection
(:meth:`synthua_usd.model.cameras.PinholeCamera.project`: lens distortion applied, pixel centres at +0.5) at the
render size, scaled to the written size when the images are resampled:

* ``v = 0`` (not labelled; written as ``x = y = 0``): ``p`` is not in front of the near clipping plane, or
  its pixel lies outside the image;
* ``v = 2`` (visible): some pixel within :data:`WINDOW_PX` pixels (a (2r+1)² square, written pixels) of the
  keypoint's pixel shows instance ``i`` in the label pass (its instance map) at a z-depth no nearer than
  ``z(p) - DEPTH_TOLERANCE_M``: the ray hits that instance near the keypoint, not a part of it well in front
  (an arm crossing the face, the torso hiding the far wrist);
* ``v = 1`` (labelled, occluded): otherwise (something else, or a nearer part of the same instance, is in
  the way).

Joints lie inside the body: :data:`DEPTH_TOLERANCE_M` is 0.2 m, a little more than the half-depth of an
adult's trunk, so that a hip or shoulder seen on its own side counts as visible.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from synthua_usd.dataset.record import InstanceEntry
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.scene import Keypoints

#: Half-size of the pixel neighbourhood searched for the instance around a keypoint, written pixels.
WINDOW_PX = 2
#: How much nearer than the keypoint the instance's surface may be and the keypoint still count as visible.
DEPTH_TOLERANCE_M = 0.2


def project_keypoints(keypoints: Keypoints, camera: PinholeCamera, render_size: tuple[int, int],
                      size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates (k, 2) at the written ``size`` (W, H) and OpenCV z-depths (k,) of the keypoints
    (NaN coordinates behind the camera)."""
    uv, z = camera.project(keypoints.points, *render_size)
    scale = np.array([size[0] / render_size[0], size[1] / render_size[1]])
    return uv * scale, z


def visibility(uv: np.ndarray, z: np.ndarray, instance_id: int, instance_ids: np.ndarray, z_depth: np.ndarray,
               near_m: float) -> np.ndarray:
    """(k,) COCO visibility flags 0/1/2 (module docstring) of keypoints at pixel coordinates ``uv`` (k, 2)
    and depths ``z`` (k,), against the label pass's ``instance_ids`` (H, W) and ``z_depth`` (H, W) metres."""
    height, width = instance_ids.shape
    flags = np.zeros(len(uv), np.int64)
    with np.errstate(invalid="ignore"):
        inside = (np.isfinite(uv).all(axis=1) & (z >= near_m) & (uv[:, 0] >= 0) & (uv[:, 0] < width)
                  & (uv[:, 1] >= 0) & (uv[:, 1] < height))
    for k in np.flatnonzero(inside):
        # the pixel of the coordinates as written (rounded to 0.01 px, :func:`coco_keypoints`): 72.996 is written
        # 73.0, and a reader checks the window round pixel 73, not 72
        col, row = int(round(float(uv[k, 0]), 2)), int(round(float(uv[k, 1]), 2))
        rows = slice(max(0, row - WINDOW_PX), row + WINDOW_PX + 1)
        cols = slice(max(0, col - WINDOW_PX), col + WINDOW_PX + 1)
        hit = (instance_ids[rows, cols] == instance_id) & (z_depth[rows, cols] >= z[k] - DEPTH_TOLERANCE_M)
        flags[k] = 2 if hit.any() else 1
    return flags


def pasted_visibility(points: np.ndarray, instance_id: int, instance_ids: np.ndarray) -> np.ndarray:
    """(k,) COCO flags of a pasted cut-out's keypoints ``points`` (k, 3): frame x, y and the flag the cut-out gives
    (rendered alone). A keypoint outside the image, or not labelled, is 0; one the cut-out shows (2) stays 2 where
    ``instance_ids`` shows its instance within :data:`WINDOW_PX` pixels, and becomes 1 where a nearer paste covers
    it; an occluded one (1) stays 1. The pixel looked around is that of the coordinates as written (rounded as
    :func:`coco_keypoints` rounds them), so that a reader checking the flags finds the same pixel."""
    height, width = instance_ids.shape
    flags = np.zeros(len(points), np.int64)
    for k, (x, y, v) in enumerate(np.asarray(points, np.float64)):
        x, y = round(float(x), 2), round(float(y), 2)
        if v == 0 or not (0 <= x < width and 0 <= y < height):
            continue
        col, row = int(x), int(y)
        window = instance_ids[max(0, row - WINDOW_PX):row + WINDOW_PX + 1, max(0, col - WINDOW_PX):col + WINDOW_PX + 1]
        flags[k] = 2 if v == 2 and (window == instance_id).any() else 1
    return flags


def coco_keypoints(uv: np.ndarray, flags: np.ndarray) -> list[float]:
    """COCO's flat ``[x1, y1, v1, x2, ...]``: coordinates rounded to 0.01 px, ``x = y = 0`` where ``v = 0``."""
    out = []
    for (x, y), v in zip(uv, flags):
        out += [0.0, 0.0, 0] if v == 0 else [round(float(x), 2), round(float(y), 2), int(v)]
    return out


def annotate_keypoints(entries: Sequence[InstanceEntry], keypoints: dict[int, Keypoints], camera: PinholeCamera,
                       render_size: tuple[int, int], instance_ids: np.ndarray, z_depth: np.ndarray) -> None:
    """Add ``keypoints`` (``{"names", "keypoints": flat COCO list, "num_keypoints"}``) to every record entry
    (of :func:`synthua_usd.dataset.annotations.annotate`) whose instance has keypoints; ``instance_ids`` and
    ``z_depth`` are the written label maps (their shape is the written size)."""
    size = (instance_ids.shape[1], instance_ids.shape[0])
    for entry in entries:
        found = keypoints.get(entry["id"])
        if found is None:
            continue
        uv, z = project_keypoints(found, camera, render_size, size)
        flags = visibility(uv, z, entry["id"], instance_ids, z_depth, camera.clip_near_m)
        entry["keypoints"] = {"names": list(found.names), "keypoints": coco_keypoints(uv, flags),
                              "num_keypoints": int((flags > 0).sum())}
