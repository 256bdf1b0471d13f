"""A cut-out's four images read from its bank, and resampled into a composite's frame at a placement.

The placement maps a cut-out point (u, v) (crop pixels, continuous: pixel centres at + 0.5) to the frame point
``anchor_px + scale * ((u, v) - entry.anchor)``. Each frame pixel takes:

* **colour and alpha**: the cut-out's premultiplied linear RGB and its alpha, filtered down (or up) by Pillow's
  bilinear resize over exactly the frame pixel's preimage (a triangle filter widened by the scale when shrinking,
  so no aliasing), in linear light;
* **labels** (``ids``, ``amodal``): the value of the cut-out pixel whose area holds the preimage of the frame pixel's
  centre, ``floor(anchor + (X + 0.5 - anchor_px) / scale)``: nearest, never interpolated, so no id is invented;
* **shadow**: the shadow layer (1 = no shadow) filtered like the colour.

Labels are resampled over the whole placed cut-out, inside the frame or not, so that the share of an instance the
frame cuts off is known (:attr:`PlacedCutout.outside`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from PIL import Image

from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.dataset.cutout_bank import BankEntry
from synthua_usd.model.srgb import to_linear

#: 8-bit sRGB value -> linear, float32 (the sRGB curve of :mod:`synthua_usd.model.srgb`, tabulated once).
LINEAR_LUT = to_linear(np.arange(256, dtype=np.float64) / 255.0).astype(np.float32)


@dataclass(frozen=True, eq=False)
class CutoutPixels:
    """A cut-out's images: ``rgba`` (h, w, 4) uint8 sRGB with straight alpha, ``ids`` (h, w) uint8, ``amodal``
    (h, w) uint16 bit field, ``shadow`` (h, w) uint8 (255 = no shadow); ``premultiplied`` (h, w, 4) float32: linear
    RGB times alpha, then alpha (0..1)."""

    rgba: np.ndarray = field(repr=False)
    ids: np.ndarray = field(repr=False)
    amodal: np.ndarray = field(repr=False)
    shadow: np.ndarray = field(repr=False)
    premultiplied: np.ndarray = field(repr=False)


def _read(path: Path, channels: int, dtype, entry: BankEntry, key: str) -> np.ndarray:
    from synthua_usd.core.images import read_image

    try:
        pixels, _ = read_image(path)
    except OSError:
        raise InputError(f"{shown(path)}: not an image OpenImageIO can read; expected the cut-out's {key} PNG") from None
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    want = (entry.size[1], entry.size[0], channels)
    if pixels.shape != want or pixels.dtype != dtype:
        raise InputError(f"{shown(path)}: {pixels.dtype} pixels of shape {pixels.shape}; expected {np.dtype(dtype)} of "
                         f"shape {want} (the cut-out's size {entry.size[0]}x{entry.size[1]}, {key})")
    return pixels if channels > 1 else pixels[..., 0]


def read_cutout(bank_root: Path, entry: BankEntry) -> CutoutPixels:
    """The four images of ``entry``, checked against its size and the format's pixel types."""
    root = Path(bank_root)
    rgba = _read(root / entry.files["rgba"], 4, np.uint8, entry, "rgba")
    ids = _read(root / entry.files["ids"], 1, np.uint8, entry, "ids")
    amodal = _read(root / entry.files["amodal"], 1, np.uint16, entry, "amodal")
    shadow = _read(root / entry.files["shadow"], 1, np.uint8, entry, "shadow")
    found = set(np.unique(ids).tolist()) - {0}
    known = {i.index for i in entry.instances}
    if not found <= known:
        raise InputError(f"{shown(root / entry.files['ids'])}: instance indices {sorted(found - known)[:5]}; expected "
                         f"only the cut-out's instances {sorted(known)}")
    alpha = rgba[..., 3].astype(np.float32) / 255.0
    premultiplied = np.empty(rgba.shape, np.float32)
    premultiplied[..., :3] = LINEAR_LUT[rgba[..., :3]] * alpha[..., None]
    premultiplied[..., 3] = alpha
    return CutoutPixels(rgba, ids, amodal, shadow, premultiplied)


@dataclass(frozen=True, eq=False)
class PlacedCutout:
    """A cut-out resampled into a ``frame`` (W, H) at a placement, over the frame ``region`` (x0, y0, x1, y1, ints,
    clipped to the frame: every array below has the region's shape). ``premultiplied`` (h, w, 4) float32 linear RGB x
    alpha and alpha; ``ids`` (h, w) uint8 instance indices; ``amodal`` (h, w) uint16 bit field; ``shadow`` (h, w)
    float32, 1 = no shadow; ``outside`` instance index -> its amodal pixels that fall outside the frame; ``cut`` whether
    the frame's left, top, right and bottom edge cuts the crop (it reaches beyond that edge)."""

    frame: tuple[int, int]
    region: tuple[int, int, int, int]
    premultiplied: np.ndarray = field(repr=False)
    ids: np.ndarray = field(repr=False)
    amodal: np.ndarray = field(repr=False)
    shadow: np.ndarray = field(repr=False)
    outside: dict
    cut: tuple[bool, bool, bool, bool] = (False, False, False, False)

    @property
    def slices(self) -> tuple[slice, slice]:
        """The region as (rows, columns) slices of the frame."""
        x0, y0, x1, y1 = self.region
        return slice(y0, y1), slice(x0, x1)


def preimage(anchor_crop: tuple[float, float], anchor_px: tuple[float, float], scale: float,
             frame_coordinate: np.ndarray | float, axis: int) -> np.ndarray | float:
    """Cut-out coordinates (continuous) of frame coordinates along ``axis`` (0: x, 1: y)."""
    return anchor_crop[axis] + (frame_coordinate - anchor_px[axis]) / scale


def _resize(channels: np.ndarray, box: tuple[float, float, float, float], size: tuple[int, int],
            pad_value: float) -> np.ndarray:
    """(h, w, C) float32 ``channels`` filtered over ``box`` (u0, v0, u1, v1, source pixel edges; may reach beyond
    the source, which is then ``pad_value``) to ``size`` (W, H): Pillow's bilinear resize, one channel at a time."""
    u0, v0, u1, v1 = box
    pad = int(math.ceil(max(0.0, -u0, -v0, u1 - channels.shape[1], v1 - channels.shape[0]))) + 2
    padded = np.pad(channels, ((pad, pad), (pad, pad), (0, 0)), constant_values=pad_value)
    shifted = (u0 + pad, v0 + pad, u1 + pad, v1 + pad)
    out = np.empty((size[1], size[0], channels.shape[2]), np.float32)
    for c in range(channels.shape[2]):
        image = Image.fromarray(np.ascontiguousarray(padded[..., c], dtype=np.float32))  # mode F
        out[..., c] = np.asarray(image.resize(size, Image.Resampling.BILINEAR, box=shifted), np.float32)
    return out


def place(pixels: CutoutPixels, entry: BankEntry, anchor_px: tuple[float, float], scale: float,
          frame: tuple[int, int]) -> PlacedCutout | None:
    """The cut-out placed in a ``frame`` (W, H) with its anchor at ``anchor_px`` and ``scale`` (frame px per crop px);
    None when no pixel of it falls in the frame."""
    width, height = frame
    h, w = pixels.ids.shape
    # the frame pixels the whole crop covers (its edges' images, rounded outwards)
    fx0 = math.floor(anchor_px[0] + scale * (0.0 - entry.anchor[0]))
    fx1 = math.ceil(anchor_px[0] + scale * (w - entry.anchor[0]))
    fy0 = math.floor(anchor_px[1] + scale * (0.0 - entry.anchor[1]))
    fy1 = math.ceil(anchor_px[1] + scale * (h - entry.anchor[1]))
    cols = np.floor(preimage(entry.anchor, anchor_px, scale, np.arange(fx0, fx1) + 0.5, 0)).astype(np.int64)
    rows = np.floor(preimage(entry.anchor, anchor_px, scale, np.arange(fy0, fy1) + 0.5, 1)).astype(np.int64)
    col_ok, row_ok = (cols >= 0) & (cols < w), (rows >= 0) & (rows < h)
    full_ids = np.zeros((rows.size, cols.size), np.uint8)
    full_amodal = np.zeros((rows.size, cols.size), np.uint16)
    take = np.ix_(np.flatnonzero(row_ok), np.flatnonzero(col_ok))
    full_ids[take] = pixels.ids[np.ix_(rows[row_ok], cols[col_ok])]
    full_amodal[take] = pixels.amodal[np.ix_(rows[row_ok], cols[col_ok])]
    x0, y0, x1, y1 = max(fx0, 0), max(fy0, 0), min(fx1, width), min(fy1, height)
    if x0 >= x1 or y0 >= y1:
        return None
    inside = (slice(y0 - fy0, y1 - fy0), slice(x0 - fx0, x1 - fx0))
    outside = {}
    for inst in entry.instances:
        bit = np.uint16(1 << (inst.index - 1))
        total = int(np.count_nonzero(full_amodal & bit))
        outside[inst.index] = total - int(np.count_nonzero(full_amodal[inside] & bit))
    box = (float(preimage(entry.anchor, anchor_px, scale, float(x0), 0)),
           float(preimage(entry.anchor, anchor_px, scale, float(y0), 1)),
           float(preimage(entry.anchor, anchor_px, scale, float(x1), 0)),
           float(preimage(entry.anchor, anchor_px, scale, float(y1), 1)))
    size = (x1 - x0, y1 - y0)
    colour = _resize(pixels.premultiplied, box, size, 0.0)
    np.clip(colour, 0.0, None, out=colour)
    np.clip(colour[..., 3], 0.0, 1.0, out=colour[..., 3])
    shadow = _resize(pixels.shadow[..., None].astype(np.float32) / 255.0, box, size, 1.0)[..., 0]
    return PlacedCutout(frame, (x0, y0, x1, y1), colour, full_ids[inside].copy(), full_amodal[inside].copy(),
                        np.clip(shadow, 0.0, 1.0), outside, (fx0 < 0, fy0 < 0, fx1 > width, fy1 > height))
