"""Camera effects on an 8-bit image (synthua_usd/backends/camera_effects.py), each held to a computation of its own:
the thin lens's circle of confusion from the lens equation, the impulse response of the defocus and motion blurs
(moments of a disc and of a line, scipy.ndimage's direct convolution), the cos⁴ law of the vignette, the mean and
variance of Poisson-Gaussian noise, colour-science's sRGB curve for exposure and white balance, and Pillow's own
JPEG round trip."""

from __future__ import annotations

import io
import math

import colour
import numpy as np
import pytest
from PIL import Image
from scipy import ndimage

from synthua_usd.backends import camera_effects as ce
from synthua_usd.randomisation.effects import (Defocus, EffectsDraw, Exposure, Jpeg, MotionBlur, Noise, Vignetting,
                                               WhiteBalance)


def _moments(kernel: np.ndarray) -> tuple[float, float, float, float, float]:
    """(total, centroid x, centroid y, covariance xx, yy, xy) of ``kernel`` about its weighted centroid, pixels."""
    ys, xs = np.indices(kernel.shape, dtype=np.float64)
    total = kernel.sum()
    cx, cy = (kernel * xs).sum() / total, (kernel * ys).sum() / total
    xx = (kernel * (xs - cx) ** 2).sum() / total
    yy = (kernel * (ys - cy) ** 2).sum() / total
    xy = (kernel * (xs - cx) * (ys - cy)).sum() / total
    return total, cx, cy, xx, yy, xy


def _impulse(size: int = 41) -> np.ndarray:
    image = np.zeros((size, size, 3))
    image[size // 2, size // 2] = 1.0
    return image


def test_circle_of_confusion_follows_the_thin_lens():
    """r(d) / r(∞) = |1 - S/d|: the blur disc's diameter from the lens equation 1/f = 1/d + 1/v and similar triangles
    (c = A |v_d - v_S| / v_d, the sensor at v_S), for a 4 mm lens focused at 3 m; depth 0 (nothing hit) is infinity;
    the cap at 4 r(∞)."""
    f, aperture, focus = 0.004, 0.002, 3.0
    v_s = 1 / (1 / f - 1 / focus)

    def coc(d):
        v_d = f if math.isinf(d) else 1 / (1 / f - 1 / d)
        return aperture * abs(v_d - v_s) / v_d

    depths = np.array([0.7, 1.0, 2.0, 3.0, 4.5, 10.0, 100.0])
    ours = ce.defocus_radii(depths, focus, 2.0) / 2.0
    np.testing.assert_allclose(ours, [coc(d) / coc(math.inf) for d in depths], rtol=1e-9)
    assert ce.defocus_radii(np.array([0.0, np.inf, 0.1]), focus, 2.0).tolist() == [2.0, 2.0, 2.0 * ce.MAX_DEFOCUS_FACTOR]


def _disc_areas(radius: float, half: int) -> np.ndarray:
    """(2 half + 1)² areas of a disc of ``radius`` centred on the middle pixel's centre within each pixel, by shapely's
    polygon intersection (the disc a 1024-gon), normalised to sum 1."""
    from shapely.geometry import Point, box

    disc = Point(0.0, 0.0).buffer(radius, quad_segs=256)
    n = 2 * half + 1
    areas = np.array([[disc.intersection(box(x - 0.5, y - 0.5, x + 0.5, y + 0.5)).area for x in range(-half, half + 1)]
                      for y in range(-half, half + 1)]).reshape(n, n)
    return areas / areas.sum()


@pytest.mark.parametrize("radius", [1.0, 2.5, 4.0])
def test_defocus_of_an_impulse_is_a_disc(radius):
    """At one depth every pixel's radius is one: the impulse spreads as the share of each pixel a disc of that
    radius covers (shapely's exact areas; ours are sampled at 16 x 16 points a pixel), nothing beyond r + 1/√2 of
    the centre, its total conserved and its second moments those of the exact areas."""
    image = _impulse()
    out = ce.defocus(image, np.full(image.shape[:2], radius))[..., 0]
    total, cx, cy, xx, yy, xy = _moments(out)
    assert total == pytest.approx(1.0, abs=1e-12) and (cx, cy) == (pytest.approx(20), pytest.approx(20))
    exact = np.zeros_like(out)
    half = int(radius) + 1
    exact[20 - half:21 + half, 20 - half:21 + half] = _disc_areas(radius, half)
    assert np.max(np.abs(out - exact)) < 0.02 * exact.max()
    _, _, _, exx, eyy, _ = _moments(exact)
    assert xx == pytest.approx(exx, rel=0.015) and yy == pytest.approx(eyy, rel=0.015) and abs(xy) < 1e-9
    ys, xs = np.indices(out.shape)
    assert np.all(out[np.hypot(xs - 20, ys - 20) > radius + math.sqrt(0.5)] < 1e-12)


def test_defocus_blurs_by_depth_and_keeps_the_focused_part():
    """Left half at the focus distance: unchanged. Right half at infinity: the image convolved (scipy.ndimage,
    direct, border replicated) with the disc of r(∞), away from the seam."""
    rng = np.random.default_rng(1)
    image = rng.uniform(0, 1, (40, 60, 3))
    depth = np.full((40, 60), 3.0)
    depth[:, 30:] = 0.0                                           # nothing hit: infinitely far
    out = ce.defocus(image, ce.defocus_radii(depth, 3.0, 2.0))
    np.testing.assert_array_equal(out[:, :30], image[:, :30])
    kernel = ce.disc_kernel(2.0)
    direct = np.stack([ndimage.convolve(image[..., c], kernel, mode="nearest") for c in range(3)], axis=-1)
    np.testing.assert_allclose(out[:, 34:], direct[:, 34:], atol=1e-9)


@pytest.mark.parametrize("length, angle", [(9.0, 0.0), (12.0, 30.0), (7.0, 90.0), (10.0, 135.0)])
def test_motion_blur_of_an_impulse_is_a_line(length, angle):
    """The impulse spreads along a centred segment at the angle: its principal axis at ``angle`` (from +x towards
    +y, rows down), its variance along it L²/12 (uniform over the length) plus what bilinear sharing between
    neighbouring pixels adds (at most 1/4 on either axis), across it no more than that."""
    out = ce.convolve(_impulse(), ce.line_kernel(length, angle))[..., 0]
    total, cx, cy, xx, yy, xy = _moments(out)
    assert total == pytest.approx(1.0, abs=1e-12) and cx == pytest.approx(20, abs=1e-9) and cy == pytest.approx(20, abs=1e-9)
    axis = 0.5 * math.degrees(math.atan2(2 * xy, xx - yy)) % 180
    assert min(abs(axis - angle), 180 - abs(axis - angle)) < 0.5
    a = math.radians(angle)
    along = xx * math.cos(a) ** 2 + yy * math.sin(a) ** 2 + 2 * xy * math.sin(a) * math.cos(a)
    across = xx * math.sin(a) ** 2 + yy * math.cos(a) ** 2 - 2 * xy * math.sin(a) * math.cos(a)
    assert length ** 2 / 12 - 0.01 < along < length ** 2 / 12 + 0.25 and across < 0.25


def test_motion_blur_along_a_stripe_leaves_it_and_across_spreads_it():
    image = np.zeros((30, 40, 3))
    image[15] = 1.0
    along = ce.convolve(image, ce.line_kernel(8.0, 0.0))
    np.testing.assert_allclose(along, image, atol=1e-12)
    across = ce.convolve(image, ce.line_kernel(8.0, 90.0))[:, 20, 0]
    assert across.sum() == pytest.approx(1.0) and np.count_nonzero(across > 1e-9) in (9, 10)


def test_vignetting_is_the_cos4_law():
    """g(ρ) = cos⁴ θ with tan θ = ρ tan θ_c, θ_c the corner's field angle where cos⁴ θ_c = 1 - loss; through
    apply_effects on a flat grey, read back through colour-science's sRGB decoding, within 8-bit rounding."""
    loss = 0.3
    h, w = 48, 64
    theta_c = math.acos((1 - loss) ** 0.25)
    ys, xs = np.indices((h, w))
    rho = np.hypot(xs + 0.5 - w / 2, ys + 0.5 - h / 2) / math.hypot(w / 2, h / 2)
    expected = np.cos(np.arctan(rho * math.tan(theta_c))) ** 4
    np.testing.assert_allclose(ce.vignetting_gain(h, w, loss), expected, rtol=1e-12)
    grey = np.full((h, w, 3), 200, np.uint8)
    out = ce.apply_effects(grey, EffectsDraw(vignetting=Vignetting(loss)))
    decode = lambda v: colour.cctf_decoding(v / 255.0, function="sRGB")  # noqa: E731
    gain = decode(out[..., 1].astype(float)) / decode(200.0)
    step = decode(201.0) / decode(200.0) - 1                   # one 8-bit step, relative
    assert np.max(np.abs(gain - expected)) < step
    corner = min(gain[0, 0], gain[-1, -1])
    assert corner == pytest.approx(1 - loss, abs=0.02)


@pytest.mark.parametrize("x, gain, sigma", [(0.2, 0.002, 0.004), (0.6, 0.0005, 0.0), (0.05, 0.0, 0.01)])
def test_noise_has_the_poisson_gaussian_mean_and_variance(x, gain, sigma):
    """Over a million values of one level x: mean x, variance g·x + σ² (3 % covers the estimates' spread); the
    same seed gives the same field; without read noise every value is a whole number of electrons."""
    flat = np.full((500, 700, 3), x)
    noisy = ce.add_noise(flat, gain, sigma, seed=7)
    expected_sd = math.sqrt(gain * x + sigma ** 2)
    assert noisy.mean() == pytest.approx(x, abs=5 * expected_sd / math.sqrt(noisy.size))
    assert noisy.var() == pytest.approx(gain * x + sigma ** 2, rel=0.03)
    np.testing.assert_array_equal(ce.add_noise(flat, gain, sigma, seed=7), noisy)
    assert not np.array_equal(ce.add_noise(flat, gain, sigma, seed=8), noisy)
    if sigma == 0:
        electrons = noisy / gain
        np.testing.assert_allclose(electrons, np.round(electrons), atol=1e-6)


def test_exposure_and_white_balance_scale_linear_light():
    """Flat colours: the output is colour-science's sRGB encoding of the decoded input times 2^ev and the channel
    gains, within one 8-bit step."""
    values = np.array([[[40, 90, 160], [120, 120, 120], [230, 30, 90]]], np.uint8)
    draw = EffectsDraw(exposure=Exposure(0.4), white_balance=WhiteBalance(1.08, 0.91))
    out = ce.apply_effects(values, draw)
    linear = colour.cctf_decoding(values / 255.0, function="sRGB") * 2 ** 0.4 * np.array([1.08, 1.0, 0.91])
    expected = np.round(colour.cctf_encoding(np.clip(linear, 0, 1), function="sRGB") * 255)
    assert np.max(np.abs(out.astype(int) - expected)) <= 1


def test_jpeg_is_pillows_round_trip():
    """The image encoded by Pillow at the quality with 4:2:0 chroma and decoded, byte for byte; a lower quality
    loses more (PSNR)."""
    rng = np.random.default_rng(3)
    image = ndimage.uniform_filter(rng.integers(0, 256, (48, 64, 3)).astype(float), size=(5, 5, 1)).astype(np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, "JPEG", quality=70, subsampling="4:2:0")
    expected = np.asarray(Image.open(io.BytesIO(buffer.getvalue())).convert("RGB"))
    np.testing.assert_array_equal(ce.apply_effects(image, EffectsDraw(jpeg=Jpeg(70))), expected)

    def psnr(q):
        out = ce.apply_effects(image, EffectsDraw(jpeg=Jpeg(q))).astype(float)
        return 10 * math.log10(255 ** 2 / np.mean((out - image) ** 2))

    assert psnr(20) < psnr(60) < psnr(95)


def test_no_effect_is_the_image_and_a_draw_gives_the_same_bytes_again():
    rng = np.random.default_rng(5)
    image = rng.integers(0, 256, (24, 32, 3), dtype=np.uint8)
    assert ce.apply_effects(image, EffectsDraw()).tobytes() == image.tobytes()
    depth = rng.uniform(1, 30, (24, 32))
    draw = EffectsDraw(Defocus(2.0, 0.05), MotionBlur(0.1, 20.0), Vignetting(0.2), Exposure(-0.2),
                       Noise(0.001, 0.003, 11), WhiteBalance(0.95, 1.05), Jpeg(80))
    first = ce.apply_effects(image, draw, depth)
    assert first.dtype == np.uint8 and first.shape == image.shape and not np.array_equal(first, image)
    assert ce.apply_effects(image, draw, depth).tobytes() == first.tobytes()


def test_defocus_needs_a_depth_of_the_images_size():
    image = np.zeros((8, 10, 3), np.uint8)
    with pytest.raises(ValueError, match="defocus needs a z-depth map"):
        ce.apply_effects(image, EffectsDraw(defocus=Defocus(2.0, 0.01)))
    with pytest.raises(ValueError, match=r"\(8, 10\)"):
        ce.apply_effects(image, EffectsDraw(defocus=Defocus(2.0, 0.01)), np.ones((4, 5)))
    with pytest.raises(ValueError, match="uint8"):
        ce.apply_effects(image.astype(float), EffectsDraw())
