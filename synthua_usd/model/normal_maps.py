"""Tangent-space normal maps from height fields, and their 8-bit encoding: the one copy the procedural textures use.

Images follow :mod:`synthua_usd.geometry.uv`'s convention: column ``j`` is s, row 0 is t = 1 (the top of the
image), so a height field's t derivative looks one row *up*. Normals are (x along s, y along t, z out of the
surface), unit, in [-1, 1]; UsdPreviewSurface reads an 8-bit map with ``scale`` 2 and ``bias`` -1
(:data:`NORMAL_SCALE`, :data:`NORMAL_BIAS`) in the ``raw`` colour space.
"""

from __future__ import annotations

import numpy as np

#: UsdUVTexture ``scale`` and ``bias`` that decode :func:`encode_normals8`'s [0, 1] values to [-1, 1].
NORMAL_SCALE = (2.0, 2.0, 2.0, 1.0)
NORMAL_BIAS = (-1.0, -1.0, -1.0, 0.0)


def height_normals(height: np.ndarray, texel_m: float) -> np.ndarray:
    """(H, W, 3) unit normals of the tileable height field ``height`` (H, W) metres, ``texel_m`` metres per
    texel (central differences that wrap around the edges)."""
    dh_ds = (np.roll(height, -1, axis=1) - np.roll(height, 1, axis=1)) / (2 * texel_m)
    dh_dt = (np.roll(height, 1, axis=0) - np.roll(height, -1, axis=0)) / (2 * texel_m)  # row - 1 is higher t
    normals = np.stack([-dh_ds, -dh_dt, np.ones_like(height)], axis=2)
    return normals / np.linalg.norm(normals, axis=2, keepdims=True)


def encode_normals8(normals: np.ndarray) -> np.ndarray:
    """(H, W, 3) unit normals in [-1, 1] → 8-bit ``n * 0.5 + 0.5`` (read back with scale 2 and bias -1, as
    UsdPreviewSurface's normal input expects)."""
    return np.round((np.clip(normals, -1.0, 1.0) * 0.5 + 0.5) * 255.0).astype(np.uint8)
