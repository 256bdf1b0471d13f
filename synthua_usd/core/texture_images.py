"""Texture images a twin carries (:attr:`synthua_usd.model.twin.TwinModel.images`): checked, and written as PNG
files beside the twin layer, as part of the command's output set (:func:`synthua_usd.core.atomic.output_set`).

Paths are relative to the layer's folder and stay inside it (``textures/asphalt.png``), so that a written
scenario is one self-contained folder tree, which is what ``synthua validate stage`` and render accept
without ``--allow-external-assets``. PNG (lossless, 8-bit) keeps the texels the generator or importer made;
the same pixels always give the same bytes.
"""

from __future__ import annotations

from pathlib import Path, PurePosixPath

import numpy as np

from synthua_usd.core.errors import InputError, echo

#: Where twins keep their images, relative to the twin layer.
TEXTURE_FOLDER = "textures"


def texture_path(name: str) -> str:
    """The relative path of the texture image ``name`` (a file name such as ``asphalt.png``)."""
    return f"{TEXTURE_FOLDER}/{name}"


def check_image(path: str, pixels: np.ndarray) -> np.ndarray:
    """``pixels`` as a contiguous (H, W, C) uint8 array (a 2-D array becomes one channel); raises
    :class:`InputError` naming ``path`` for anything else or for a path that leaves the layer's folder."""
    rel = PurePosixPath(path)
    if rel.is_absolute() or ".." in rel.parts or rel.suffix.lower() != ".png" or not rel.name:
        raise InputError(f"texture image '{echo(path)}': expected a relative path to a .png inside the twin's "
                         f"folder, such as {texture_path('asphalt.png')}")
    array = np.asarray(pixels)
    if array.ndim == 2:
        array = array[:, :, None]
    if array.dtype != np.uint8 or array.ndim != 3 or array.shape[2] not in (1, 2, 3, 4) or 0 in array.shape:
        raise InputError(f"texture image '{echo(path)}': pixels of shape {array.shape} and type {array.dtype}; "
                         f"expected (H, W, C) uint8 with 1 to 4 channels")
    return np.ascontiguousarray(array)


def write_texture_images(images: dict[str, np.ndarray], folder: str | Path) -> list[Path]:
    """Write every image of ``images`` (relative path → pixels) below ``folder`` as 8-bit PNG
    (:func:`synthua_usd.core.images.write_color_png`: the texels as they are); returns the paths written."""
    from synthua_usd.core.images import write_color_png

    written = []
    for rel, pixels in sorted(images.items()):
        path = Path(folder) / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        written.append(write_color_png(path, check_image(rel, pixels)))
    return written
