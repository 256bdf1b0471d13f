"""A cut-out placed in a frame: its labels are the cut-out's pixel under each frame pixel's centre (checked pixel by
pixel with a loop of its own), its colour keeps flat colours and its alpha's mass scales with the area, and what the
frame cuts off is counted."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bank_maker import write_bank
from synthua_usd.backends.cutout_pixels import read_cutout, place
from synthua_usd.dataset.cutout_bank import read_bank


@pytest.fixture(scope="module")
def bank(tmp_path_factory):
    return read_bank(write_bank(tmp_path_factory.mktemp("bank") / "bank"))


def _nearest(array: np.ndarray, entry, anchor_px, scale, region) -> np.ndarray:
    """The cut-out's value under each frame pixel centre of ``region``, one pixel at a time."""
    x0, y0, x1, y1 = region
    out = np.zeros((y1 - y0, x1 - x0), array.dtype)
    for row in range(y0, y1):
        for col in range(x0, x1):
            u = entry.anchor[0] + (col + 0.5 - anchor_px[0]) / scale
            v = entry.anchor[1] + (row + 0.5 - anchor_px[1]) / scale
            if 0 <= u < array.shape[1] and 0 <= v < array.shape[0]:
                out[row - y0, col - x0] = array[int(math.floor(v)), int(math.floor(u))]
    return out


@pytest.mark.parametrize("anchor_px, scale", [((40.3, 50.7), 0.61), ((20.0, 70.2), 1.73), ((5.5, 30.0), 1.0)])
def test_labels_are_the_cutout_pixel_under_each_frame_pixel_centre(bank, anchor_px, scale):
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    placed = place(pixels, entry, anchor_px, scale, (80, 60))
    assert placed.ids.shape == placed.premultiplied.shape[:2] == placed.amodal.shape == placed.shadow.shape
    np.testing.assert_array_equal(placed.ids, _nearest(pixels.ids, entry, anchor_px, scale, placed.region))
    np.testing.assert_array_equal(placed.amodal, _nearest(pixels.amodal, entry, anchor_px, scale, placed.region))


def test_what_the_frame_cuts_off_is_counted(bank):
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    anchor_px, scale = (3.0, 40.0), 1.0           # the group's left and top parts lie outside the frame
    placed = place(pixels, entry, anchor_px, scale, (80, 60))
    x0 = placed.region[0]
    assert x0 == 0
    for inst in entry.instances:
        bit = 1 << (inst.index - 1)
        whole = np.zeros((200, 200), bool)   # the placed cut-out on a frame large enough for all of it
        big = place(pixels, entry, (anchor_px[0] + 100, anchor_px[1] + 100), scale, (200, 200))
        whole[big.slices] = (big.amodal & bit) > 0
        inside = int(((placed.amodal & bit) > 0).sum())
        assert inside + placed.outside[inst.index] == int(whole.sum())
        assert placed.outside[inst.index] == int(whole.sum() - whole[100:160, 100:180].sum())  # the 80x60 frame


def test_a_flat_colour_stays_that_colour_and_alpha_mass_scales_with_area(bank):
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    scale = 0.5
    placed = place(pixels, entry, (40.0, 55.0), scale, (80, 60))
    alpha = placed.premultiplied[..., 3]
    assert alpha.sum() == pytest.approx(pixels.premultiplied[..., 3].sum() * scale ** 2, rel=0.02)
    opaque = alpha > 0.999                        # deep inside the torso: the person's own colour
    colour = placed.premultiplied[..., :3][opaque] / alpha[opaque][:, None]
    torso = pixels.premultiplied[30, 24, :3]
    assert np.abs(colour - torso).min(axis=0).max() < 1e-4
    assert placed.shadow.min() < 0.5 and placed.shadow.max() == pytest.approx(1.0)


def test_a_cutout_outside_the_frame_places_nothing(bank):
    entry = bank.entries[0]
    assert place(read_cutout(bank.root, entry), entry, (500.0, 500.0), 1.0, (80, 60)) is None
