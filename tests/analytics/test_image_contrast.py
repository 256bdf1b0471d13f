"""RMS contrast and edge density (``synthua_usd.analytics.image_contrast``): against images worked out by hand,
against a plain Python loop over the pixels and against ``scipy.ndimage.sobel``, and as ``synthua stats``
reports them for the hand-made dataset of tiny_dataset.py."""

from __future__ import annotations

import math

import numpy as np
import OpenImageIO as oiio
import pytest
from PIL import Image
from scipy import ndimage

from synthua_usd.analytics import image_contrast as ic
from synthua_usd.analytics.dataset_index import load_index
from synthua_usd.analytics.statistics import compute

from analytics import tiny_dataset

H, W = 6, 8


def rgb(grey: np.ndarray) -> np.ndarray:
    """(H, W) 8-bit greys as (H, W, 3) RGB."""
    return np.repeat(np.asarray(grey, np.uint8)[..., None], 3, axis=2)


def measures(image8: np.ndarray) -> tuple[float, float]:
    y = ic.luma(image8)
    return ic.rms_contrast(y), ic.edge_density(y)


@pytest.mark.parametrize("value", [0, 1, 128, 255])
def test_a_flat_image_has_no_contrast_and_no_edge_even_at_its_frame(value):
    # zero padding would make the frame of every bright image an edge; replicate padding makes none
    assert measures(rgb(np.full((H, W), value))) == (0.0, 0.0)


def test_half_black_half_white():
    """Luma 0 | 1: standard deviation 0.5 exactly. Sobel x at the last black column is 1 + 2 + 1 = 4 times the
    step, and the same at the first white column; gy is 0; so 2 columns of edges out of 8, the frame rows
    included (replicated rows equal the rows they copy)."""
    left_right = np.zeros((H, W), np.uint8)
    left_right[:, W // 2:] = 255
    assert measures(rgb(left_right)) == (0.5, 2 / W)
    magnitude = ic.gradient_magnitude(ic.luma(rgb(left_right)))
    assert magnitude[:, W // 2 - 1: W // 2 + 1].tolist() == [[1.0, 1.0]] * H          # a unit step gives 1
    assert np.count_nonzero(magnitude) == 2 * H
    assert measures(rgb(left_right.T)) == (0.5, 2 / W)          # the same split as rows: 2 rows of 8
    coloured = np.zeros((H, W, 3), np.uint8)
    coloured[:, W // 2:] = (0, 255, 0)                          # pure green: luma 0.7152
    assert measures(coloured) == pytest.approx((0.7152 / 2, 2 / W))


def test_one_white_pixel_inside_and_at_the_corner():
    """A white pixel in a black 5x5: its 8 neighbours see it (the side ones at 2/4, the diagonal ones at
    sqrt(2)/4 > 0.1), the pixel itself has 0 gradient. At the corner (0, 0), replicated, it stands for a 2x2
    block beyond the frame: (0, 0), (0, 1), (1, 0), (1, 1) are edges (|g|/4 = sqrt(18)/4, sqrt(10)/4 twice,
    sqrt(2)/4) and nothing else: 4 of 25 (zero padding would give 3, the interior alone 1 of 9)."""
    grey = np.zeros((5, 5), np.uint8)
    grey[2, 2] = 255
    contrast, density = measures(rgb(grey))
    assert contrast == pytest.approx(math.sqrt(1 / 25 * 24 / 25)) and density == 8 / 25
    g = ic.gradient_magnitude(ic.luma(rgb(grey)))
    assert g[2, 2] == 0 and g[2, 1] == 0.5 and g[1, 1] == pytest.approx(math.sqrt(2) / 4)
    corner = np.zeros((5, 5), np.uint8)
    corner[0, 0] = 255
    g = ic.gradient_magnitude(ic.luma(rgb(corner)))
    assert g[:2, :2] == pytest.approx(np.array([[math.sqrt(18), math.sqrt(10)], [math.sqrt(10), math.sqrt(2)]]) / 4)
    assert np.count_nonzero(g > ic.EDGE_THRESHOLD) == 4 and ic.edge_density(ic.luma(rgb(corner))) == 4 / 25


def test_the_threshold_is_strict():
    y = np.zeros((H, W))
    y[:, W // 2:] = 0.25                                        # |g| / 4 = 0.25 exactly on 2 columns
    assert ic.edge_density(y, 0.25) == 0.0
    assert ic.edge_density(y, 0.2499) == 2 / W


def loop_measures(image8: np.ndarray) -> tuple[float, float]:
    """The definitions as a plain loop over pixels: no NumPy arithmetic, the border by clamping indices."""
    h, w = len(image8), len(image8[0])
    y = [[(0.2126 * int(px[0]) + 0.7152 * int(px[1]) + 0.0722 * int(px[2])) / 255 for px in row] for row in image8]
    mean = sum(sum(row) for row in y) / (h * w)
    contrast = math.sqrt(sum((v - mean) ** 2 for row in y for v in row) / (h * w))

    def at(r, c):
        return y[min(max(r, 0), h - 1)][min(max(c, 0), w - 1)]

    edges = 0
    for r in range(h):
        for c in range(w):
            gx = sum(k * (at(r + dr, c + 1) - at(r + dr, c - 1)) for dr, k in ((-1, 1), (0, 2), (1, 1)))
            gy = sum(k * (at(r + 1, c + dc) - at(r - 1, c + dc)) for dc, k in ((-1, 1), (0, 2), (1, 1)))
            edges += math.sqrt(gx * gx + gy * gy) / 4 > 0.1
    return contrast, edges / (h * w)


def smooth_random(shape, seed) -> np.ndarray:
    """8-bit RGB with some edges and some flat parts: noise blurred and quantised."""
    noise = np.random.default_rng(seed).random(shape)
    return np.round(255 * ndimage.uniform_filter(noise, size=(3, 3, 1))).astype(np.uint8)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_against_a_plain_loop_over_pixels(seed):
    image8 = smooth_random((11, 13, 3), seed)
    contrast, density = measures(image8)
    want_contrast, want_density = loop_measures(image8.tolist())
    assert contrast == pytest.approx(want_contrast, rel=1e-12)
    assert density == want_density and 0 < density < 1          # a case with edges and non-edges


@pytest.mark.parametrize("mode", ["nearest", "reflect"])          # the same beyond one pixel: 3x3 kernels
def test_against_scipy_sobel(mode):
    image8 = smooth_random((60, 80, 3), 7)
    y = (image8.astype(np.float64) @ np.array([0.2126, 0.7152, 0.0722])) / 255
    want = np.hypot(ndimage.sobel(y, axis=1, mode=mode), ndimage.sobel(y, axis=0, mode=mode)) / 4
    got = ic.gradient_magnitude(ic.luma(image8))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    assert ic.edge_density(ic.luma(image8)) == np.mean(want > 0.1)
    assert 0.05 < np.mean(want > 0.1) < 0.95


def test_spread_of_values():
    s = ic.spread(range(11))                                     # 0..10: p10 = 1, p90 = 9 by interpolation
    assert s == {"count": 11, "mean": 5.0, "median": 5.0, "p10": 1.0, "p90": 9.0}
    assert ic.spread([0.2, 0.4]) == pytest.approx({"count": 2, "mean": 0.3, "median": 0.3, "p10": 0.22, "p90": 0.38})
    assert ic.spread([]) == {"count": 0, "mean": None, "median": None, "p10": None, "p90": None}


def test_the_statistics_of_the_tiny_dataset(tmp_path):
    root = tiny_dataset.write(tmp_path / "ds")
    stats = compute(load_index(root))
    want = tiny_dataset.kept_contrast_and_edges(root)
    rows = stats.document()["image_contrast_per_image"]
    assert [r["id"] for r in rows] == [1, 2] and [r["split"] for r in rows] == ["train", "val"]
    for r in rows:
        assert (r["rms_contrast"], r["edge_density"]) == pytest.approx(want[r["id"]], abs=1e-12)
    c = stats.summary["image_contrast"]
    for k, m in enumerate(ic.MEASURES):
        a, b = want[1][k], want[2][k]
        lo, hi = sorted((a, b))                                    # percentiles interpolate between the two
        assert c[m] == pytest.approx({"count": 2, "mean": (a + b) / 2, "median": (a + b) / 2,
                                      "p10": lo + 0.1 * (hi - lo), "p90": lo + 0.9 * (hi - lo)})
        assert c["per_split"]["train"][m] == pytest.approx({"count": 1, "mean": a, "median": a, "p10": a, "p90": a})
        assert c["per_split"]["val"][m]["median"] == pytest.approx(b)
    assert set(c["per_split"]) == {"train", "val"}                 # the rejected test image is left out
    assert all(0 < want[i][1] < 1 for i in want)                   # the label blocks make edges


@pytest.mark.parametrize("bad, found", [
    (np.zeros((3, 4, 3), np.uint8), "4x3 pixels, 3 channel(s) of uint8"),
    (np.zeros((6, 8), np.uint8), "8x6 pixels, 1 channel(s) of uint8"),
    (np.zeros((6, 8, 3), np.uint16), "8x6 pixels, 3 channel(s) of uint16"),
    (None, "not an image OpenImageIO can read"),
    ("truncated", "not an image OpenImageIO can read"),
])
def test_a_wrong_rgb_is_one_error(run_cli, tmp_path, bad, found):
    root = tiny_dataset.write(tmp_path / "ds")
    path = root / "images" / "val" / f"{tiny_dataset.NAMES[1]}.png"
    if bad is None:
        path.write_bytes(b"not a png")
    elif isinstance(bad, str):  # its header intact (OpenImageIO opens it), its pixels cut off inside IDAT
        data = path.read_bytes()
        path.write_bytes(data[:data.index(b"IDAT") + 8])
    else:
        assert oiio.ImageBuf(np.ascontiguousarray(bad)).write(str(path), str(bad.dtype))
    code, _, err = run_cli("stats", root, "--out", tmp_path / "r")
    assert code == 2 and err.count("synthua: error:") == 1 and err.count("\n") == 1, err
    assert f"{found}; expected the 8x6 8-bit RGB PNG of record {tiny_dataset.NAMES[1]}" in err
    assert not (tmp_path / "r").exists()

