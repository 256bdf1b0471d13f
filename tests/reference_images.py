"""RGB reference images of a tiny scene, and the statistical comparison renders must pass against them.

One owner for the facts both sides use: ``tools/make_refs.py`` (``make refs``) writes the references with
:func:`render_reference`; ``tests/backends/mitsuba/test_reference_images.py`` renders :func:`render_passes`
and calls :func:`compare`.

Why this comparison. A reference is one render at ``REF_SPP`` samples per pixel; a test renders
``PASSES`` independent passes (other seeds) of ``PASS_SPP`` each. Both use the box pixel filter, so each
pixel is the plain mean of its own samples: pixels are independent and unbiased, whatever the seeds or
the Mitsuba version draw. The spread of the passes measures the noise, so no tolerance is guessed:

* per region (every instance of the exact label map, and the sky), per channel: the region's mean over
  its pixels in each pass gives ``PASSES`` values; Student's t of their mean against the reference's
  region mean (the reference's own noise added) must stay below ``REGION_T``. A material colour, a light
  or a transform that changes moves a whole region's mean, far beyond a few standard errors.
* per pixel: t of the pass mean against the reference; at most ``OUTLIER_SHARE`` of the values may
  exceed ``PIXEL_T`` (by chance about 0.1 % do), which catches changes smaller than a region (a shadow,
  an edge). Pixels whose passes all agree exactly (sky seen straight) must match the reference to float
  rounding.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.stage_io import open_stage

TESTS = Path(__file__).resolve().parent
SCENE = TESTS / "data" / "valid" / "tiny_lit_scene.usda"
CAMERA = "/World/Cam"
REFS = TESTS / "data" / "refs"
WIDTH, HEIGHT = 64, 48
REF_SPP, REF_SEED = 1024, 0
PASSES, PASS_SPP = 16, 8
#: Two-sided p of about 1e-5 for Student's t with 15 degrees of freedom; with 4 regions x 3 channels
#: a correct render fails by chance about once in 10,000 runs.
REGION_T = 6.5
#: |t| > 4 happens by chance for about 0.1 % of pixel values (t with 15 degrees of freedom).
PIXEL_T = 4.0
OUTLIER_SHARE = 0.01


def reference_path(variant: str) -> Path:
    return REFS / f"tiny_{variant}.exr"


def tiny_scene(class_map: ClassMap | None = None):
    """(snapshot, camera) of the reference scene at its only time code."""
    stage = open_stage(SCENE)
    return read_snapshot(stage, 1.0, class_map or ClassMap.default()), read_camera(stage, CAMERA, 1.0)


def _render(snapshot, camera, variant: str, spp: int, seed: int):
    # The path tracer itself, not denoised: the comparison relies on independent, unbiased pixels.
    config = RenderConfig(width=WIDTH, height=HEIGHT, spp=spp, seed=seed, pixel_filter="box", denoise=False,
                          variant=variant)
    return RenderSession(config).render(snapshot, camera)


def render_reference(snapshot, camera, variant: str) -> np.ndarray:
    """(H, W, 3) float32: the reference image of ``variant``."""
    return _render(snapshot, camera, variant, REF_SPP, REF_SEED).rgb


def render_passes(snapshot, camera, variant: str) -> tuple[np.ndarray, np.ndarray]:
    """((PASSES, H, W, 3) float32 independent passes, (H, W) uint16 instance map)."""
    frames = [_render(snapshot, camera, variant, PASS_SPP, seed) for seed in range(1, PASSES + 1)]
    return np.stack([f.rgb for f in frames]), frames[0].instance_ids


@dataclass
class Comparison:
    """``region_t``: instance id (0 = sky) -> per-channel t; ``outlier_share`` of pixel values beyond
    PIXEL_T; ``exact_mismatch``: noiseless pixel values that differ from the reference."""

    region_t: dict[int, np.ndarray]
    outlier_share: float
    exact_mismatch: int
    problems: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.problems


def compare(reference: np.ndarray, passes: np.ndarray, instance_ids: np.ndarray) -> Comparison:
    """Compare ``passes`` (k, H, W, 3) with ``reference`` (H, W, 3) region by region and pixel by pixel."""
    k = len(passes)
    # The reference's own noise: REF_SPP samples against k * PASS_SPP, as a factor on the variance.
    ref_share = k * PASS_SPP / REF_SPP
    region_t = {}
    for inst in np.unique(instance_ids):
        mask = instance_ids == inst
        means = passes[:, mask].mean(axis=1)  # (k, 3)
        se = means.std(axis=0, ddof=1) / np.sqrt(k) * np.sqrt(1 + ref_share)
        diff = means.mean(axis=0) - reference[mask].mean(axis=0)
        region_t[int(inst)] = np.where(se > 0, diff / np.where(se > 0, se, 1), np.where(np.abs(diff) > 1e-5, np.inf, 0))
    mean = passes.mean(axis=0)
    se = passes.std(axis=0, ddof=1) / np.sqrt(k) * np.sqrt(1 + ref_share)
    noisy = se > 0
    t = np.abs(mean - reference)[noisy] / se[noisy]
    outliers = float(np.mean(t > PIXEL_T)) if t.size else 0.0
    exact = int(np.sum(~np.isclose(mean[~noisy], reference[~noisy], rtol=1e-5, atol=1e-6)))
    result = Comparison(region_t, outliers, exact)
    for inst, tv in region_t.items():
        if np.any(np.abs(tv) > REGION_T):
            result.problems.append(f"instance {inst}: region mean t = {np.round(tv, 2).tolist()}, beyond {REGION_T}")
    if outliers > OUTLIER_SHARE:
        result.problems.append(f"{outliers:.2%} of pixel values beyond t = {PIXEL_T}; expected at most {OUTLIER_SHARE:.0%}")
    if exact:
        result.problems.append(f"{exact} noiseless pixel values differ from the reference")
    return result
