"""Checks on rendered frames that several tests make."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def black_shares(frame: Path) -> tuple[float, float]:
    """(share of all pixels, share of the pixels whose centre ray hits nothing) that are black in a rendered
    frame's rgb.png; depth.exr says which rays escaped (0: no hit). Asserts that some do: the view looks past
    the modelled ground or at the sky."""
    import OpenImageIO as oiio
    from PIL import Image

    black = np.asarray(Image.open(frame / "rgb.png").convert("RGB")).max(axis=2) == 0
    escaped = oiio.ImageBuf(str(frame / "depth.exr")).get_pixels(oiio.FLOAT)[..., 0] == 0
    assert escaped.any(), f"{frame}: no pixel sees past the twin"
    return float(black.mean()), float(black[escaped].mean())
