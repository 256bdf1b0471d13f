"""Writing a dataset smaller than it was rendered: RGB by a proper filter, label maps by mode or nearest.

* RGB: OpenImageIO's ``ImageBufAlgo.resize`` with the ``blackman-harris`` filter (OIIO's own choice for
  shrinking; its width scales with the reduction, so every source pixel contributes), on *linear* light
  (averaging sRGB codes would darken edges). The Blackman–Harris window is non-negative, so unlike
  Lanczos it neither rings nor makes negative values around bright lamps in an HDR image.
* Label maps (class ids, instance ids, and anything that must stay consistent with them): each output pixel
  copies one *source pixel*, never a blend, so no id appears that was not there (bilinear would invent
  classes at edges). For integer factors (W % w == 0 and H % h == 0) the source pixel is one carrying the
  most frequent label in its block; ties go to the smallest label (a rule that ignores pixel order, so
  resampling commutes with flips and transposes) and, among its pixels, to the first in row-major order.
  Otherwise the nearest pixel: source column ``floor((x + 0.5) W / w)`` in exact integer arithmetic.
* Several maps resampled together (:func:`resample_label_maps`) pick their source pixel by the mode of
  the *joint* label (e.g. (class, instance) pairs), so class and instance never disagree in an output pixel;
  depth and amodal pixel sets are gathered from the same source pixels (:func:`gather`,
  :func:`resample_pixel_set`), so depth belongs to the label it is written with and every visible pixel of
  an instance stays inside its amodal mask.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np


def _check_size(shape: tuple[int, int], width: int, height: int) -> None:
    h, w = shape
    for name, value, limit in (("width", width, w), ("height", height, h)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= value <= limit:
            raise ValueError(f"resample {name} = {value!r}; expected an integer 1..{limit} (the source {name})")


def resample_rgb(rgb_linear: np.ndarray, width: int, height: int) -> np.ndarray:
    """``rgb_linear`` ((H, W, C) float32, linear light) resized to (height, width, C) float32 by OpenImageIO's
    Blackman–Harris filter. The same size returns a copy."""
    import OpenImageIO as oiio

    src = np.ascontiguousarray(rgb_linear, dtype=np.float32)
    if src.ndim != 3:
        raise ValueError(f"expected an (H, W, C) image, got shape {src.shape}")
    _check_size(src.shape[:2], width, height)
    if (height, width) == src.shape[:2]:
        return src.copy()
    buf = oiio.ImageBuf(oiio.ImageSpec(src.shape[1], src.shape[0], src.shape[2], oiio.FLOAT))
    buf.set_pixels(oiio.ROI(), src)
    out = oiio.ImageBuf(oiio.ImageSpec(width, height, src.shape[2], oiio.FLOAT))
    # One thread: workers are processes already, and a fixed partition keeps the result reproducible.
    if not oiio.ImageBufAlgo.resize(out, buf, filtername="blackman-harris", nthreads=1):
        raise RuntimeError(f"OpenImageIO resize failed: {out.geterror()}")
    return np.asarray(out.get_pixels(oiio.FLOAT), dtype=np.float32).reshape(height, width, src.shape[2])


def nearest_index(shape: tuple[int, int], width: int, height: int) -> np.ndarray:
    """(height, width) int64 flat source indices (row-major, y W + x) of the pixel nearest each output pixel's
    centre in a source of ``shape`` (H, W)."""
    H, W = shape
    _check_size(shape, width, height)
    ys = (2 * np.arange(height, dtype=np.int64) + 1) * H // (2 * height)
    xs = (2 * np.arange(width, dtype=np.int64) + 1) * W // (2 * width)
    return ys[:, None] * W + xs[None, :]


def mode_index(labels: np.ndarray, width: int, height: int) -> np.ndarray:
    """(height, width) int64 flat source indices of the pixel chosen for each output pixel of ``labels``
    ((H, W) integers): by block mode for integer factors (ties: smallest label, then its first pixel in
    row-major order), by nearest pixel otherwise."""
    labels = np.asarray(labels)
    if labels.ndim != 2 or not np.issubdtype(labels.dtype, np.integer):
        raise ValueError(f"expected an (H, W) integer label map, got {labels.dtype} {labels.shape}")
    H, W = labels.shape
    _check_size(labels.shape, width, height)
    if H % height or W % width:
        return nearest_index(labels.shape, width, height)
    fy, fx = H // height, W // width
    k = fy * fx
    # (height*width, k) blocks of labels and of their source indices, each block in row-major order.
    index = np.arange(H * W, dtype=np.int64).reshape(height, fy, width, fx).transpose(0, 2, 1, 3).reshape(-1, k)
    block = labels.reshape(-1)[index]
    order = np.argsort(block, axis=1, kind="stable")
    keys = np.take_along_axis(block, order, axis=1)
    column = np.broadcast_to(np.arange(k), keys.shape)
    starts = np.ones(keys.shape, dtype=bool)
    starts[:, 1:] = keys[:, 1:] != keys[:, :-1]
    ends = np.ones(keys.shape, dtype=bool)
    ends[:, :-1] = starts[:, 1:]
    first = np.maximum.accumulate(np.where(starts, column, 0), axis=1)
    last = np.minimum.accumulate(np.where(ends, column, k - 1)[:, ::-1], axis=1)[:, ::-1]
    # argmax takes the first maximum: the start of the run of the smallest label among the most frequent;
    # the stable sort puts that label's first row-major pixel there.
    best = np.argmax(last - first + 1, axis=1)
    chosen = np.take_along_axis(order, best[:, None], axis=1)[:, 0]
    return np.take_along_axis(index, chosen[:, None], axis=1)[:, 0].reshape(height, width)


def gather(array: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``array`` ((H, W, ...) any dtype: labels, depth) at the source pixels ``index`` ((h, w) flat)."""
    array = np.asarray(array)
    return array.reshape(array.shape[0] * array.shape[1], *array.shape[2:])[index]


def resample_labels(ids: np.ndarray, width: int, height: int) -> np.ndarray:
    """``ids`` ((H, W) integers) at (height, width), same dtype: block mode for integer factors, nearest
    otherwise (see :func:`mode_index`)."""
    return gather(ids, mode_index(ids, width, height))


def joint_labels(maps: Mapping[str, np.ndarray]) -> np.ndarray:
    """(H, W) int64 codes of the tuples of ``maps``' values per pixel, ordered as the tuples are
    lexicographically (maps in the mapping's order), so the smallest-label tie rule carries over."""
    code = None
    for array in maps.values():
        values, inverse = np.unique(np.asarray(array), return_inverse=True)
        inverse = inverse.reshape(np.shape(array)).astype(np.int64)
        code = inverse if code is None else code * len(values) + inverse
        if code.size and int(code.max()) >= 2 ** 62:
            values, code = np.unique(code, return_inverse=True)
            code = code.reshape(np.shape(array)).astype(np.int64)
    if code is None:
        raise ValueError("expected at least one label map")
    return code


def resample_label_maps(maps: Mapping[str, np.ndarray], width: int, height: int,
                        ) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Resample several (H, W) label maps of one image together: each output pixel copies the same source
    pixel in every map, chosen by the mode of the joint label. Returns (resampled maps, the (height, width)
    flat source index, for :func:`gather` of depth and :func:`resample_pixel_set` of amodal masks)."""
    shapes = {np.shape(a) for a in maps.values()}
    if len(shapes) != 1:
        raise ValueError(f"label maps of different shapes: {sorted(shapes)}")
    index = mode_index(joint_labels(maps), width, height)
    return {name: gather(array, index) for name, array in maps.items()}, index


def resample_pixel_set(pixels: np.ndarray, source_shape: tuple[int, int], index: np.ndarray) -> np.ndarray:
    """A pixel set (sorted flat indices y W + x into ``source_shape``, e.g. an amodal mask) at the output size:
    the sorted flat output indices whose source pixel is in the set."""
    member = np.zeros(source_shape[0] * source_shape[1], dtype=bool)
    member[np.asarray(pixels, dtype=np.int64)] = True
    return np.flatnonzero(member[index.reshape(-1)]).astype(np.int64)
