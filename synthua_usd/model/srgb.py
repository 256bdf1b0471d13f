"""The sRGB transfer function (IEC 61966-2-1), elementwise: the one copy its decoders and encoders use.

Plain numpy: values keep the caller's float dtype, so a float32 texture decodes in float32 and an 8-bit
colour divided by 255 in float64. Images meant for display go through OCIO instead
(:func:`synthua_usd.core.images.linear_to_display`).
"""

from __future__ import annotations

import numpy as np


def to_linear(values: np.ndarray) -> np.ndarray:
    """sRGB-encoded values in [0, 1] → linear."""
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


def from_linear(values: np.ndarray) -> np.ndarray:
    """Linear values in [0, 1] → sRGB-encoded."""
    return np.where(values <= 0.0031308, 12.92 * values, 1.055 * values ** (1 / 2.4) - 0.055)


def encode_srgb8(linear: np.ndarray) -> np.ndarray:
    """(H, W, 3) linear values in [0, 1] → 8-bit sRGB."""
    c = np.clip(linear, 0.0, 1.0)
    return np.round(from_linear(c) * 255.0).astype(np.uint8)


#: ``to_linear(v / 255.0)`` of every 8-bit value v: :func:`decode_srgb8` looks the values up (the same float64s
#: the formula gives, a tenth of its time on a 640x480 image).
_DECODED = to_linear(np.arange(256) / 255.0)


def decode_srgb8(pixels: np.ndarray) -> np.ndarray:
    """8-bit sRGB → linear float64 (what a renderer decodes)."""
    pixels = np.asarray(pixels)
    if pixels.dtype == np.uint8:
        return _DECODED[pixels]
    return to_linear(pixels / 255.0)
