"""The denoiser on its own (no renderer): the firefly filter, OIDN's determinism, and refused inputs."""

import numpy as np
import pytest

from synthua_usd.backends.denoise import FIREFLY_RATIO, Denoiser, suppress_fireflies
from synthua_usd.model.photometry import luminance


def noisy_scene(seed: int = 0, size=(48, 64)):
    """(colour, albedo, normal, clean): a lit wall and a floor with a shadow edge, and Monte Carlo-like noise
    (each pixel the mean of 2 samples that are 0 or a lit value)."""
    h, w = size
    rng = np.random.default_rng(seed)
    albedo = np.zeros((h, w, 3), np.float32)
    albedo[: h // 2] = (0.6, 0.3, 0.2)
    albedo[h // 2:] = (0.3, 0.3, 0.3)
    normal = np.zeros((h, w, 3), np.float32)
    normal[: h // 2] = (0, 0, -1)
    normal[h // 2:] = (0, 1, 0)
    light = np.where(np.arange(w)[None, :, None] < w // 2, 1.0, 0.3).astype(np.float32)
    clean = albedo * light
    hits = rng.random((h, w, 2)) < 0.5
    colour = (clean * hits.mean(axis=2, keepdims=True) * 2).astype(np.float32)
    return colour, albedo, normal, clean


def test_an_isolated_spike_is_scaled_down_and_a_bright_region_kept():
    rgb = np.full((9, 9, 3), 0.1, np.float32)
    rgb[2, 2] = (50.0, 40.0, 30.0)  # a firefly
    rgb[5:8, 5:8] = 20.0  # a lamp: every pixel has bright neighbours
    out, report = suppress_fireflies(rgb)
    assert report.pixels == 1 and report.share == pytest.approx(1 / 81)
    assert luminance(out[2, 2]) == pytest.approx(FIREFLY_RATIO * 0.1, rel=1e-5)
    assert out[2, 2, 0] / out[2, 2, 2] == pytest.approx(50 / 30, rel=1e-5)  # hue kept
    mask = np.ones((9, 9), bool)
    mask[2, 2] = False
    assert np.array_equal(out[mask], rgb[mask])
    assert 0 < report.energy_share < 1
    assert rgb[2, 2, 0] == 50.0  # the input is not changed


def test_a_clean_image_is_left_alone():
    rgb = np.random.default_rng(0).uniform(0.1, 0.3, (16, 16, 3)).astype(np.float32)
    out, report = suppress_fireflies(rgb)
    assert report.pixels == 0 and np.array_equal(out, rgb)


def test_denoising_brings_noise_close_to_the_clean_image():
    colour, albedo, normal, clean = noisy_scene()
    with Denoiser() as denoise:
        out = denoise(colour, albedo, normal)
    assert out.shape == colour.shape and out.dtype == np.float32
    before = np.mean((colour - clean) ** 2)
    after = np.mean((out - clean) ** 2)
    assert after < before / 10, (before, after)


def test_oidn_gives_the_same_bytes_run_after_run_and_on_any_thread_count():
    colour, albedo, normal, _ = noisy_scene(seed=1, size=(96, 128))
    results = []
    for threads in (None, None, 1, 2, 4):
        with Denoiser(num_threads=threads) as denoise:
            results.append(denoise(colour, albedo, normal).tobytes())
    assert len(set(results)) == 1


def test_refuses_guides_of_another_shape():
    colour, albedo, normal, _ = noisy_scene()
    with Denoiser() as denoise:
        with pytest.raises(ValueError, match=r"denoiser normal: shape \(48, 63, 3\)"):
            denoise(colour, albedo, normal[:, :63])


def test_the_denoiser_does_not_load_torch_and_leaves_it_importable():
    """pyoidn imports torch whenever it is installed; the denoiser hides it (start-up time, and torch's exit
    handlers made OpenImageIO print leak reports after a command's last line)."""
    import subprocess
    import sys

    code = ("import importlib.util, sys\n"
            "from synthua_usd.backends.denoise import Denoiser\n"
            "Denoiser(num_threads=1).close()\n"
            "assert 'torch' not in sys.modules, 'torch was loaded'\n"
            "if importlib.util.find_spec('torch') is not None:\n"
            "    import torch\n"
            "    print('torch', torch.__version__)\n"
            "print('ok')\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().endswith("ok")


def subject_on_empty_frame(size=(160, 192), box=(70, 100, 90, 130), seed=2):
    """(colour, albedo, normal): a noisy lit patch (rows and columns of ``box``: y0, y1, x0, x1) on a frame where
    nothing was hit (all three zero), as a cut-out's render is."""
    h, w = size
    y0, y1, x0, x1 = box
    colour, albedo, normal, _ = noisy_scene(seed, (y1 - y0, x1 - x0))
    frames = [np.zeros((h, w, 3), np.float32) for _ in range(3)]
    for frame, part in zip(frames, (colour, albedo, normal)):
        frame[y0:y1, x0:x1] = part
    return frames


def test_a_subject_denoised_in_its_box_keeps_the_rest_and_matches_the_whole_frame():
    """``margin``: OIDN sees the hit pixels' box widened by the margin, from a multiple of 16; every pixel
    outside keeps its input (zero), and the subject's pixels match denoising the whole frame closely."""
    from synthua_usd.backends.denoise import BIN_PX, _hit_box

    colour, albedo, normal = subject_on_empty_frame()
    hit = normal.any(axis=2)
    assert _hit_box(hit, 8) == (48, 112, 80, 144)           # 70-8 -> 48, 100+8 -> 112 (4 bins); 90-8 -> 80, ...
    assert all(v % BIN_PX == 0 for v in _hit_box(hit, 8))
    assert _hit_box(hit, 500) is None and _hit_box(np.zeros_like(hit), 8) is None
    with Denoiser() as denoise:
        whole, _ = denoise.denoise_pass(colour, albedo, normal)
        boxed, report = denoise.denoise_pass(colour, albedo, normal, margin=64)
        wide, _ = denoise.denoise_pass(colour, albedo, normal, margin=500)     # the box is the frame
    assert np.array_equal(wide, whole)
    assert report.pixels == 0
    assert np.array_equal(boxed[~hit], colour[~hit])
    error = np.abs(boxed[hit] - whole[hit])
    assert error.max() <= 3e-3 * whole[hit].max() and error.mean() <= 1e-4 * whole[hit].mean()
    assert not np.array_equal(boxed[hit], colour[hit])       # denoised, not passed through


def test_a_frame_whose_sides_are_not_multiples_of_16_is_denoised_whole():
    """OIDN spreads its exposure bins evenly over the image: on a 300-wide frame a box would see another exposure
    (measured: 0.34 against 0.63, 5 % of the brightest off), so the margin is not used there."""
    colour, albedo, normal = subject_on_empty_frame(size=(160, 300), box=(60, 100, 140, 190))
    with Denoiser() as denoise:
        whole, _ = denoise.denoise_pass(colour, albedo, normal)
        boxed, _ = denoise.denoise_pass(colour, albedo, normal, margin=64)
    assert np.array_equal(boxed, whole)


def test_guides_of_another_shape_are_refused_with_a_margin_too():
    colour, albedo, normal = subject_on_empty_frame()
    with Denoiser() as denoise:
        with pytest.raises(ValueError, match=r"denoiser albedo: shape \(160, 150, 3\)"):
            denoise.denoise_pass(colour, albedo[:, :150], normal, margin=8)
        with pytest.raises(ValueError, match=r"denoiser normal: shape \(160, 192, 1\)"):
            denoise.denoise_pass(colour, albedo, normal[..., :1])
