"""Painting a composite: label maps by the painter's rule (checked with labels resampled here pixel by pixel), the
photo untouched outside pastes and shadows, shadows darkening by the factor the shadow layer gives, hard edges
showing the cut-out's own colours, soft edges soft, the gains of exposure and white balance as defined, and Poisson
blending solving its equation; blurred and Poisson pastes going on beyond the frame's edge where it cuts them;
sharpness matching reading a known blur and giving it to a sharper paste."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from scipy import ndimage

from bank_maker import banded_aid_user, bands, write_bank
from synthua_usd.backends.compositing import (POISSON_MARGIN_PX, PasteInput, compose, composite_depth, edge_blur,
                                              paste_gains, retone, tone_gains)
from synthua_usd.backends.cutout_pixels import LINEAR_LUT, PlacedCutout, place, read_cutout
from synthua_usd.backends.poisson_blend import poisson_blend
from synthua_usd.dataset.composite_config import MatchSettings
from synthua_usd.dataset.composite_plan import Placement
from synthua_usd.dataset.cutout_bank import read_bank
from synthua_usd.model.srgb import from_linear, to_linear
from synthua_usd.model.taxonomy import ClassMap

NO_MATCH = MatchSettings(exposure_strength=0.0, white_balance_strength=0.0)


@pytest.fixture(scope="module")
def bank(tmp_path_factory):
    return read_bank(write_bank(tmp_path_factory.mktemp("bank") / "bank"))


def _placement(entry, anchor, scale, order, mode="hard", shadow=0.0, **blend) -> Placement:
    x0, y0, x1, y1 = entry.group_box()
    ax, ay = entry.anchor
    box = (anchor[0] + scale * (x0 - ax), anchor[1] + scale * (y0 - ay), anchor[0] + scale * (x1 - ax),
           anchor[1] + scale * (y1 - ay))
    return Placement(entry.id, entry.kind, anchor, scale, 0.5, 0.5, 5.0, 10.0, entry.camera.elevation_deg, None, box,
                     0.0, {"mode": mode, **blend}, shadow, order)


def _nearest(array, entry, anchor, scale, shape):
    """The cut-out's value under every frame pixel centre (0 off the cut-out), one pixel at a time."""
    out = np.zeros(shape + array.shape[2:], array.dtype)
    for row in range(shape[0]):
        for col in range(shape[1]):
            u = entry.anchor[0] + (col + 0.5 - anchor[0]) / scale
            v = entry.anchor[1] + (row + 0.5 - anchor[1]) / scale
            if 0 <= u < array.shape[1] and 0 <= v < array.shape[0]:
                out[row, col] = array[int(math.floor(v)), int(math.floor(u))]
    return out


def _photo(h=60, w=80, seed=0):
    return np.random.default_rng(seed).integers(30, 220, (h, w, 3), dtype=np.uint8)


def test_labels_follow_the_painter_rule_and_amodal_masks_stay_whole(bank):
    far, near = bank.entries[0], bank.entries[3]
    photo = _photo()
    pastes = [PasteInput(far, read_cutout(bank.root, far), _placement(far, (40.0, 45.0), 0.7, 0)),
              PasteInput(near, read_cutout(bank.root, near), _placement(near, (44.0, 58.0), 0.8, 1))]
    painted = compose(photo, pastes, ClassMap.default(), NO_MATCH)
    ids_far = _nearest(read_cutout(bank.root, far).ids, far, (40.0, 45.0), 0.7, (60, 80)).astype(np.uint16)
    ids_near = _nearest(read_cutout(bank.root, near).ids, near, (44.0, 58.0), 0.8, (60, 80)).astype(np.uint16)
    expected = np.where(ids_far > 0, ids_far, 0)                     # far: ids 1 (person), 2 (wheelchair)
    expected = np.where(ids_near > 0, ids_near + 2, expected)        # near: id 3 (person), drawn over
    np.testing.assert_array_equal(painted.instance_ids, expected)
    classes = np.array([0, 18, 29, 18], np.uint8)
    np.testing.assert_array_equal(painted.class_ids, classes[expected])
    amodal_far = _nearest(read_cutout(bank.root, far).amodal, far, (40.0, 45.0), 0.7, (60, 80))
    person_far = np.flatnonzero((amodal_far & 1).reshape(-1))
    np.testing.assert_array_equal(painted.amodal[1], person_far)
    hidden = np.isin(person_far, np.flatnonzero((expected == 3).reshape(-1)))
    assert hidden.any(), "the nearer pedestrian covers part of the farther aid user"
    assert [p["instance_ids"] for p in painted.pastes] == [[1, 2], [3]]
    assert {i.id: i.relations for i in painted.instances}[1] == (("uses", f"/pastes/p0/{far.id}/device2"),)


def test_the_photo_is_untouched_away_from_pastes_and_darkened_by_the_shadow_factor(bank):
    entry = bank.entries[0]
    photo = _photo()
    anchor, scale, strength = (40.0, 50.0), 1.0, 0.8
    painted = compose(photo, [PasteInput(entry, read_cutout(bank.root, entry),
                                         _placement(entry, anchor, scale, 0, shadow=strength))],
                      ClassMap.default(), NO_MATCH)
    shadow = _nearest(read_cutout(bank.root, entry).shadow, entry, anchor, scale, (60, 80))
    rgba = _nearest(read_cutout(bank.root, entry).rgba, entry, anchor, scale, (60, 80))
    free = (painted.instance_ids == 0) & (rgba[..., 3] == 0)
    # at scale 1 the shadow's interior is the drawn value; away from it and from the paste, the photo as it was
    untouched = free & (shadow == 255)
    np.testing.assert_array_equal(painted.rgb[untouched], photo[untouched])
    dark = free & (shadow == 110)
    assert dark.sum() > 20
    factor = 1.0 - strength * (1.0 - 110 / 255)
    expected = np.round(from_linear(np.clip(to_linear(photo[dark] / 255.0) * factor, 0, 1)) * 255)
    assert np.abs(painted.rgb[dark].astype(int) - expected.astype(int)).max() <= 1


def test_hard_edges_show_the_cutout_colours_and_soft_edges_are_soft(bank):
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    photo = _photo()
    anchor, scale = (40.0, 52.0), 0.9
    ids = _nearest(pixels.ids, entry, anchor, scale, (60, 80))
    rgba = _nearest(pixels.rgba, entry, anchor, scale, (60, 80))
    hard = compose(photo, [PasteInput(entry, pixels, _placement(entry, anchor, scale, 0))], ClassMap.default(),
                   NO_MATCH).rgb
    deep = (ids == 1)
    deep[[0, -1], :] = deep[:, [0, -1]] = False  # the frame's edge cuts the head: not inside
    for _ in range(2):  # two pixels in from every edge of the person: the filter sees only the person's colour
        deep[1:-1, 1:-1] &= deep[:-2, 1:-1] & deep[2:, 1:-1] & deep[1:-1, :-2] & deep[1:-1, 2:]
    assert deep.sum() > 10
    assert np.abs(hard[deep].astype(int) - np.array([200, 40, 40])).max() <= 1
    far_out = np.ones_like(ids, bool)
    around = (rgba[..., 3] > 0) | (ids > 0)
    for dy in range(-4, 5):
        for dx in range(-4, 5):
            far_out &= ~np.roll(np.roll(around, dy, 0), dx, 1)
    for blend in ({"mode": "feather", "feather_px": 2.0}, {"mode": "blur", "sigma_px": 1.0}):
        soft = compose(photo, [PasteInput(entry, pixels, _placement(entry, anchor, scale, 0, **blend))],
                       ClassMap.default(), NO_MATCH).rgb
        inner = deep.copy()
        for _ in range(3):
            inner[1:-1, 1:-1] &= inner[:-2, 1:-1] & inner[2:, 1:-1] & inner[1:-1, :-2] & inner[1:-1, 2:]
        assert np.abs(soft[inner].astype(int) - hard[inner].astype(int)).max() <= 1, blend
        np.testing.assert_array_equal(soft[far_out], photo[far_out])
        opaque = rgba[..., 3] == 255
        edge = (ids == 1) & ~(np.roll(opaque, 1, 0) & np.roll(opaque, -1, 0) & np.roll(opaque, 1, 1)
                              & np.roll(opaque, -1, 1))  # the person's pixels on the group's outline
        edge[[0, -1], :] = False
        assert edge.sum() > 10
        assert (soft[edge] != hard[edge]).any(axis=1).mean() > 0.8, blend  # the outline blends with the photo


def test_gains_match_the_photo_around_the_paste(bank):
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    photo = np.zeros((60, 80, 3), np.uint8)
    photo[...] = (90, 120, 160)                     # a bluish, darker surround
    placement = _placement(entry, (40.0, 50.0), 0.8, 0)
    placed = place(pixels, entry, placement.anchor_px, placement.scale, (80, 60))
    settings = MatchSettings(exposure_strength=0.5, exposure_gain=(0.1, 10.0), white_balance_strength=1.0,
                             white_balance_gain=(0.1, 10.0))
    exposure, balance = paste_gains(photo, placed, placement.box, settings)
    m_photo = LINEAR_LUT[np.array([90, 120, 160])].astype(np.float64)
    alpha = placed.premultiplied[..., 3].astype(np.float64)
    m_paste = placed.premultiplied[..., :3].astype(np.float64).sum(axis=(0, 1)) / alpha.sum()
    luminance = np.array([0.2126, 0.7152, 0.0722])
    assert exposure == pytest.approx((m_photo @ luminance / (m_paste @ luminance)) ** 0.5, rel=1e-5)
    cast = m_photo / (m_photo @ luminance)
    assert balance == pytest.approx(list(cast / (cast @ luminance)), rel=1e-5)
    assert balance[2] > 1 > balance[0]             # the paste takes the photo's blue cast
    clamped = paste_gains(photo, placed, placement.box, MatchSettings())
    assert 0.5 <= clamped[0] <= 2.0 and all(0.8 <= g <= 1.25 for g in clamped[1])


def test_poisson_blending_solves_its_equation():
    rng = np.random.default_rng(1)
    target = rng.random((20, 24, 3))
    source = rng.random((20, 24, 3))
    domain = np.zeros((20, 24), bool)
    domain[4:15, 5:19] = True
    domain[9, 19:22] = True
    f = poisson_blend(target, source, domain)
    np.testing.assert_array_equal(f[~domain], target[~domain])
    for y, x in zip(*np.nonzero(domain)):
        lhs = 4 * f[y, x] - sum(f[y + dy, x + dx] for dy, dx in ((-1, 0), (1, 0), (0, -1), (0, 1)))
        rhs = sum(source[y, x] - source[y + dy, x + dx] for dy, dx in ((-1, 0), (1, 0), (0, -1), (0, 1)))
        np.testing.assert_allclose(lhs, rhs, atol=1e-9)
    np.testing.assert_allclose(poisson_blend(target, target, domain), target, atol=1e-9)


def test_poisson_blending_guides_by_the_source_within_its_regions_only():
    """With ``regions``, the source's gradient between neighbours in different regions counts as 0 (checked pixel by
    pixel); a flat paste region over a flat photo then takes the photo's value: nothing guides it elsewhere."""
    rng = np.random.default_rng(5)
    target, source = rng.random((20, 24, 3)), rng.random((20, 24, 3))
    domain = np.zeros((20, 24), bool)
    domain[3:16, 4:20] = True
    regions = np.zeros((20, 24), np.int64)
    regions[6:13, 8:16] = 1
    regions[8:11, 10:13] = 2
    f = poisson_blend(target, source, domain, regions)
    np.testing.assert_array_equal(f[~domain], target[~domain])
    for y, x in zip(*np.nonzero(domain)):
        near = [(y + dy, x + dx) for dy, dx in ((-1, 0), (1, 0), (0, -1), (0, 1))]
        lhs = 4 * f[y, x] - sum(f[q] for q in near)
        rhs = sum(source[y, x] - source[q] for q in near if regions[q] == regions[y, x])
        np.testing.assert_allclose(lhs, rhs, atol=1e-9)
    flat_target, flat_source = np.full((20, 24, 3), 0.3), np.full((20, 24, 3), 0.3)
    flat_source[regions > 0] = 0.8
    np.testing.assert_allclose(poisson_blend(flat_target, flat_source, domain, regions > 0), flat_target, atol=1e-9)
    np.testing.assert_allclose(poisson_blend(flat_target, flat_source, domain), flat_source, atol=1e-9)


def test_poisson_blending_leaves_the_arrays_border_open():
    rng = np.random.default_rng(2)
    target, source = rng.random((20, 24, 3)), rng.random((20, 24, 3))
    domain = np.zeros((20, 24), bool)
    domain[0:12, 0:9] = True                       # at the top-left corner: two sides on the border
    f = poisson_blend(target, source, domain)
    np.testing.assert_array_equal(f[~domain], target[~domain])
    for y, x in zip(*np.nonzero(domain)):           # |N(p)| counts only the neighbours that exist
        near = [(y + dy, x + dx) for dy, dx in ((-1, 0), (1, 0), (0, -1), (0, 1))
                if 0 <= y + dy < 20 and 0 <= x + dx < 24]
        lhs = len(near) * f[y, x] - sum(f[q] for q in near)
        np.testing.assert_allclose(lhs, sum(source[y, x] - source[q] for q in near), atol=1e-9)
    assert not np.allclose(f[0, 0], target[0, 0])   # the corner is solved for, not held at the target
    np.testing.assert_array_equal(poisson_blend(target, source, np.ones((20, 24), bool)), source)


def test_a_poisson_paste_keeps_the_photo_on_its_edge(bank):
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    photo = _photo()
    painted = compose(photo, [PasteInput(entry, pixels, _placement(entry, (40.0, 52.0), 0.9, 0, mode="poisson"))],
                      ClassMap.default(), NO_MATCH)
    labelled = painted.instance_ids > 0
    near = ndimage.binary_dilation(labelled, iterations=POISSON_MARGIN_PX)      # Poisson's domain
    np.testing.assert_array_equal(painted.rgb[~near], photo[~near])
    assert (painted.rgb[labelled] != photo[labelled]).any()


def _flat_cutout(bank, colour=0.5):
    """Entry 0 of the bank in one straight linear colour (its alpha, labels and shadow kept)."""
    from synthua_usd.backends.cutout_pixels import CutoutPixels

    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    premultiplied = pixels.premultiplied.copy()
    premultiplied[..., :3] = colour * premultiplied[..., 3:]
    return entry, CutoutPixels(pixels.rgba, pixels.ids, pixels.amodal, pixels.shadow, premultiplied)


def _opaque_cutout(bank, inset=0):
    """Entry 0 of the bank opaque and labelled over its whole crop but an ``inset`` px border, in random linear
    colours; with an ``inset``, also an 8 x 8 px hole in the middle, labelled but transparent (no sample covers it)."""
    from synthua_usd.backends.cutout_pixels import CutoutPixels

    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    h, w = pixels.ids.shape
    colours = np.random.default_rng(3).uniform(0.05, 0.9, (h, w, 3)).astype(np.float32)
    alpha = np.zeros((h, w, 1), np.float32)
    alpha[inset:h - inset, inset:w - inset] = 1.0
    ids = np.where(pixels.ids > 0, pixels.ids, 1).astype(np.uint8) * (alpha[..., 0] > 0)
    if inset:
        alpha[h // 2 - 4:h // 2 + 4, w // 2 - 4:w // 2 + 4] = 0.0
    return entry, CutoutPixels(pixels.rgba, ids.astype(np.uint8), pixels.amodal, pixels.shadow,
                               np.concatenate([colours * alpha, alpha], -1))


@pytest.mark.parametrize("inset", [0, 3])
@pytest.mark.parametrize("shift, cut", [((20.0, 10.0), (False, False, False, False)),
                                        ((-6.0, 26.0), (True, False, False, True))])
def test_a_poisson_paste_is_seamless_cloning_up_to_its_crops_edges(bank, shift, cut, inset):
    """A cut-out labelled up to its crop's own edges (a small paste from a tight crop), or a few pixels short of them
    with a labelled hole no sample covers, Poisson-blended over a random photo, whole in the frame or cut at its
    left and bottom: the crop is solved as :func:`poisson_blend` over the whole frame gives it (computed here), with
    the labels widened by ``POISSON_MARGIN_PX`` within the crop as its domain, the hard composite as its source and
    the covered pixels as one region (the paste's own gradients and the photo's, none across the silhouette): bounded
    by the photo's pixels around the crop, open where the frame cuts it. On a flat grey photo its colour slides to the
    grey. Jobs without ``job_key.seamless_poisson`` imposed the photo's values on the crop's edges: a labelled pixel
    there showed the photo."""
    from synthua_usd.backends.compositing import encode

    entry, cutout = _opaque_cutout(bank, inset)
    anchor = (0.6 * entry.anchor[0] + shift[0], 0.6 * entry.anchor[1] + shift[1])  # crop edges on pixel edges
    placed = place(cutout, entry, anchor, 0.6, (80, 60))
    assert placed.cut == cut
    rows, cols = placed.slices
    covered = np.zeros((60, 80), bool)
    covered[rows, cols] = (placed.ids > 0) & (placed.premultiplied[..., 3] > 1e-6)
    crop = np.zeros((60, 80), bool)
    crop[rows, cols] = True
    for photo in (np.random.default_rng(9).integers(40, 200, (60, 80, 3)).astype(np.uint8),
                  np.full((60, 80, 3), 90, np.uint8)):
        hard, painted, kept = (compose(photo, [PasteInput(entry, cutout, _placement(entry, anchor, 0.6, 0, mode=mode))],
                                       ClassMap.default(), NO_MATCH, seamless_poisson=seamless)
                               for mode, seamless in (("hard", True), ("poisson", True), ("poisson", False)))
        labelled = painted.instance_ids > 0
        if inset:
            assert (labelled & ~covered).any() and not (labelled & ~crop).any()
            assert not (labelled & ~ndimage.binary_erosion(crop, border_value=1)).any()
        else:
            np.testing.assert_array_equal(labelled, crop)       # labelled up to the crop's edges, and only there
        domain = ndimage.binary_dilation(labelled, iterations=POISSON_MARGIN_PX) & crop
        assert (domain & ~ndimage.binary_erosion(crop, border_value=1)).sum() >= 40   # it reaches the crop's edges
        source = LINEAR_LUT[photo].astype(np.float64)
        straight = placed.premultiplied[..., :3] / np.maximum(placed.premultiplied[..., 3:], 1e-6)
        source[covered] = straight[covered[rows, cols]]                              # the hard paste, unrounded
        expected = encode(poisson_blend(LINEAR_LUT[photo], source, domain, covered).astype(np.float32))
        assert np.abs(painted.rgb.astype(int) - expected.astype(int)).max() <= 1
        np.testing.assert_array_equal(painted.rgb[~domain], photo[~domain])
    # on the flat grey photo, the colour slides towards it: the paste's mean moves
    assert abs(painted.rgb[covered].mean() - 90) < abs(hard.rgb[covered].mean() - 90) - 10
    if not inset:
        uncut = crop & ~ndimage.binary_erosion(crop, border_value=1)
        uncut[:, 0] &= not cut[0]
        uncut[-1] &= not cut[3]
        assert uncut.sum() >= 40
        np.testing.assert_array_equal(kept.rgb[uncut], photo[uncut])        # an earlier job's rule


def test_an_earlier_jobs_poisson_paste_with_room_around_it_was_the_hard_paste(bank):
    """With every gradient of the hard composite imported (jobs without ``job_key.seamless_poisson``), a paste whose
    labels keep off its crop's edges came out as the hard paste itself; seamless cloning moves its colours."""
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    photo = _photo()
    hard, kept, painted = (compose(photo, [PasteInput(entry, pixels, _placement(entry, (40.0, 56.0), 0.9, 0,
                                                                                 mode=mode))],
                                   ClassMap.default(), NO_MATCH, seamless_poisson=seamless)
                           for mode, seamless in (("hard", True), ("poisson", False), ("poisson", True)))
    labelled = hard.instance_ids > 0
    own = ndimage.binary_dilation(place(pixels, entry, (40.0, 56.0), 0.9, (80, 60)).ids > 0,
                                  iterations=POISSON_MARGIN_PX)
    assert not (own[0].any() or own[-1].any() or own[:, 0].any() or own[:, -1].any())   # off the crop's edges
    np.testing.assert_array_equal(kept.rgb, hard.rgb)
    moved = np.abs(painted.rgb.astype(int) - hard.rgb.astype(int)).max(axis=-1)
    assert (moved[labelled] > 5).mean() > 0.5


def test_placing_records_which_frame_edges_cut_the_crop(bank):
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    assert place(pixels, entry, (40.0, 56.0), 0.9, (80, 60)).cut == (False, False, False, False)  # the whole height
    assert place(pixels, entry, (40.0, 52.0), 0.9, (80, 60)).cut == (False, True, False, False)
    assert place(pixels, entry, (3.0, 56.0), 0.9, (80, 60)).cut == (True, False, False, False)
    assert place(pixels, entry, (77.0, 70.0), 0.9, (80, 60)).cut == (False, False, True, True)


EDGES = {"left": (slice(None), 0), "top": (0, slice(None)), "right": (slice(None), -1), "bottom": (-1, slice(None))}


@pytest.mark.parametrize("anchor, sides", [((3.0, 56.0), ("left",)), ((77.0, 70.0), ("right", "bottom"))])
@pytest.mark.parametrize("mode,blend", [("poisson", {}), ("blur", {"sigma_px": 1.5}), ("feather", {"feather_px": 2.0})])
def test_a_paste_the_frame_cuts_goes_on_beyond_the_cut(bank, mode, blend, anchor, sides):
    """A flat paste over a flat photo, cut by the frame (at its left side; at its right side and bottom): the blur
    and feather leave its colour whole wherever the paste's own edges are beyond their reach (the cut is not an
    edge); jobs without ``job_key.open_cuts`` (``open_cuts`` False) faded Poisson and blurred pastes towards the
    photo along the cut. Poisson as jobs with ``open_cuts`` but without ``seamless_poisson`` made it gives the hard
    paste itself (its source meets the photo on every edge but the cut, which is open); seamless cloning at a cut:
    :func:`test_a_poisson_paste_is_seamless_cloning_up_to_its_crops_edges`."""
    entry, flat = _flat_cutout(bank)
    photo = np.full((60, 80, 3), 40, np.uint8)
    hard = compose(photo, [PasteInput(entry, flat, _placement(entry, anchor, 0.9, 0))], ClassMap.default(), NO_MATCH)
    labelled = hard.instance_ids > 0
    for side in sides:
        assert labelled[EDGES[side]].sum() >= 10, side            # the cut runs through the paste
    placement = _placement(entry, anchor, 0.9, 0, mode=mode, **blend)
    opened = compose(photo, [PasteInput(entry, flat, placement)], ClassMap.default(), NO_MATCH, seamless_poisson=False)
    closed = compose(photo, [PasteInput(entry, flat, placement)], ClassMap.default(), NO_MATCH, open_cuts=False,
                     seamless_poisson=False)
    np.testing.assert_array_equal(opened.instance_ids, hard.instance_ids)
    if mode == "poisson":
        whole = np.ones(labelled.shape, bool)
    else:                                   # beyond the blend's reach of every pixel the paste does not label
        whole = ndimage.distance_transform_edt(labelled) > int(4.0 * 1.5 + 0.5) + 1
        for side in sides:
            assert whole[EDGES[side]].sum() >= 2, side
    assert np.abs(opened.rgb.astype(int) - hard.rgb.astype(int))[whole].max() <= 1
    if mode == "feather":                   # feather never faded a cut
        np.testing.assert_array_equal(closed.rgb, opened.rgb)
        return
    for side in sides:
        at_cut = labelled[EDGES[side]]
        faded = np.abs(closed.rgb[EDGES[side]][at_cut].astype(int) - hard.rgb[EDGES[side]][at_cut].astype(int))
        assert faded.max() >= 20, side


@pytest.mark.parametrize("sigma", [0.4, 1.5, 3.2])
@pytest.mark.parametrize("cut", [(True, False, False, False), (False, True, True, False), (True, True, True, True)])
def test_the_blur_beyond_a_cut_is_the_paste_repeated_as_far_as_the_gaussian_reaches(sigma, cut):
    """Against the same Gaussian over the crop padded 50 px on every side: by its last row or column where the frame
    cuts it, by transparency elsewhere."""
    from synthua_usd.backends.compositing import _blur_beyond_cuts

    values = np.random.default_rng(4).random((17, 13, 3)).astype(np.float32)
    left, top, right, bottom = cut
    rows = np.pad(values, ((50, 50), (0, 0), (0, 0)), mode="edge")
    rows[:50] *= top
    rows[-50:] *= bottom
    wide = np.pad(rows, ((0, 0), (50, 50), (0, 0)), mode="edge")
    wide[:, :50] *= left
    wide[:, -50:] *= right
    reference = ndimage.gaussian_filter(wide, (sigma, sigma, 0), mode="constant")[50:-50, 50:-50]
    np.testing.assert_allclose(_blur_beyond_cuts(values, sigma, cut), reference, rtol=0, atol=1e-6)
    np.testing.assert_allclose(_blur_beyond_cuts(values[..., 0], sigma, cut), reference[..., 0], rtol=0, atol=1e-6)


def test_depth_for_effects_puts_each_paste_at_its_distance(bank):
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    painted = compose(_photo(), [PasteInput(entry, pixels, _placement(entry, (40.0, 52.0), 0.9, 0))],
                      ClassMap.default(), NO_MATCH)
    ground = np.full((60, 80), 3.0, np.float32)
    depth = composite_depth(ground, painted, [7.5])
    assert (depth[painted.instance_ids > 0] == 7.5).all() and (depth[painted.instance_ids == 0] == 3.0).all()


def test_a_labelled_pixel_no_sample_covered_keeps_the_photo(bank):
    from synthua_usd.backends.cutout_pixels import CutoutPixels

    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    premultiplied = pixels.premultiplied.copy()
    premultiplied[30, 20:28] = 0.0                 # a row of the torso that no sample of the render hit
    thin = CutoutPixels(pixels.rgba, pixels.ids, pixels.amodal, pixels.shadow, premultiplied)
    photo = _photo()
    anchor = (40.0, 50.0)                          # scale 1: cut-out pixel (u, v) is frame pixel (u + 16, v - 12)
    painted = compose(photo, [PasteInput(entry, thin, _placement(entry, anchor, 1.0, 0))], ClassMap.default(),
                      NO_MATCH)
    assert (painted.instance_ids[18, 36:44] == 1).all()          # still labelled the person
    np.testing.assert_array_equal(painted.rgb[18, 36:44], photo[18, 36:44])
    assert np.abs(painted.rgb[18, 34].astype(int) - [200, 40, 40]).max() <= 1


def test_edge_blur_reads_a_known_gaussian_and_ignores_what_its_weight_leaves_out():
    rng = np.random.default_rng(3)
    blocks = np.kron(rng.random((10, 12)), np.ones((16, 16))).astype(np.float32)
    everywhere = np.ones(blocks.shape, bool)
    for sigma in (1.0, 2.0, 3.0):
        blurred = ndimage.gaussian_filter(blocks, sigma).astype(np.float32)
        assert edge_blur(blurred, everywhere.astype(np.float32), everywhere) == pytest.approx(sigma, abs=0.35)
    # a part that covers the left half: sharp junk on the right, left out by the weight, changes nothing
    blurred = ndimage.gaussian_filter(blocks, 2.0).astype(np.float32)
    part = np.zeros(blocks.shape, bool)
    part[:, :96] = True
    junk = np.where(part, blurred, rng.random(blocks.shape).astype(np.float32))
    clean = np.where(part, blurred, 0.0).astype(np.float32)
    read = edge_blur(clean, part.astype(np.float32), part)
    assert read is not None and read == pytest.approx(2.0, abs=0.35)
    assert edge_blur(junk, part.astype(np.float32), part) == pytest.approx(read, abs=1e-6)
    assert edge_blur(np.full((40, 40), 0.5, np.float32), np.ones((40, 40), np.float32),
                     np.ones((40, 40), bool)) is None  # flat: no edges to read


def _edges_at(angle_deg: float, sigma: float, size: int = 128) -> np.ndarray:
    """Straight stripes 16 px wide at ``angle_deg``, each pixel the mean of 8 x 8 samples (a rendered edge's own
    0.29 px of box blur), then blurred by a Gaussian of ``sigma``."""
    samples = 8
    yy, xx = np.mgrid[0:size * samples, 0:size * samples] / samples
    theta = math.radians(angle_deg)
    across = (xx - size / 2) * math.cos(theta) + (yy - size / 2) * math.sin(theta)
    image = (np.floor(across / 16) % 2 == 0) * 0.5 + 0.2
    image = image.reshape(size, samples, size, samples).mean(axis=(1, 3))
    return (ndimage.gaussian_filter(image, sigma) if sigma else image).astype(np.float32)


def test_edge_blur_is_near_zero_for_sharp_edges_in_every_direction_and_reads_small_blurs():
    everywhere = np.ones((128, 128), bool)
    weight = everywhere.astype(np.float32)
    sharp = [edge_blur(_edges_at(angle, 0.0), weight, everywhere) for angle in (0.0, 22.5, 45.0)]
    assert all(b is not None and b < 0.5 for b in sharp), sharp  # the 0.29 px box blur of the samples, and a bit
    assert max(sharp) - min(sharp) < 0.2, sharp
    for sigma in (0.75, 1.0, 1.5):
        for angle in (0.0, 30.0):
            read = edge_blur(_edges_at(angle, sigma), weight, everywhere)
            truth = math.hypot(sigma, 1 / math.sqrt(12))  # the Gaussian and the sampling's box, combined
            assert read == pytest.approx(truth, abs=0.15), (sigma, angle, read)


def _banded_bank(tmp_path, sigma: float):
    """A bank of one aid user whose person is drawn in grey bands (blurred by ``sigma`` within it)."""
    return read_bank(write_bank(tmp_path / f"bank{sigma}", [banded_aid_user("c000000", sigma)]))


def _slope_sigma(column: np.ndarray, low: float, high: float) -> float:
    """The Gaussian blur of the steps in a column of sRGB values in [0, 1], read from its steepest step: a step of
    contrast C blurred by s rises at most C / (s sqrt(2 pi)) a pixel."""
    return (high - low) / (np.abs(np.diff(column)).max() * math.sqrt(2 * math.pi))


def test_sharpness_matching_softens_a_sharp_paste_to_the_photos_blur_and_leaves_labels_alone(tmp_path):
    bank = _banded_bank(tmp_path, 0.0)
    entry = bank.entries[0]
    photo_sigma, scale, anchor = 2.0, 3.0, (160.0, 230.0)
    photo = np.round(np.repeat(bands(260, 320, 36, 0.3, 0.75, photo_sigma)[..., None], 3, axis=2) * 255
                     ).astype(np.uint8)
    paste = [PasteInput(entry, read_cutout(bank.root, entry), _placement(entry, anchor, scale, 0))]
    as_rendered = compose(photo, paste, ClassMap.default(), NO_MATCH)
    matched = compose(photo, paste, ClassMap.default(), MatchSettings(exposure_strength=0.0,
                                                                        white_balance_strength=0.0,
                                                                        sharpness_strength=1.0))
    np.testing.assert_array_equal(matched.instance_ids, as_rendered.instance_ids)
    np.testing.assert_array_equal(matched.class_ids, as_rendered.class_ids)
    outside = as_rendered.instance_ids == 0
    np.testing.assert_array_equal(matched.rgb[outside], as_rendered.rgb[outside])  # only the paste changes
    assert "sharpness_sigma_px" not in as_rendered.pastes[0]
    assert matched.pastes[0]["sharpness_sigma_px"] > 1.0
    # the torso's middle column, rows of the person only (the head and the chair left out): its steps' blur
    column = int(anchor[0])
    rows = np.flatnonzero(as_rendered.instance_ids[:, column] == 1)
    torso = rows[(rows >= anchor[1] - scale * (62 - 14)) & (rows < anchor[1] - scale * (62 - 37))]
    low, high = 0.35, 0.7
    before = _slope_sigma(as_rendered.rgb[torso, column, 1] / 255.0, low, high)
    after = _slope_sigma(matched.rgb[torso, column, 1] / 255.0, low, high)
    assert before < 1.1  # the resampling's own ramp
    assert after == pytest.approx(photo_sigma, abs=0.5)


def test_a_paste_no_sharper_than_the_photo_is_left_as_rendered(tmp_path):
    bank = _banded_bank(tmp_path, 2.5)
    entry = bank.entries[0]
    photo = np.round(np.repeat(bands(260, 320, 36, 0.3, 0.75)[..., None], 3, axis=2) * 255).astype(np.uint8)
    paste = [PasteInput(entry, read_cutout(bank.root, entry), _placement(entry, (160.0, 230.0), 3.0, 0))]
    as_rendered = compose(photo, paste, ClassMap.default(), NO_MATCH)
    matched = compose(photo, paste, ClassMap.default(), MatchSettings(exposure_strength=0.0,
                                                                        white_balance_strength=0.0,
                                                                        sharpness_strength=1.0))
    # both parts are measured (the sigma is 0 because the paste is softer, not because nothing could be read)
    placed = place(read_cutout(bank.root, entry), entry, (160.0, 230.0), 3.0, (320, 260))
    alpha = placed.premultiplied[..., 3]
    grey = from_linear(placed.premultiplied[..., 1] / np.maximum(alpha, 1e-6)).astype(np.float32)
    paste_blur = edge_blur(grey, alpha, alpha >= 0.999)
    photo_blur = edge_blur(photo[..., 1] / np.float32(255), np.ones(photo.shape[:2], np.float32),
                           np.ones(photo.shape[:2], bool))
    assert paste_blur is not None and photo_blur is not None and paste_blur > photo_blur
    assert matched.pastes[0]["sharpness_sigma_px"] == 0.0
    np.testing.assert_array_equal(matched.rgb, as_rendered.rgb)


REC709 = np.array([0.2126, 0.7152, 0.0722])


def _log_spread_and_chroma(rgb: np.ndarray, weight: np.ndarray) -> tuple[float, float]:
    """Contrast and saturation as the schema defines them, written out again: the weighted standard deviation of
    ln Y and the weighted mean of ||rgb - Y|| / Y over the pixels given (the caller picks them)."""
    y = rgb @ REC709
    w = weight / weight.sum()
    mean = np.sum(w * np.log(y))
    spread = math.sqrt(np.sum(w * (np.log(y) - mean) ** 2))
    chroma = np.sum(w * np.sqrt(((rgb - y[:, None]) ** 2).sum(axis=1)) / y)
    return spread, chroma


def _placed(rgb: np.ndarray, alpha: np.ndarray) -> PlacedCutout:
    """A placed cut-out made directly: straight linear ``rgb`` (h, w, 3) and ``alpha`` (h, w) at the frame's
    origin."""
    h, w = alpha.shape
    premultiplied = np.concatenate([rgb * alpha[..., None], alpha[..., None]], axis=-1).astype(np.float32)
    return PlacedCutout((w, h), (0, 0, w, h), premultiplied, (alpha > 0).astype(np.uint8),
                        np.zeros((h, w), np.uint16), np.ones((h, w), np.float32), {1: 0})


def _colourful(h=30, w=20, seed=0):
    """Straight linear colours of luminance 0.05-0.4 with chroma up to half their luminance (no channel below 0),
    alpha 1 but for a transparent first row and a half-transparent last one."""
    rng = np.random.default_rng(seed)
    y = np.exp(rng.uniform(np.log(0.05), np.log(0.4), (h, w)))
    hue = rng.uniform(0, 2 * np.pi, (h, w))
    u = np.array([REC709[1], -REC709[0], 0.0]) / np.linalg.norm([REC709[1], -REC709[0], 0.0])
    v = np.cross(REC709, u)
    v = v - (v @ REC709) / (REC709 @ REC709) * REC709
    v /= np.linalg.norm(v)
    direction = np.cos(hue)[..., None] * u + np.sin(hue)[..., None] * v
    rgb = y[..., None] * (1.0 + rng.uniform(0.0, 0.5, (h, w))[..., None] * direction)
    rgb = np.maximum(rgb, y[..., None] * 0.2)        # no channel at 0 (the chroma direction may point below it)
    alpha = np.ones((h, w))
    alpha[0], alpha[-1] = 0.0, 0.5
    return rgb, alpha


def test_retone_scales_contrast_and_saturation_by_its_gains_and_keeps_alpha():
    rgb, alpha = _colourful()
    placed = _placed(rgb, alpha)
    counted = alpha.reshape(-1) > 0.5

    def measures(p):
        a = p.premultiplied[..., 3].reshape(-1).astype(np.float64)
        straight = p.premultiplied[..., :3].reshape(-1, 3).astype(np.float64) / np.maximum(a, 1e-6)[:, None]
        return _log_spread_and_chroma(straight[counted], a[counted])

    spread, chroma = measures(placed)
    toned = retone(placed, 1.3, 0.6)
    np.testing.assert_array_equal(toned.premultiplied[..., 3], placed.premultiplied[..., 3])
    np.testing.assert_array_equal(toned.ids, placed.ids)
    assert measures(toned) == pytest.approx((1.3 * spread, 0.6 * chroma), rel=1e-4)
    only_saturation = retone(placed, 1.0, 0.6)
    y0 = placed.premultiplied[..., :3] @ REC709.astype(np.float32)
    np.testing.assert_allclose(only_saturation.premultiplied[..., :3] @ REC709.astype(np.float32), y0, rtol=1e-5)
    only_contrast = retone(placed, 1.3, 1.0)
    inside = alpha > 0
    ratio_before = placed.premultiplied[..., :3][inside] / y0[inside][:, None]
    y1 = only_contrast.premultiplied[..., :3] @ REC709.astype(np.float32)
    np.testing.assert_allclose(only_contrast.premultiplied[..., :3][inside] / y1[inside][:, None], ratio_before,
                               rtol=1e-4)          # the colour's chromaticity kept
    assert retone(placed, 1.0, 1.0) is placed


def _checker_photo(bright, dark, h=120, w=160):
    """A photo of 2 x 2-pixel blocks in a checkerboard of two sRGB colours (every other pixel of every other row
    samples both equally)."""
    blocks = ((np.arange(h)[:, None] // 2 + np.arange(w)[None, :] // 2) % 2).astype(bool)
    return np.where(blocks[..., None], np.array(bright, np.uint8), np.array(dark, np.uint8))


def test_tone_gains_take_the_photos_measures_partly_and_clamp(bank):
    entry = bank.entries[0]
    placement = _placement(entry, (80.0, 100.0), 1.2, 0)
    placed = place(read_cutout(bank.root, entry), entry, placement.anchor_px, placement.scale, (160, 120))
    bright, dark = (230, 180, 120), (40, 60, 70)
    photo = _checker_photo(bright, dark)
    colours = LINEAR_LUT[np.array([bright, dark], np.uint8)].astype(np.float64)
    photo_spread, photo_chroma = _log_spread_and_chroma(colours, np.ones(2))
    a = placed.premultiplied[..., 3].reshape(-1).astype(np.float64)
    straight = placed.premultiplied[..., :3].reshape(-1, 3).astype(np.float64) / np.maximum(a, 1e-6)[:, None]
    counted = (a > 0.5) & (straight @ REC709 > 0.005)
    paste_spread, paste_chroma = _log_spread_and_chroma(straight[counted], a[counted])
    wide = {"contrast_gain": (0.1, 10.0), "saturation_gain": (0.1, 10.0)}
    full = tone_gains(photo, placed, placement.box, MatchSettings(contrast_strength=1.0, saturation_strength=1.0,
                                                                  **wide))
    assert full == pytest.approx((photo_spread / paste_spread, photo_chroma / paste_chroma), rel=0.03)
    half = tone_gains(photo, placed, placement.box, MatchSettings(contrast_strength=0.5, saturation_strength=0.5,
                                                                  **wide))
    assert half == pytest.approx((math.sqrt(full[0]), math.sqrt(full[1])), rel=0.01)
    clamped = tone_gains(photo, placed, placement.box, MatchSettings(contrast_strength=1.0, saturation_strength=1.0,
                                                                     contrast_gain=(0.9, 1.1),
                                                                     saturation_gain=(0.9, 1.1)))
    assert clamped == (min(max(full[0], 0.9), 1.1), min(max(full[1], 0.9), 1.1))
    assert tone_gains(photo, placed, placement.box, MatchSettings()) == (1.0, 1.0)          # off by default
    both = MatchSettings(contrast_strength=1.0, saturation_strength=1.0, contrast_gain=(0.25, 4.0),
                         saturation_gain=(0.25, 4.0))
    # a grey photo (every grey level, in random order: no chroma, some spread) asks for the least saturation; a flat
    # one for the least contrast too, however its levels round
    grey = np.repeat(np.random.default_rng(3).integers(20, 256, (120, 160, 1), dtype=np.uint8), 3, axis=2)
    assert tone_gains(grey, placed, placement.box, both)[1] == 0.25
    for level in (128, 200, 77):
        assert tone_gains(np.full_like(photo, level), placed, placement.box, both) == (0.25, 0.25)
    # too few pixels bright enough to measure: nothing asked
    assert tone_gains(np.full_like(photo, 3), placed, placement.box, both) == (1.0, 1.0)


def test_tone_gains_weigh_the_paste_by_alpha_and_skip_dark_photo_pixels():
    # the paste: two halves in 2 x 2 blocks (its sampling reads each once), a greyish one opaque and a colourful one
    # at alpha 0.6; the photo: three colours in 2 x 2 blocks, one too dark to count
    h, w = 40, 40
    greyish, colourful = np.array([0.30, 0.29, 0.27]), np.array([0.25, 0.04, 0.01])
    rgb = np.where((np.arange(w) < w // 2)[None, :, None], greyish, colourful) * np.ones((h, w, 3))
    alpha = np.where(np.arange(w) < w // 2, 1.0, 0.6)[None, :] * np.ones((h, w))
    placed = _placed(rgb, alpha)
    colours = np.array([(230, 180, 120), (40, 60, 70), (4, 2, 1)], np.uint8)
    cycle = (np.arange(300)[:, None] // 2 + np.arange(400)[None, :] // 2) % 3
    photo = colours[cycle]
    counted = LINEAR_LUT[colours[:2]].astype(np.float64)
    assert LINEAR_LUT[colours[2]].astype(np.float64) @ REC709 < 0.005
    photo_spread, photo_chroma = _log_spread_and_chroma(counted, np.ones(2))
    paste_spread, paste_chroma = _log_spread_and_chroma(np.array([greyish, colourful]), np.array([1.0, 0.6]))
    unweighted = _log_spread_and_chroma(np.array([greyish, colourful]), np.ones(2))
    assert abs(unweighted[1] / paste_chroma - 1) > 0.1        # weighting matters here, beyond the tolerance below
    settings = MatchSettings(contrast_strength=1.0, saturation_strength=1.0, contrast_gain=(0.1, 10.0),
                             saturation_gain=(0.1, 10.0), surround_share=3.0)
    gains = tone_gains(photo, placed, (0, 0, w, h), settings)
    assert gains == pytest.approx((photo_spread / paste_spread, photo_chroma / paste_chroma), rel=0.02)


def test_retone_keeps_the_mean_log_luminance_and_clips_no_channel():
    rgb, alpha = _colourful()
    rgb[5, :4] = 0.0                                   # black: left black
    rgb[6, :4] = 0.002                                 # darker than the measure's threshold: not counted
    placed = _placed(rgb, alpha)
    counted = (alpha > 0.5) & (rgb @ REC709 > 0.005)

    def mean_log(p):
        a = p.premultiplied[..., 3].astype(np.float64)
        y = (p.premultiplied[..., :3].astype(np.float64) / np.maximum(a, 1e-6)[..., None]) @ REC709
        return np.sum(a[counted] * np.log(y[counted])) / a[counted].sum()

    toned = retone(placed, 1.4, 1.0)
    assert mean_log(toned) == pytest.approx(mean_log(placed), abs=1e-5)       # scaled about its mean, not about 0
    np.testing.assert_array_equal(toned.premultiplied[5, :4, :3], 0.0)
    # darker than the threshold: the threshold's factor
    threshold = math.exp(0.4 * (math.log(0.005) - mean_log(placed)))
    np.testing.assert_allclose(toned.premultiplied[6, :4, :3], placed.premultiplied[6, :4, :3] * threshold, rtol=1e-4)
    assert np.isfinite(toned.premultiplied).all()
    # a saturation gain of 3 pushes most pixels' smallest channel below 0: those stop at 0, their luminance and hue
    # kept; the others take the whole gain
    vivid = retone(placed, 1.0, 3.0)
    inside = alpha > 0
    before = placed.premultiplied[..., :3][inside].astype(np.float64) / alpha[inside][:, None]
    after = vivid.premultiplied[..., :3][inside].astype(np.float64) / alpha[inside][:, None]
    assert after.min() >= 0.0
    np.testing.assert_allclose(after @ REC709, before @ REC709, rtol=1e-4, atol=1e-7)
    y = (before @ REC709)[:, None]
    gain = np.linalg.norm(after - y, axis=1) / np.maximum(np.linalg.norm(before - y, axis=1), 1e-12)
    stopped = after.min(axis=1) < 1e-6
    moved = np.linalg.norm(before - y, axis=1) > 1e-4         # pixels with a chroma to scale (not the greys)
    assert 0 < stopped[moved].mean() < 1
    np.testing.assert_allclose(gain[moved & ~stopped], 3.0, rtol=1e-3)
    assert np.all(gain[moved & stopped] < 3.0 + 1e-3)
    unit = (after - y) / np.maximum(np.linalg.norm(after - y, axis=1, keepdims=True), 1e-12)
    unit_before = (before - y) / np.maximum(np.linalg.norm(before - y, axis=1, keepdims=True), 1e-12)
    np.testing.assert_allclose(unit[moved], unit_before[moved], atol=1e-3)     # the hue kept


def test_tone_matching_changes_the_pastes_colour_only_and_is_recorded(bank):
    entry = bank.entries[0]
    pixels = read_cutout(bank.root, entry)
    photo = _checker_photo((150, 140, 130), (60, 58, 56))      # a greyish, contrasty surround
    paste = [PasteInput(entry, pixels, _placement(entry, (80.0, 100.0), 1.2, 0))]
    as_rendered = compose(photo, paste, ClassMap.default(), NO_MATCH)
    settings = MatchSettings(exposure_strength=0.0, white_balance_strength=0.0, contrast_strength=1.0,
                             saturation_strength=1.0)
    toned = compose(photo, paste, ClassMap.default(), settings)
    np.testing.assert_array_equal(toned.instance_ids, as_rendered.instance_ids)
    np.testing.assert_array_equal(toned.class_ids, as_rendered.class_ids)
    outside = (as_rendered.instance_ids == 0) & (as_rendered.rgb == photo).all(axis=-1)
    np.testing.assert_array_equal(toned.rgb[outside], photo[outside])
    record = toned.pastes[0]
    assert record["saturation_gain"] < 1.0 and record["contrast_gain"] != 1.0
    # exposure and white balance are matched to the paste as toned, not as rendered
    lit = MatchSettings(contrast_strength=1.0, saturation_strength=1.0)
    placed = place(pixels, entry, (80.0, 100.0), 1.2, (160, 120))
    as_toned = paste_gains(photo, retone(placed, record["contrast_gain"], record["saturation_gain"]),
                           paste[0].placement.box, lit)
    assert as_toned != paste_gains(photo, placed, paste[0].placement.box, lit)
    painted = compose(photo, paste, ClassMap.default(), lit).pastes[0]
    assert (painted["exposure_gain"], painted["white_balance_gains"]) == as_toned
    assert "contrast_gain" not in as_rendered.pastes[0] and "saturation_gain" not in as_rendered.pastes[0]
    person = as_rendered.instance_ids == 1
    assert (toned.rgb[person] != as_rendered.rgb[person]).any(axis=1).mean() > 0.9
    # the red person (200, 40, 40 in sRGB) comes out greyer: its channels closer together
    spread_before = np.ptp(as_rendered.rgb[person].astype(int), axis=1).mean()
    assert np.ptp(toned.rgb[person].astype(int), axis=1).mean() < 0.8 * spread_before


def _gaussian_by_hand(values: np.ndarray, sigma: float) -> np.ndarray:
    """``values`` (h, w, c) convolved with a sampled, normalised 2-D Gaussian of ``sigma`` reaching 4 sigma, the
    frame mirrored at its edges (the edge pixel repeated), summed shift by shift."""
    reach = int(np.ceil(4.0 * sigma))
    taps = np.exp(-0.5 * (np.arange(-reach, reach + 1) / sigma) ** 2)
    taps /= taps.sum()
    padded = np.pad(values, ((reach, reach), (reach, reach), (0, 0)), mode="symmetric")
    h, w = values.shape[:2]
    out = np.zeros_like(values, dtype=np.float64)
    for dy in range(-reach, reach + 1):
        for dx in range(-reach, reach + 1):
            out += taps[dy + reach] * taps[dx + reach] * padded[reach + dy:reach + dy + h, reach + dx:reach + dx + w]
    return out


@pytest.mark.parametrize("anchor", [(40.0, 50.0), (6.0, 59.0)])  # inside the frame, and cut by its corner
def test_sharpening_unsharp_masks_the_pastes_labelled_pixels_only_and_keeps_labels(bank, anchor):
    entry = bank.entries[0]
    photo = _photo()
    pixels = read_cutout(bank.root, entry)
    plain = compose(photo, [PasteInput(entry, pixels, _placement(entry, anchor, 1.0, 0))], ClassMap.default(), NO_MATCH)
    amount, sigma = 2.0, 1.5
    sharpened = replace(_placement(entry, anchor, 1.0, 0), sharpen={"amount": amount, "sigma_px": sigma})
    painted = compose(photo, [PasteInput(entry, pixels, sharpened)], ClassMap.default(), NO_MATCH)
    np.testing.assert_array_equal(painted.instance_ids, plain.instance_ids)
    np.testing.assert_array_equal(painted.class_ids, plain.class_ids)
    labelled = plain.instance_ids > 0
    assert labelled.sum() > 50
    np.testing.assert_array_equal(painted.rgb[~labelled], plain.rgb[~labelled])
    values = plain.rgb.astype(np.float64) / 255.0
    expected = np.round(np.clip(values + amount * (values - _gaussian_by_hand(values, sigma)), 0, 1) * 255)
    assert np.abs(painted.rgb[labelled].astype(int) - expected[labelled].astype(int)).max() <= 1
    assert np.abs(painted.rgb[labelled].astype(int) - plain.rgb[labelled].astype(int)).max() > 20


@pytest.mark.parametrize("sigma", [1.7, 2.4])
def test_sharpening_reads_the_whole_gaussians_reach_around_labels_at_the_pastes_edge(sigma):
    """A paste labelled up to its region's edge, far from the frame's: every labelled pixel is sharpened with the
    photo's pixels a Gaussian reaches beyond the region, exactly as over the whole frame."""
    from types import SimpleNamespace

    from synthua_usd.backends.compositing import sharpen

    rgb = np.random.default_rng(3).integers(0, 256, (64, 72, 3), dtype=np.uint8)
    ids = np.zeros((20, 24), np.uint8)
    ids[:, :] = 1
    ids[5:9, 6:10] = 0                                   # a hole: photo pixels inside the region stay
    placed = SimpleNamespace(slices=(slice(22, 42), slice(24, 48)), ids=ids)
    before = rgb.copy()
    sharpen(rgb, placed, 1.5, sigma)
    values = before.astype(np.float64) / 255.0
    expected = np.round(np.clip(values + 1.5 * (values - _gaussian_by_hand(values, sigma)), 0, 1) * 255)
    labelled = np.zeros((64, 72), bool)
    labelled[22:42, 24:48] = ids > 0
    assert np.abs(rgb[labelled].astype(int) - expected[labelled].astype(int)).max() <= 1
    np.testing.assert_array_equal(rgb[~labelled], before[~labelled])
