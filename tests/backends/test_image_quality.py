"""PSNR and SSIM on display values, checked against values computed by hand."""

import math

import numpy as np
import pytest

from synthua_usd.backends.exposure import choose_exposure
from synthua_usd.backends.image_quality import display_values, psnr_db, reference_ceiling_db, reference_scale, ssim


def srgb_decode(v: float) -> float:
    """The scene-linear value whose sRGB encoding is ``v`` (IEC 61966-2-1, written out here by hand)."""
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4


def test_display_values_are_srgb_encoded_and_clipped():
    rgb = np.array([[[0.0, 1.0, 4.0], [srgb_decode(0.5), 0.002, -1.0]]], np.float32)
    shown = display_values(rgb, 1.0)
    assert shown[0, 0] == pytest.approx([0.0, 1.0, 1.0], abs=1e-12)  # above 1 clips, as rgb.png does
    assert shown[0, 1, 0] == pytest.approx(0.5, abs=1e-6)
    assert shown[0, 1, 1] == pytest.approx(0.002 * 12.92, abs=1e-7)  # the linear toe
    assert shown[0, 1, 2] == 0.0
    darker = display_values(rgb, 0.25)  # 4.0 x 0.25 is white; 1.0 x 0.25 is not
    assert darker[0, 0, 2] == pytest.approx(1.0, abs=1e-12) and darker[0, 0, 1] < 0.6


def test_psnr_of_one_wrong_value_by_hand():
    reference = np.zeros((8, 8, 3), np.float32)
    test = reference.copy()
    test[3, 4, 1] = 1.0  # display 1 against 0: squared error 1 in one of 192 values
    assert psnr_db(test, reference, scale=1.0) == pytest.approx(10 * math.log10(192), abs=1e-9)
    half = reference + np.float32(srgb_decode(0.5))
    # every value off by 0.5 on display: MSE 0.25, PSNR 10 log10(4)
    assert psnr_db(half, reference, scale=1.0) == pytest.approx(10 * math.log10(4), abs=1e-4)
    assert psnr_db(reference, reference, scale=1.0) == math.inf


def test_psnr_uses_the_reference_exposure_by_default():
    rng = np.random.default_rng(0)
    reference = rng.uniform(0.01, 0.2, (16, 16, 3)).astype(np.float32)
    test = reference * rng.uniform(0.9, 1.1, reference.shape).astype(np.float32)
    scale = choose_exposure(reference).scale
    assert psnr_db(test, reference) == psnr_db(test, reference, scale=scale)
    # Exposure follows the reference: the same scene 8x brighter scores the same (within float rounding).
    assert psnr_db(test * 8, reference * 8) == pytest.approx(psnr_db(test, reference), abs=1e-3)


def test_reference_scale_meters_the_masked_pixels_as_rgb_png_is_metered():
    # Half the view is black void beyond a twin's edge: metered over every pixel, the log-average falls to
    # the void's and the lit street is exposed thousands of times too bright; over the surface pixels it is
    # the street's own exposure.
    street = np.full((8, 16, 3), 0.05, np.float32)
    view = np.concatenate([np.zeros_like(street), street])
    surface = np.concatenate([np.zeros((8, 16), bool), np.ones((8, 16), bool)])
    assert reference_scale(view, surface) == pytest.approx(reference_scale(street), rel=1e-6)
    assert reference_scale(view) > 1000 * reference_scale(view, surface)
    assert display_values(view, reference_scale(view))[8:].min() == 1.0  # every lit pixel clipped


def test_ssim_of_constant_images_by_hand():
    # For constant images x and y, SSIM = (2xy + C1) / (x^2 + y^2 + C1): the contrast-structure term is C2 / C2.
    c1 = (0.01 * 1.0) ** 2
    a = np.full((16, 16, 3), srgb_decode(0.5), np.float32)
    b = np.full((16, 16, 3), srgb_decode(0.25), np.float32)
    expected = (2 * 0.5 * 0.25 + c1) / (0.5 ** 2 + 0.25 ** 2 + c1)
    assert ssim(b, a, scale=1.0) == pytest.approx(expected, abs=1e-5)
    assert ssim(a, a, scale=1.0) == pytest.approx(1.0)


def test_ssim_falls_with_noise_and_is_symmetric():
    rng = np.random.default_rng(1)
    reference = np.tile(np.linspace(0.02, 0.3, 32, dtype=np.float32)[None, :, None], (24, 1, 3))
    slightly = reference * (1 + 0.05 * rng.standard_normal(reference.shape)).astype(np.float32)
    very = reference * (1 + 0.5 * rng.standard_normal(reference.shape)).astype(np.float32)
    assert 1.0 > ssim(slightly, reference, scale=1.0) > ssim(very, reference, scale=1.0)
    assert ssim(slightly, reference, scale=1.0) == pytest.approx(ssim(reference, slightly, scale=1.0))


def test_refuses_mismatched_or_non_finite_images():
    a = np.zeros((8, 8, 3), np.float32)
    with pytest.raises(ValueError, match="differ in shape"):
        psnr_db(a, np.zeros((8, 9, 3), np.float32))
    with pytest.raises(ValueError, match=r"expected \(H, W, 3\)"):
        ssim(np.zeros((8, 8), np.float32), a)
    b = a.copy()
    b[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        psnr_db(b, a)
    with pytest.raises(ValueError, match="exposure scale"):
        psnr_db(a, a, scale=0.0)


def test_reference_ceiling_from_two_halves_matches_a_noise_free_image():
    """Two half-references of a known truth with independent noise: a noise-free image (the truth) scores against
    their mean what the ceiling says, within 0.1 dB (display values; noise small against the signal)."""
    rng = np.random.default_rng(5)
    truth = rng.uniform(0.05, 0.2, (240, 320, 3)).astype(np.float32)
    a = truth + rng.normal(0.0, 0.004, truth.shape).astype(np.float32)
    b = truth + rng.normal(0.0, 0.004, truth.shape).astype(np.float32)
    reference = (a + b) / 2
    scale = 2.0
    assert reference_ceiling_db(a, b, scale) == pytest.approx(psnr_db(truth, reference, scale), abs=0.1)
    # with less noise in the halves the ceiling rises by the ratio of the variances
    a2 = truth + (a - truth) / 2
    b2 = truth + (b - truth) / 2
    assert reference_ceiling_db(a2, b2, scale) - reference_ceiling_db(a, b, scale) == pytest.approx(6.02, abs=0.1)
