"""Texture coordinates of triangle meshes, as plain arrays: projections for procedural geometry (points split where
per-corner coordinates disagree, :func:`synthua_usd.model.meshes.split_corners`).

Coordinates follow USD's ``st``: (0, 0) at an image's bottom-left corner, t up the image. Projections scale
metres to texture repeats by ``tile_m`` (the size of one repeat of the image on the surface).
"""

from __future__ import annotations

import numpy as np

from synthua_usd.model.meshes import split_corners

#: Faces whose normal is within about 45° of up take the ground projection (x, y) in :func:`box_uvs`.
_FLAT = np.cos(np.radians(45.0))


def planar_uvs(points: np.ndarray, tile_m: float) -> np.ndarray:
    """(n, 2) float32 st of ``points`` (n, 3) metres projected straight down (s = x, t = y, in repeats of
    ``tile_m``): for ground surfaces, whose points can keep one coordinate each."""
    return (np.asarray(points, np.float64)[:, :2] / tile_m).astype(np.float32)


def box_uvs(points: np.ndarray, triangles: np.ndarray, tile_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Face-aligned projection of a Z-up mesh: (points, triangles, uvs) with points split where faces meet
    at an edge of the projection.

    Faces within 45° of horizontal take (x, y); the others take s along the horizontal direction of the face
    (up × normal) and t up: walls at any heading get their image upright and unstretched. ``points`` (n, 3)
    metres, ``triangles`` (m, 3) int64; returns (k, 3) float64, (m, 3) int64, (k, 2) float32."""
    p = np.asarray(points, np.float64)
    tris = np.asarray(triangles, np.int64)
    corners = p[tris]  # (m, 3, 3)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    flat = np.abs(normals[:, 2]) >= _FLAT
    # Round the horizontal direction so that coplanar faces get bit-identical directions and share points.
    side = np.round(np.stack([-normals[:, 1], normals[:, 0]], axis=1), 6)
    side /= np.maximum(np.linalg.norm(side, axis=1, keepdims=True), 1e-12)
    s = np.where(flat[:, None], corners[:, :, 0], np.einsum("mkc,mc->mk", corners[:, :, :2], side))
    t = np.where(flat[:, None], corners[:, :, 1], corners[:, :, 2])
    corner_uvs = (np.stack([s, t], axis=2) / tile_m).astype(np.float32)
    return split_corners(p, tris, corner_uvs)
