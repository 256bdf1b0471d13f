"""Compositing a contact sheet with OpenImageIO: a grid of rendered cells, each an RGB image and its class
overlay side by side, under a title, condition names across the top and camera names down the side.

Text is drawn by ``ImageBufAlgo.render_text`` with Droid Sans, the font the OpenImageIO wheel ships
(Apache-2.0; ``OpenImageIO/share/fonts``), so no system font or extra package is needed.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import OpenImageIO as oiio

from synthua_usd.core import images

log = logging.getLogger(__name__)

FONT = "DroidSans"
OVERLAY_ALPHA = 0.5
GAP_PX = 4
HEADER_PX = 46
TITLE_PX = 30
SIDE_PX = 190
BACKGROUND = (0.12, 0.12, 0.12)
TEXT = (0.95, 0.95, 0.95)


def class_overlay(rgb8: np.ndarray, class_ids: np.ndarray, palette: np.ndarray,
                  alpha: float = OVERLAY_ALPHA) -> np.ndarray:
    """(H, W, 3) uint8: the class colours of ``palette`` (classes, 3) blended over display ``rgb8`` with
    ``alpha``; unlabelled pixels (class 0) keep their RGB."""
    colours = palette[class_ids].astype(np.float64)
    blended = (1.0 - alpha) * rgb8.astype(np.float64) + alpha * colours
    out = np.where((class_ids > 0)[..., None], blended, rgb8.astype(np.float64))
    return np.round(out).astype(np.uint8)


def _text(buf: oiio.ImageBuf, x: int, y: int, text: str, size: int) -> None:
    if not oiio.ImageBufAlgo.render_text(buf, x, y, text, size, FONT, TEXT):
        log.warning("contact sheet: cannot draw text with font %s (%s); leaving the label out", FONT,
                    buf.geterror() or oiio.geterror())


def compose(cells: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]], row_labels: list[str],
            column_labels: list[str], title: str) -> np.ndarray:
    """The sheet as (H, W, 3) uint8. ``cells[(row, column)]`` is (rgb8, overlay8), both (h, w, 3) uint8 of
    one size; each column holds the pair side by side under ``column_labels[column]``."""
    h, w = next(iter(cells.values()))[0].shape[:2]
    pair_w = 2 * w + GAP_PX
    width = SIDE_PX + len(column_labels) * (pair_w + 2 * GAP_PX)
    height = TITLE_PX + HEADER_PX + len(row_labels) * (h + 2 * GAP_PX)
    sheet = oiio.ImageBuf(oiio.ImageSpec(width, height, 3, oiio.FLOAT))
    oiio.ImageBufAlgo.fill(sheet, BACKGROUND)
    _text(sheet, 8, TITLE_PX - 9, title, 18)
    for col, label in enumerate(column_labels):
        x = SIDE_PX + col * (pair_w + 2 * GAP_PX) + GAP_PX
        _text(sheet, x, TITLE_PX + 20, label, 18)
        _text(sheet, x, TITLE_PX + HEADER_PX - 8, "RGB", 13)
        _text(sheet, x + w + GAP_PX, TITLE_PX + HEADER_PX - 8, "classes over RGB", 13)
    for row, label in enumerate(row_labels):
        y = TITLE_PX + HEADER_PX + row * (h + 2 * GAP_PX) + GAP_PX
        _text(sheet, 8, y + h // 2, label, 15)
        for col in range(len(column_labels)):
            if (row, col) not in cells:
                continue
            x = SIDE_PX + col * (pair_w + 2 * GAP_PX) + GAP_PX
            for k, image in enumerate(cells[(row, col)]):
                # ImageBuf wants (H, W, C) arrays.
                tile = oiio.ImageBuf(np.ascontiguousarray(image.astype(np.float32) / 255.0))
                oiio.ImageBufAlgo.paste(sheet, x + k * (w + GAP_PX), y, 0, 0, tile)
    pixels = np.clip(sheet.get_pixels(oiio.FLOAT), 0.0, 1.0)
    return np.round(pixels * 255.0).astype(np.uint8)


def write_sheet(path: Path, sheet: np.ndarray) -> Path:
    """The sheet as an 8-bit sRGB PNG, written atomically (its cells are display-referred already)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    return images.write_color_png(path, sheet)
