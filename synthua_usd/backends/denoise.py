"""Denoising a few-sample path-traced image: a firefly filter, then Intel Open Image Denoise (PyPI ``pyoidn``).

Why this order and these inputs:

* OIDN's ``RT`` filter removes Monte Carlo noise that is independent from pixel to pixel. The noisy image
  must therefore be rendered with a **box** pixel filter (each sample lands in its own pixel); a Gaussian
  filter splats samples into neighbours, correlates the noise, and the denoiser mistakes it for detail
  (measured: +0.5 dB with a Gaussian filter against the large gain with a box filter).
* It is guided by the **albedo** and the **shading normal** of the first hit, at the same film positions as
  the colour's samples (Mitsuba's ``aov`` integrator with the colour pass's seed and sample count;
  :func:`synthua_usd.backends.mitsuba.render.render_rgb`). They carry no lighting noise, but at a few samples
  per pixel their edges are anti-aliased from those few samples only, so the filter runs **without**
  ``cleanAux`` (OIDN then treats the guides as possibly noisy): measured on the district at 4 spp, +0.85,
  +0.24, +1.06 and 0.00 dB PSNR on four views against ``cleanAux`` on, and equal at 8 spp
  (``tools/bench_denoise.py``, docs/rendering.md).
* The colour is HDR scene-linear radiance (``hdr``): exposure is chosen afterwards, from the denoised image.
* **Fireflies.** Mitsuba's ``path`` integrator gives no access to single samples, so samples are not clamped;
  instead :func:`suppress_fireflies` runs before OIDN: a pixel whose luminance exceeds ``FIREFLY_RATIO`` times
  the brightest of its 8 neighbours is an isolated spike (a rare light path found by one sample) and is
  scaled down to that bound, hue kept. Isolated spikes are what a denoiser smears into blotches; a
  bright region (a lamp, a sunlit wall) has bright neighbours and is never touched. The share of pixels
  touched is logged and returned.

Determinism: the CPU device gives the same bytes for the same input run after run and with 1, 2 or 4
threads (tested in ``tests/backends/test_denoise.py``); datasets rely on it for byte-identical reruns.
The device is created once per :class:`Denoiser` (a render session holds one) and released with it.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from synthua_usd.model.photometry import luminance

log = logging.getLogger(__name__)

#: A pixel brighter than this many times its brightest neighbour is a firefly (see the module docstring).
FIREFLY_RATIO = 4.0
#: OIDN's memory limit per filter: it denoises larger images in overlapping tiles. Measured at 1280x960: peak
#: memory 531 MiB against 787 MiB without a limit, the same bytes out, no slower.
MAX_MEMORY_MB = 512
#: OIDN measures an HDR image's exposure over bins of this many pixels a side: a box denoised alone starts on
#: a multiple of it (:meth:`Denoiser.denoise_pass`'s ``margin``).
BIN_PX = 16


class DenoiserError(RuntimeError):
    """OIDN failed (device creation, filter set-up or execution); the message carries OIDN's own."""


@dataclass(frozen=True)
class FireflyReport:
    """What :func:`suppress_fireflies` changed: ``pixels`` touched, their ``share`` of the image, and the
    radiance removed as a share of the image's total luminance (``energy_share``)."""

    pixels: int
    share: float
    energy_share: float


def suppress_fireflies(rgb: np.ndarray, ratio: float = FIREFLY_RATIO) -> tuple[np.ndarray, FireflyReport]:
    """(H, W, 3) float32 scene-linear ``rgb`` with isolated spikes scaled down to ``ratio`` × the brightest
    of their 8 neighbours' luminance (hue kept), and a report. A new array; ``rgb`` is not changed."""
    from scipy.ndimage import maximum_filter

    rgb = np.asarray(rgb, np.float32)
    lum = np.maximum(luminance(rgb), 0.0).astype(np.float32)
    ring = np.ones((3, 3), bool)
    ring[1, 1] = False
    neighbours = maximum_filter(lum, footprint=ring, mode="nearest")
    bound = np.float32(ratio) * neighbours
    spikes = lum > bound
    out = rgb.copy()
    total = float(lum.sum(dtype=np.float64))
    removed = 0.0
    if spikes.any():
        factor = bound[spikes] / lum[spikes]
        out[spikes] *= factor[:, None]
        removed = float(np.sum(lum[spikes] - bound[spikes], dtype=np.float64))
    n = int(spikes.sum())
    report = FireflyReport(pixels=n, share=n / spikes.size, energy_share=removed / total if total > 0 else 0.0)
    if n:
        log.debug("fireflies: %d pixels (%.4f%%) scaled down, %.4f%% of the luminance", n, 100 * report.share,
                  100 * report.energy_share)
    return out, report


def _import_pyoidn():
    """``pyoidn``, imported without torch.

    pyoidn imports torch at import time whenever it is installed (only its tensor interop uses it). We pass
    NumPy arrays, so that costs every render process torch's start-up, and torch's exit handlers make
    OpenImageIO's bindings print "nanobind: leaked ..." after our last line. Hiding torch while pyoidn loads
    makes it take its no-torch path; torch stays importable afterwards for whoever needs it."""
    import sys

    if "pyoidn" in sys.modules or "torch" in sys.modules:
        import pyoidn

        return pyoidn
    sys.modules["torch"] = None  # a None entry makes `import torch` raise ImportError
    try:
        import pyoidn
    finally:
        del sys.modules["torch"]
    return pyoidn


def _checked(color, albedo, normal) -> dict[str, np.ndarray]:
    """The three images as contiguous float32 (H, W, 3), by OIDN's names; a guide of another shape is refused."""
    images = {}
    for name, image in (("color", color), ("albedo", albedo), ("normal", normal)):
        image = np.ascontiguousarray(image, np.float32)
        if image.ndim != 3 or image.shape[2] != 3 or image.shape != np.shape(color):
            raise ValueError(f"denoiser {name}: shape {image.shape}; expected (H, W, 3) like color "
                             f"{np.shape(color)}")
        images[name] = image
    return images


def _hit_box(hit: np.ndarray, margin: int) -> tuple[int, int, int, int] | None:
    """(y0, y1, x0, x1) of the pixels ``hit`` (H, W) widened by ``margin``, from a multiple of :data:`BIN_PX` and
    a multiple of it long (or to the image's edge); None where nothing is hit, where the box is the whole image,
    and where the image's sides are not multiples of :data:`BIN_PX` (OIDN spreads its bins evenly over the image:
    only then do they fall on those multiples, so that a box sees the exposure the whole image would)."""
    rows, cols = np.flatnonzero(hit.any(axis=1)), np.flatnonzero(hit.any(axis=0))
    h, w = hit.shape
    if not len(rows) or h % BIN_PX or w % BIN_PX:
        return None
    box = []
    for first, last, size in ((rows[0], rows[-1], h), (cols[0], cols[-1], w)):
        start = max(0, first - margin) // BIN_PX * BIN_PX
        end = min(size, start + -(-(last + 1 + margin - start) // BIN_PX) * BIN_PX)
        box += [start, end]
    return None if box == [0, h, 0, w] else (box[0], box[1], box[2], box[3])


class Denoiser:
    """Intel Open Image Denoise's ``RT`` filter on the CPU, guided by albedo and normal.

    ``num_threads`` None lets OIDN use every core it sees (the result does not depend on it). Use it as a
    context manager or call :meth:`close`; a session keeps one for all its frames.
    """

    def __init__(self, num_threads: int | None = None) -> None:
        try:
            pyoidn = _import_pyoidn()
        except ImportError as exc:  # an optional-looking import, but a core dependency: say how to fix it
            raise DenoiserError(f"denoising needs the pyoidn package ({exc}); install it with "
                                f"`pip install -c constraints.txt pyoidn` or render with denoise off") from None
        self._oidn = pyoidn
        if not pyoidn.Device.is_cpu_available():
            raise DenoiserError("OIDN has no CPU device on this machine (it needs SSE4.1 or NEON); "
                                "render with denoise off")
        self._device = pyoidn.Device(pyoidn.OIDN_DEVICE_TYPE_CPU)
        if num_threads is not None:
            self._device.set_int("numThreads", int(num_threads))
        # No thread pinning: the render (Mitsuba's own threads) and other workers share the cores.
        self._device.set_bool("setAffinity", False)
        self._device.commit()
        self._check("device creation")

    def _check(self, what: str) -> None:
        message = self._device.get_error()
        if message is not None:
            raise DenoiserError(f"OIDN {what} failed: {message}")

    @property
    def num_threads(self) -> int:
        return int(self._device.get_int("numThreads"))

    def __call__(self, color: np.ndarray, albedo: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """(H, W, 3) float32 denoised radiance from HDR scene-linear ``color``, ``albedo`` in [0, 1] and
        ``normal`` (components in [-1, 1], any consistent space; 0 where nothing is hit), all (H, W, 3)."""
        pyoidn = self._oidn
        images = _checked(color, albedo, normal)
        output = np.zeros_like(images["color"])
        flt = pyoidn.Filter(self._device, pyoidn.OIDN_FILTER_TYPE_RT)
        try:
            for name, image in images.items():
                flt.set_image(name, image, pyoidn.OIDN_FORMAT_FLOAT3)
            flt.set_image(pyoidn.OIDN_IMAGE_OUTPUT, output, pyoidn.OIDN_FORMAT_FLOAT3)
            flt.set_bool("hdr", True)
            flt.set_bool("cleanAux", False)  # few-sample guides: see the module docstring
            flt.set_quality(pyoidn.OIDN_QUALITY_HIGH)
            flt.set_int("maxMemoryMB", MAX_MEMORY_MB)
            flt.commit()
            self._check("filter set-up")
            flt.execute()
            self._check("denoising")
        finally:
            flt.release()
        return output

    def denoise_pass(self, color: np.ndarray, albedo: np.ndarray, normal: np.ndarray,
                     margin: int | None = None) -> tuple[np.ndarray, FireflyReport]:
        """A path-traced pass, (H, W, 3) float32 each, denoised: :func:`suppress_fireflies`, then OIDN; pixels
        whose every sample escaped to the environment (normal guide exactly 0) keep their value, since the sky
        seen straight has no Monte Carlo noise and OIDN would only add its own small error to it (measured:
        about 1.5 % on a constant sky).

        With ``margin`` (pixels), OIDN sees only the box of the pixels something was hit in, widened by
        ``margin`` and from a multiple of :data:`BIN_PX` (OIDN's exposure bins then fall as in the whole image;
        an image whose sides are not multiples of it is denoised whole): for a small subject on an empty frame (a
        cut-out), where the rest keeps its value anyway. The
        hit pixels then differ from the whole image's by what OIDN's view beyond the margin would have added
        (64 pixels: at most 3e-5 of their mean and 0.2 % of the brightest, on frames of the cut-out bank)."""
        images = _checked(color, albedo, normal)
        cleaned, report = suppress_fireflies(images["color"])
        normal = images["normal"]
        sky = (normal[..., 0] == 0) & (normal[..., 1] == 0) & (normal[..., 2] == 0)    # ~any(axis=2), faster
        box = _hit_box(~sky, margin) if margin is not None else None
        if box is None:
            out = self(cleaned, images["albedo"], normal)
        else:
            y0, y1, x0, x1 = box
            out = cleaned.copy()
            out[y0:y1, x0:x1] = self(*(np.ascontiguousarray(image[y0:y1, x0:x1])
                                       for image in (cleaned, images["albedo"], normal)))
        out[sky] = images["color"][sky]
        return out, report

    def close(self) -> None:
        if self._device is not None:
            self._device.release()
            self._device = None

    def __enter__(self) -> "Denoiser":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:  # a session dropped without close() still frees OIDN's memory
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown: the library may already be gone
            pass
