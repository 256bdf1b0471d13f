"""How much contrast and how many edges a dataset's RGB images have: two figures to hold against real photos
(a detector trained on real photos found our images at about half their contrast and edge density).

Per image, from its display sRGB PNG (``images/{split}/{name}.png``, 8-bit, as ``synthua generate`` writes it):

* *luma* Y' = 0.2126 R' + 0.7152 G' + 0.0722 B' of the 8-bit values / 255: the Rec. 709 weights
  (:data:`synthua_usd.model.photometry.REC709_LUMA`) on the display values, not on linear light, so on what a
  viewer and a detector are shown; Y' lies in [0, 1].
* *RMS contrast*: the standard deviation of Y' over the image's pixels (population, ddof 0). 0 for a flat
  image; 0.5, the most any image can have, for one half black and half white.
* *edge density*: the share of the image's pixels whose Sobel gradient magnitude of Y', divided by
  :data:`SOBEL_GAIN` = 4, exceeds :data:`EDGE_THRESHOLD` = 0.1 (strictly). The kernels are
  [1, 2, 1]ᵀ [-1, 0, 1] and its transpose; the weights on either side of the centre add up to 4, so the
  division makes a unit step (black to white) read 1 on the two pixels beside it, and the threshold is a step
  of a tenth of the luma range. Magnitude sqrt(gx² + gy²).
* *border*: pixels beyond the image are copies of the nearest border pixel (replicate padding; for a 3x3
  kernel the same as ``scipy.ndimage.sobel``'s default ``reflect``). So the share is of all H x W pixels,
  each counted once (leaving the frame out would measure 2(H + W) - 4 fewer, and an edge crossing it would
  go uncounted there); a flat image has no edge along its frame (zero padding would mark the whole frame of
  any bright image as edge); and a step edge in the outermost row or column reads as it would inside. Only a
  smooth ramp running into the frame reads there at half its slope.

A photo of another set (:func:`photo_measures`, for ``synthua stats --compare``) is measured alike, on its values as
stored: its first three channels (a grey image's one channel as all three, alpha ignored), 16-bit values scaled to
the 8-bit range (/ 257).

Per dataset and per split, over its images: count, mean, median and the 10th and 90th percentiles
(:data:`PERCENTILES`; linear interpolation, NumPy's default). Each RGB is read once (OpenImageIO) and the
arithmetic is float64 NumPy.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.analytics.dataset_index import DatasetIndex, ImageSummary, image_file
from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.model.photometry import REC709_LUMA

#: Sum of the Sobel weights on either side of the centre: a unit step gives a gradient of this.
SOBEL_GAIN = 4.0
#: Normalised gradient magnitude a pixel must exceed to count as edge.
EDGE_THRESHOLD = 0.1
#: Percentiles reported beside the median.
PERCENTILES = (10, 90)
#: The two figures, as statistics.json names them.
MEASURES = ("rms_contrast", "edge_density")
#: What :func:`spread` gives of each, beside the count.
SPREAD = ("mean", "median") + tuple(f"p{q}" for q in PERCENTILES)


def luma(rgb8: np.ndarray) -> np.ndarray:
    """(H, W, C >= 3) 8-bit sRGB values -> (H, W) float64 Rec. 709 luma in [0, 1] (channels past the third,
    alpha, ignored)."""
    return (np.asarray(rgb8[..., :3], np.float64) / 255.0) @ REC709_LUMA


def rms_contrast(y: np.ndarray) -> float:
    """Standard deviation (ddof 0) of the luma ``y``."""
    return float(np.std(y))


def gradient_magnitude(y: np.ndarray) -> np.ndarray:
    """(H, W) Sobel gradient magnitude of ``y`` / :data:`SOBEL_GAIN`, the border replicated."""
    p = np.pad(np.asarray(y, np.float64), 1, mode="edge")
    across = p[:, 2:] - p[:, :-2]                           # (H + 2, W): right minus left
    gx = across[:-2] + 2.0 * across[1:-1] + across[2:]
    down = p[2:, :] - p[:-2, :]                             # (H, W + 2): below minus above
    gy = down[:, :-2] + 2.0 * down[:, 1:-1] + down[:, 2:]
    return np.hypot(gx, gy) / SOBEL_GAIN


def edge_density(y: np.ndarray, threshold: float = EDGE_THRESHOLD) -> float:
    """Share of the pixels of ``y`` whose normalised Sobel magnitude exceeds ``threshold``."""
    return float(np.mean(gradient_magnitude(y) > threshold)) if np.size(y) else 0.0


def _read_rgb8(index: DatasetIndex, img: ImageSummary) -> np.ndarray:
    from synthua_usd.core.images import read_image

    path = image_file(index.root, img, img.rgb)
    expected = f"expected the {img.width}x{img.height} 8-bit RGB PNG of record {img.name}"
    try:
        pixels, _ = read_image(path)
    except OSError:
        raise InputError(f"{shown(path)}: not an image OpenImageIO can read; {expected}") from None
    h, w, c = pixels.shape
    if pixels.dtype != np.uint8 or c < 3 or (w, h) != (img.width, img.height):
        raise InputError(f"{shown(path)}: {w}x{h} pixels, {c} channel(s) of {pixels.dtype}; {expected}")
    return pixels


def image_measures(index: DatasetIndex, img: ImageSummary) -> dict[str, float]:
    """RMS contrast and edge density of the RGB of ``img``."""
    y = luma(_read_rgb8(index, img))
    return {"rms_contrast": rms_contrast(y), "edge_density": edge_density(y)}


def photo_measures(path) -> dict[str, float]:
    """RMS contrast and edge density of the image file at ``path`` (8- or 16-bit, grey or colour)."""
    from synthua_usd.core.images import read_image

    try:
        pixels, _ = read_image(path)
    except OSError:
        raise InputError(f"{shown(path)}: not an image OpenImageIO can read; expected a photo of the set") from None
    values = pixels.astype(np.float64) / 257.0 if pixels.dtype == np.uint16 else pixels
    if values.dtype != np.uint8 and pixels.dtype != np.uint16:
        raise InputError(f"{shown(path)}: pixels of {pixels.dtype}; expected an 8- or 16-bit image")
    if values.shape[2] < 3:
        values = np.repeat(values[..., :1], 3, axis=2)
    y = luma(values)
    return {"rms_contrast": rms_contrast(y), "edge_density": edge_density(y)}


def spread(values) -> dict:
    """Count, mean, median and :data:`PERCENTILES` of ``values`` (None for none)."""
    v = np.asarray(values, np.float64)
    if v.size == 0:
        return {"count": 0} | dict.fromkeys(SPREAD)
    numbers = [v.mean(), np.median(v), *np.percentile(v, PERCENTILES)]
    return {"count": int(v.size)} | {k: float(x) for k, x in zip(SPREAD, numbers)}


def summarise(per_image: list[dict]) -> dict:
    """The :func:`spread` of each measure over all of ``per_image`` (rows with ``split`` and the
    :data:`MEASURES`) and over the rows of each split."""
    def of(rows):
        return {m: spread([r[m] for r in rows]) for m in MEASURES}

    splits = sorted({r["split"] for r in per_image})
    return of(per_image) | {"per_split": {s: of([r for r in per_image if r["split"] == s]) for s in splits}}
