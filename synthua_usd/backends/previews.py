"""Colourised instance maps for people: a raw 16-bit id map looks black in every image viewer."""

from __future__ import annotations

import numpy as np

#: Golden-ratio step of hue between consecutive ids: neighbouring ids get far-apart hues.
_GOLDEN = 0.6180339887498949


def instance_colors(ids: np.ndarray) -> np.ndarray:
    """(n,) integer ids -> (n, 3) uint8 sRGB colours; black for 0, the same colour for an id everywhere.

    Hue steps by the golden ratio per id; saturation and value take one of three levels each from a
    multiplicative hash of the id, so that ids whose hues come close still differ in brightness.
    """
    ids = np.asarray(ids, np.uint64).reshape(-1)
    hue = (ids.astype(np.float64) * _GOLDEN) % 1.0
    h = (ids * np.uint64(2654435761)) & np.uint64(0xFFFFFFFF)
    sat = np.array([0.55, 0.75, 0.95])[((h >> np.uint64(8)) % np.uint64(3)).astype(np.int64)]
    val = np.array([0.7, 0.85, 1.0])[((h >> np.uint64(16)) % np.uint64(3)).astype(np.int64)]
    # HSV -> RGB
    i = np.floor(hue * 6.0).astype(np.int64) % 6
    f = hue * 6.0 - np.floor(hue * 6.0)
    p, q, t = val * (1 - sat), val * (1 - f * sat), val * (1 - (1 - f) * sat)
    choices = [(val, t, p), (q, val, p), (p, val, t), (p, q, val), (t, p, val), (val, p, q)]
    rgb = np.zeros((ids.size, 3))
    for k, (r, g, b) in enumerate(choices):
        sel = i == k
        rgb[sel] = np.stack([r[sel], g[sel], b[sel]], axis=-1)
    out = np.round(rgb * 255.0).astype(np.uint8)
    out[ids == 0] = 0
    return out


def instance_preview(instance_ids: np.ndarray) -> np.ndarray:
    """(H, W) non-negative integer instance ids -> (H, W, 3) uint8 sRGB preview, black where the id is 0."""
    ids = np.asarray(instance_ids)
    if ids.size == 0:
        return np.zeros(ids.shape + (3,), np.uint8)
    # a colour table over the ids present, looked up once per pixel (no sort of the whole map)
    present = np.flatnonzero(np.bincount(ids.reshape(-1)))
    table = np.zeros((int(present[-1]) + 1, 3), np.uint8)
    table[present] = instance_colors(present)
    return table[ids]
