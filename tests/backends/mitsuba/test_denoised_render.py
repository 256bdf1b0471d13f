"""Denoised RGB through a render session: a measured gain against the 1024-spp reference, the guides' values,
and the same bytes from fresh and reused sessions."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import activate_variant
from reference_images import HEIGHT, WIDTH, reference_path, tiny_scene
from synthua_usd.core import images
from synthua_usd.backends.image_quality import psnr_db, ssim
from synthua_usd.backends.mitsuba.render import render_rgb
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.backends.mitsuba.translate import guide_integrator_dict
from synthua_usd.model.render_config import RenderConfig

GREY = (0.3, 0.3, 0.3)  # the ground's diffuseColor in tests/data/valid/tiny_lit_scene.usda


@pytest.fixture(scope="module")
def lit():
    return tiny_scene()


def _frame(lit, variant, denoise: bool, spp: int = 4, seed: int = 1):
    snapshot, camera = lit
    config = RenderConfig(width=WIDTH, height=HEIGHT, spp=spp, seed=seed, pixel_filter="box", denoise=denoise,
                          variant=variant)
    return RenderSession(config).render(snapshot, camera)


def _interior(mask: np.ndarray) -> np.ndarray:
    """Pixels of ``mask`` whose 8 neighbours are in it too (a whole pixel footprint on one surface)."""
    from scipy.ndimage import binary_erosion

    return binary_erosion(mask, structure=np.ones((3, 3), bool), border_value=0)


def test_denoising_measurably_improves_a_few_sample_render(lit, variant):
    reference = images.read_image(reference_path(variant))[0].astype(np.float32)  # 1024 spp, seed 0
    noisy = _frame(lit, variant, denoise=False)
    denoised = _frame(lit, variant, denoise=True)
    assert noisy.denoised is None and denoised.denoised["firefly_pixels"] >= 0
    gain = psnr_db(denoised.rgb, reference) - psnr_db(noisy.rgb, reference)
    assert gain > 5.0, gain
    assert ssim(denoised.rgb, reference) > ssim(noisy.rgb, reference)
    assert "denoise" in denoised.seconds and "denoise" not in noisy.seconds
    # The sky seen straight has no noise: it keeps its path-traced value exactly.
    sky = _interior(noisy.class_ids == 0)
    assert sky.sum() > 50 and np.array_equal(denoised.rgb[sky], noisy.rgb[sky])


def test_guides_are_the_first_hit_albedo_and_a_unit_normal_facing_the_camera(lit, variant):
    snapshot, camera = lit
    session = RenderSession(RenderConfig(width=WIDTH, height=HEIGHT, spp=4, variant=variant))
    frame = session.render(snapshot, camera)  # the first RGB frame makes the session's guide integrator
    result = render_rgb(session.mi, session._scene, session.config, guides=session._guides)
    assert result.albedo.shape == result.normal.shape == (HEIGHT, WIDTH, 3)
    inner = _interior(frame.class_ids == 1)
    assert inner.sum() > 100
    assert np.allclose(result.albedo[inner], GREY, atol=1e-5)
    normals = result.normal[inner]
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-4)
    assert np.allclose(normals, (0.0, 0.0, 1.0), atol=1e-4)  # the ground plane, Z up
    _, dirs = camera.pixel_center_rays(WIDTH, HEIGHT)
    assert np.all(np.einsum("ij,ij->i", normals, dirs[inner.ravel()]) < 0)  # facing the camera
    sky = _interior(frame.class_ids == 0)
    assert sky.any() and not result.albedo[sky].any() and not result.normal[sky].any()


def test_separate_guide_pass_equals_guides_of_the_wrapped_path_tracer(lit):
    """The claim behind rendering guides in a pass of their own on JIT variants: same seed and spp, same film
    positions (the scalar variant draws a pixel's samples from one sequence and takes the wrapped integrator)."""
    snapshot, camera = lit
    activate_variant("llvm_ad_rgb")
    session = RenderSession(RenderConfig(width=WIDTH, height=HEIGHT, spp=4, variant="llvm_ad_rgb"))
    session.render(snapshot, camera, rgb=False)
    mi, scene = session.mi, session._scene
    wrapped = mi.load_dict(guide_integrator_dict(session.config))
    both = np.asarray(mi.render(scene, integrator=wrapped, spp=4, seed=11))
    alone = np.asarray(mi.render(scene, integrator=mi.load_dict(guide_integrator_dict()), spp=4, seed=11))
    plain = np.asarray(mi.render(scene, spp=4, seed=11))
    assert np.array_equal(both[..., 3:9], alone[..., :6])
    assert np.array_equal(both[..., :3], plain[..., :3])


def test_denoised_rgb_is_bit_identical_between_sessions():
    activate_variant("llvm_ad_rgb")
    lit = tiny_scene()
    a = _frame(lit, "llvm_ad_rgb", denoise=True, seed=2)
    b = _frame(lit, "llvm_ad_rgb", denoise=True, seed=2)
    assert np.array_equal(a.rgb, b.rgb)
