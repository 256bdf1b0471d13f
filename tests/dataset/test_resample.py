"""Resampling: RGB by OpenImageIO's Blackman-Harris filter; label maps by block mode or nearest, never a blend."""

import numpy as np
import pytest

from synthua_usd.dataset.resample import (
    gather, mode_index, nearest_index, resample_label_maps, resample_labels, resample_pixel_set, resample_rgb,
)


def test_block_mode_and_its_tie_rule():
    labels = np.array([[1, 1, 2, 2],
                       [3, 1, 2, 5],
                       [4, 4, 7, 7],
                       [4, 6, 8, 8]], dtype=np.uint16)
    # blocks: {1,1,3,1} -> 1; {2,2,2,5} -> 2; {4,4,4,6} -> 4; {7,7,8,8} tie -> the smaller, 7
    out = resample_labels(labels, 2, 2)
    assert out.dtype == np.uint16 and out.tolist() == [[1, 2], [4, 7]]
    assert resample_labels(np.array([[2, 1], [1, 2]]), 1, 1).tolist() == [[1]]
    assert resample_labels(np.array([[9, 3, 3], [9, 9, 0], [3, 0, 0]]), 1, 1).tolist() == [[0]]  # 3-way tie
    # the source pixel of a tie is the smaller label's first pixel in row-major order
    assert mode_index(np.array([[2, 1], [1, 2]]), 1, 1).tolist() == [[1]]


def test_mode_commutes_with_flips_and_transposes():
    rng = np.random.default_rng(5)
    labels = rng.integers(0, 3, size=(12, 18))          # three labels in 3 x 3 and 2 x 2 blocks: many ties
    for w, h in ((6, 4), (9, 6)):
        out = resample_labels(labels, w, h)
        assert np.array_equal(resample_labels(labels[::-1], w, h), out[::-1])
        assert np.array_equal(resample_labels(labels[:, ::-1], w, h), out[:, ::-1])
        assert np.array_equal(resample_labels(labels.T, h, w), out.T)


def test_mode_against_a_direct_count():
    rng = np.random.default_rng(1)
    labels = rng.integers(0, 4, size=(9, 12))
    out = resample_labels(labels, 4, 3)
    for y in range(3):
        for x in range(4):
            values, counts = np.unique(labels[3 * y:3 * y + 3, 3 * x:3 * x + 3], return_counts=True)
            assert out[y, x] == values[np.argmax(counts)]   # np.unique sorts: argmax = smallest most frequent


def test_nearest_for_other_factors():
    # W = 5 -> 2: source columns floor((2x + 1) 5 / 4) = 1, 3; H = 3 -> 2: rows floor((2y + 1) 3 / 4) = 0, 2
    assert nearest_index((3, 5), 2, 2).tolist() == [[1, 3], [11, 13]]
    labels = np.arange(15).reshape(3, 5)
    assert resample_labels(labels, 2, 2).tolist() == [[1, 3], [11, 13]]


@pytest.mark.parametrize("size", [(16, 12), (13, 7), (32, 24), (5, 3)])
def test_no_new_ids_at_edges(size):
    yy, xx = np.mgrid[0:24, 0:32]
    labels = np.where(xx + yy < 28, 3, 250).astype(np.uint8)
    labels[(xx - 20) ** 2 + (yy - 8) ** 2 < 20] = 17
    out = resample_labels(labels, *size)
    assert set(np.unique(out)) <= {3, 17, 250}
    # what bilinear would do: average across the 3/250 edge gives values in between
    assert len(set(np.unique((labels[:, :-1].astype(float) + labels[:, 1:]) / 2))) > 3


def test_maps_resampled_together_stay_consistent():
    classes = np.array([[2, 2], [1, 1]])
    instances = np.array([[5, 5], [7, 7]])
    # alone, each map's tie rule would pick class 1 and instance 5: a pair no source pixel has
    assert resample_labels(classes, 1, 1)[0, 0] == 1 and resample_labels(instances, 1, 1)[0, 0] == 5
    out, index = resample_label_maps({"class": classes, "instance": instances}, 1, 1)
    assert (out["class"][0, 0], out["instance"][0, 0]) == (1, 7)
    depth = np.array([[4.0, 4.5], [9.0, 9.5]], dtype=np.float32)
    assert gather(depth, index).tolist() == [[9.0]]


def test_amodal_pixel_sets_contain_the_resampled_visible_masks():
    rng = np.random.default_rng(2)
    instances = rng.integers(0, 4, size=(12, 16))
    classes = instances * 10
    out, index = resample_label_maps({"class": classes, "instance": instances}, 8, 6)
    for k in range(4):
        visible = np.flatnonzero(instances == k)
        amodal = np.union1d(visible, rng.choice(instances.size, 20))
        resized = resample_pixel_set(amodal, instances.shape, index)
        assert np.all(np.diff(resized) > 0)
        assert set(np.flatnonzero(out["instance"] == k)) <= set(resized.tolist())
    assert np.array_equal(out["class"], out["instance"] * 10)


def test_rgb_filter_keeps_constants_levels_and_sign():
    flat = np.full((24, 32, 3), 0.25, np.float32)
    assert np.allclose(resample_rgb(flat, 13, 9), 0.25, atol=1e-6)
    rng = np.random.default_rng(0)
    noise = rng.random((48, 64, 3), dtype=np.float32)
    half = resample_rgb(noise, 32, 24)
    assert half.shape == (24, 32, 3) and half.dtype == np.float32
    assert abs(float(half.mean()) - float(noise.mean())) < 1e-3
    assert half.std() < noise.std() / 1.5      # it averages: noise falls
    lamp = np.zeros((48, 64, 3), np.float32)
    lamp[20, 30] = 1000.0                       # an HDR point light: no ringing into negative values
    small = resample_rgb(lamp, 32, 24)
    assert small.min() >= 0.0 and small.sum() * 4 == pytest.approx(3000.0, rel=1e-4)
    assert np.array_equal(resample_rgb(noise, 64, 48), noise)
    assert np.array_equal(resample_rgb(noise, 20, 15), resample_rgb(noise, 20, 15))


def test_bad_sizes_are_refused():
    with pytest.raises(ValueError, match="resample width = 40; expected an integer 1..32"):
        resample_labels(np.zeros((24, 32), np.int32), 40, 12)
    with pytest.raises(ValueError, match="integer label map"):
        resample_labels(np.zeros((4, 4), np.float32), 2, 2)
