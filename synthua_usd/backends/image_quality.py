"""Image quality of a render against a reference of the same view: PSNR and SSIM on display values.

Both metrics compare what a viewer sees, not raw radiance: a scene-linear render holds sky values of
hundreds and street values of a few hundredths, and an error in the sky would swamp everything else.
Both images are therefore

1. multiplied by the same exposure scale: the reference's (:func:`synthua_usd.backends.exposure.choose_exposure`,
   the rule ``rgb.png`` is made with) unless ``scale`` is given. ``rgb.png`` is metered over the pixels that see
   a surface; without that mask every pixel is metered, and a view with much sky or void beyond a twin's edge
   then gets another exposure than its ``rgb.png`` (a UAV view half void: 3,600 times brighter, every lit
   surface clipped to white, so that only its outline was scored). Benchmarks therefore pass
   ``reference_scale(reference, frame.hits.mesh_index >= 0)`` — the label pass's surface pixels;
2. encoded with the sRGB transfer function (IEC 61966-2-1, through colour-science's ``cctf_encoding``), in
   float: no 8-bit quantisation;
3. clipped to [0, 1], as ``rgb.png`` is.

PSNR is ``10 log10(1 / MSE)`` over all pixels and channels (peak 1). SSIM is scikit-image's
``structural_similarity`` with the settings of Wang et al. 2004 (Gaussian window, sigma 1.5, population
covariance, data range 1), averaged over the three channels. Identical images give PSNR ``inf`` and SSIM 1.

Plain numpy in, floats out: benchmarks and tests import this module; nothing here renders or writes files.
"""

from __future__ import annotations

import math

import numpy as np


def _checked(test: np.ndarray, reference: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    test = np.asarray(test, np.float32)
    reference = np.asarray(reference, np.float32)
    if test.ndim != 3 or test.shape[2] != 3:
        raise ValueError(f"test image: shape {test.shape}; expected (H, W, 3)")
    if test.shape != reference.shape:
        raise ValueError(f"test image {test.shape} and reference {reference.shape} differ in shape; expected the same view")
    if not (np.isfinite(test).all() and np.isfinite(reference).all()):
        raise ValueError("an image holds NaN or infinite values; expected finite scene-linear RGB")
    return test, reference


def reference_scale(reference: np.ndarray, metered: np.ndarray | None = None) -> float:
    """The exposure scale of (H, W, 3) scene-linear ``reference``, metered over the (H, W) bool mask ``metered``
    (the pixels that see a surface, as ``rgb.png`` is metered; None: all its pixels)."""
    from synthua_usd.backends.exposure import choose_exposure

    return choose_exposure(np.asarray(reference, np.float32), metered).scale


def display_values(rgb: np.ndarray, scale: float) -> np.ndarray:
    """(H, W, 3) float64 display values in [0, 1]: ``rgb × scale``, sRGB-encoded, clipped."""
    import colour

    linear = np.clip(np.asarray(rgb, np.float64) * float(scale), 0.0, None)
    return np.clip(colour.cctf_encoding(linear, function="sRGB"), 0.0, 1.0)


def display_pair(test: np.ndarray, reference: np.ndarray, scale: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Display values of ``test`` and ``reference`` at one exposure (``scale``, default the reference's)."""
    test, reference = _checked(test, reference)
    if scale is None:
        scale = reference_scale(reference)
    if not (math.isfinite(scale) and scale > 0):
        raise ValueError(f"exposure scale {scale!r}; expected a finite number > 0")
    return display_values(test, scale), display_values(reference, scale)


def psnr_db(test: np.ndarray, reference: np.ndarray, scale: float | None = None) -> float:
    """PSNR in dB of (H, W, 3) float32 scene-linear ``test`` against ``reference`` on display values (peak 1);
    ``inf`` when they are equal."""
    a, b = display_pair(test, reference, scale)
    mse = float(np.mean((a - b) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(1.0 / mse)


def reference_ceiling_db(half_a: np.ndarray, half_b: np.ndarray, scale: float | None = None) -> float:
    """The PSNR a noise-free image would score against the reference ``(half_a + half_b) / 2``, where the halves
    are renders of one view with the same settings and sample count but other seeds (independent noise).

    Their difference holds the noise of two halves, four times the noise of their mean, so the ceiling is
    ``PSNR(half_a, half_b) + 10 log10 4``; it holds for any sampler (the halves need not have noise falling as
    1/spp) and, on display values, to first order in the noise. Display values at ``scale`` (default: the mean's
    exposure). A measured PSNR near the ceiling measures the reference, not the test image."""
    a, b = _checked(half_a, half_b)
    if scale is None:
        scale = reference_scale((a + b) / 2)
    return psnr_db(a, b, scale) + 10.0 * math.log10(4.0)


def ssim(test: np.ndarray, reference: np.ndarray, scale: float | None = None) -> float:
    """Mean SSIM of (H, W, 3) float32 scene-linear ``test`` against ``reference`` on display values (Wang et al.
    2004 settings; images smaller than the 7×7 window are refused by scikit-image)."""
    from skimage.metrics import structural_similarity

    a, b = display_pair(test, reference, scale)
    return float(structural_similarity(a, b, channel_axis=2, data_range=1.0, gaussian_weights=True, sigma=1.5,
                                       use_sample_covariance=False))
