"""Planning a composite's pastes: every paste stands on the photo's ground plane at the share of the frame it was
drawn for, its cut-out's camera elevation is among the nearest to the paste's, nearer pastes come later, Poisson at
most once; checked against the ground-plane relations computed here again."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from bank_maker import default_cutouts, write_bank
from synthua_usd.core.errors import InputError
from synthua_usd.dataset.composite_config import CameraSettings, CompositeConfig
from synthua_usd.dataset.composite_plan import covered_share, draw_camera, eligible, plan_pastes
from synthua_usd.dataset.cutout_bank import read_bank
from synthua_usd.model.photo_camera import PhotoCamera


@pytest.fixture(scope="module")
def bank(tmp_path_factory):
    return read_bank(write_bank(tmp_path_factory.mktemp("bank") / "bank"))


def _drawn(camera: PhotoCamera, light=None):
    from synthua_usd.dataset.composite_plan import DrawnCamera

    return DrawnCamera(camera, {"horizon_row_px": "config", "height_m": "config", "focal_px": "config"}, light, None)


@pytest.mark.parametrize("seed", range(6))
def test_pastes_stand_on_the_ground_plane_at_their_share(bank, seed):
    config = CompositeConfig.from_document({"pastes": {"per_image": [3, 3], "height_share": [0.2, 0.6],
                                                       "choose_among": 2}})
    camera = PhotoCamera(320, 240, 40.0, 1.4, 300.0)
    pools = eligible(bank.entries, config)
    placements = plan_pastes(_drawn(camera), pools, config, [], np.random.default_rng(seed))
    assert len(placements) == 3
    assert [p.order for p in placements] == [0, 1, 2]
    assert [p.anchor_px[1] for p in placements] == sorted(p.anchor_px[1] for p in placements)  # far to near
    assert placements[0].kind == "aid_user" or any(p.kind == "aid_user" for p in placements)
    for p in placements:
        entry = bank.entry(p.entry_id)
        drop = p.anchor_px[1] - camera.horizon_row_px
        z = camera.focal_px * camera.height_m / drop
        assert p.distance_m == pytest.approx(z)
        assert p.elevation_deg == pytest.approx(math.degrees(math.atan2(camera.height_m, z)))
        # the group's pixel height on the ground plane is the drawn share of the frame (the camera allows 0.6)
        assert entry.subject_height_m * drop / camera.height_m == pytest.approx(p.share * 240)
        assert p.share == pytest.approx(p.share_drawn)
        assert 0.2 <= p.share <= 0.6
        # its scale makes its pixels per metre at the anchor the ground plane's: f / Z
        assert p.scale * entry.scale_px_per_m == pytest.approx(camera.focal_px / z)
        # the group's box lies within the frame's width
        assert -1e-9 <= p.box[0] and p.box[2] <= 320 + 1e-9
        # the cut-out is among the `choose_among` best for the elevation of the paste of the kind's median height
        kind = [e for e in bank.entries if e.kind == p.kind]
        nominal = float(np.median([e.subject_height_m for e in kind]))
        elevation = math.degrees(math.atan(p.share * 240 * camera.height_m / nominal / camera.focal_px))
        ranked = sorted(kind, key=lambda e: (abs(e.camera.elevation_deg - elevation), e.id))
        assert entry.id in [e.id for e in ranked[:config.pastes.choose_among]]


def test_the_first_paste_is_an_aid_user_and_poisson_comes_once(bank):
    config = CompositeConfig.from_document({"pastes": {"per_image": [4, 4], "aid_user_share": 0.0},
                                            "blend": {"hard": 0, "feather": 0, "blur": 0, "poisson": 1}})
    camera = PhotoCamera(640, 480, 100.0, 1.5, 500.0)
    for seed in range(5):
        placements = plan_pastes(_drawn(camera), eligible(bank.entries, config), config, [],
                                 np.random.default_rng(seed))
        kinds = sorted(p.kind for p in placements)
        assert kinds == ["aid_user", "pedestrian", "pedestrian", "pedestrian"]
        modes = [p.blend["mode"] for p in placements]
        assert modes.count("poisson") == 1 and modes.count("hard") == 3  # the others fall back to hard


def test_a_camera_that_cannot_show_the_share_takes_the_largest_it_can(bank):
    config = CompositeConfig.from_document({"pastes": {"per_image": [1, 1], "height_share": [0.9, 0.9]}})
    camera = PhotoCamera(320, 240, 200.0, 1.5, 300.0)     # horizon low: the ground is a strip of 40 rows
    (p,) = plan_pastes(_drawn(camera), eligible(bank.entries, config), config, [], np.random.default_rng(0))
    entry = bank.entry(p.entry_id)
    assert p.anchor_px[1] == pytest.approx(camera.lowest_anchor_row())
    assert p.share == pytest.approx(entry.subject_height_m * (239.5 - 200.0) / 1.5 / 240)
    assert p.share_drawn == pytest.approx(0.9)


def test_pastes_keep_off_earlier_ones_and_background_boxes_where_they_can(bank):
    config = CompositeConfig.from_document({"pastes": {"per_image": [3, 3], "height_share": [0.3, 0.3],
                                                       "max_overlap": 0.0, "placement_tries": 200}})
    camera = PhotoCamera(640, 480, 100.0, 1.5, 500.0)
    kept = [(0.0, 0.0, 200.0, 480.0)]
    for seed in range(4):
        placements = plan_pastes(_drawn(camera), eligible(bank.entries, config), config, kept,
                                 np.random.default_rng(seed))
        for a in placements:
            assert covered_share(kept[0], a.box) <= config.background_labels.drop_covered_share
            for b in placements:
                if a is not b:
                    assert covered_share(a.box, b.box) == pytest.approx(0.0, abs=1e-9)


def test_pastes_keep_off_labelled_people_entirely_or_are_skipped(bank):
    """max_background_cover 0 with when_no_room skip: no paste covers any of a kept box; a photo whose labelled
    people fill the ground gets no paste at all, where least_overlap would cover them."""
    roomy = {"per_image": [3, 3], "height_share": [0.3, 0.3], "max_overlap": 1.0, "placement_tries": 50,
             "max_background_cover": 0.0, "when_no_room": "skip"}
    config = CompositeConfig.from_document({"pastes": roomy})
    camera = PhotoCamera(640, 480, 100.0, 1.5, 500.0)
    kept = [(0.0, 0.0, 250.0, 480.0)]
    made = 0
    for seed in range(6):
        placements = plan_pastes(_drawn(camera), eligible(bank.entries, config), config, kept,
                                 np.random.default_rng(seed))
        made += len(placements)
        for p in placements:                                 # independent: the box against the kept one
            x0, y0, x1, y1 = p.box
            assert x0 >= 250.0 - 1e-6 or x1 <= 0.0 or y1 <= 0.0
    assert made > 0
    full = [(0.0, 0.0, 640.0, 480.0)]
    for seed in range(3):
        assert plan_pastes(_drawn(camera), eligible(bank.entries, config), config, full,
                           np.random.default_rng(seed)) == []
        crowded = CompositeConfig.from_document({"pastes": {**roomy, "when_no_room": "least_overlap"}})
        assert len(plan_pastes(_drawn(camera), eligible(bank.entries, crowded), crowded, full,
                               np.random.default_rng(seed))) == 3


def test_pastes_stand_partly_beyond_the_side_edges_within_edge_cut(bank):
    """edge_cut: a paste's box may reach beyond the left edge, and beyond the right one, by at most that share of its
    width (people at a photo's edge are cut off so); where the photo's labelled people fill the middle, that is the
    room left."""
    base = {"per_image": [2, 2], "height_share": [0.5, 0.6], "max_overlap": 1.0, "placement_tries": 50,
            "max_background_cover": 0.0, "when_no_room": "skip"}
    camera = PhotoCamera(640, 480, 100.0, 1.5, 500.0)
    middle = [(80.0, 0.0, 560.0, 480.0)]
    made, cut_off = {}, 0
    for share in (0.0, 0.5):
        config = CompositeConfig.from_document({"pastes": {**base, "edge_cut": share}})
        made[share] = 0
        for seed in range(8):
            for p in plan_pastes(_drawn(camera), eligible(bank.entries, config), config, middle,
                                 np.random.default_rng(seed)):
                made[share] += 1
                x0, _, x1, _ = p.box                         # independent: the box against the frame and the kept one
                assert x1 <= 80.0 + 1e-6 or x0 >= 560.0 - 1e-6
                assert max(-x0, x1 - 640.0) <= share * (x1 - x0) + 1e-6
                outside = max(0.0, -x0) + max(0.0, x1 - 640.0)
                cut_off += outside > 1e-6
    assert made[0.5] > made[0.0] and cut_off > 0, (made, cut_off)


def test_the_default_placement_limit_is_the_drop_threshold(bank):
    """max_background_cover null is background_labels.drop_covered_share: the same plans as before the key."""
    camera = PhotoCamera(640, 480, 100.0, 1.5, 500.0)
    kept = [(100.0, 50.0, 400.0, 480.0)]
    base = {"per_image": [3, 3], "max_overlap": 0.0, "placement_tries": 30}
    implicit = CompositeConfig.from_document({"pastes": base, "background_labels": {"drop_covered_share": 0.2}})
    explicit = CompositeConfig.from_document({"pastes": {**base, "max_background_cover": 0.2},
                                              "background_labels": {"drop_covered_share": 0.2}})
    for seed in range(3):
        a = plan_pastes(_drawn(camera), eligible(bank.entries, implicit), implicit, kept, np.random.default_rng(seed))
        b = plan_pastes(_drawn(camera), eligible(bank.entries, explicit), explicit, kept, np.random.default_rng(seed))
        assert a == b


@pytest.mark.parametrize("pastes, message", [
    ({"when_no_room": "squeeze"}, "pastes.when_no_room"),
    ({"max_background_cover": 1.5}, "pastes.max_background_cover"),
    ({"edge_cut": 1.0}, "edge_cut"),
])
def test_placement_limits_are_checked(pastes, message):
    with pytest.raises(InputError, match=message):
        CompositeConfig.from_document({"pastes": pastes})


def test_edge_cut_is_checked_by_the_settings_too():
    """The schema bounds edge_cut; settings made in code (no document) are held to the same range."""
    from synthua_usd.dataset.composite_config import PasteSettings

    with pytest.raises(InputError, match="pastes.edge_cut: 0.95"):
        PasteSettings(edge_cut=0.95)


def test_the_camera_draw_names_its_sources():
    settings = CameraSettings(horizon_row_share=(0.25, 0.25), height_m=(1.6, 1.6), focal_width_share=(0.5, 0.5),
                              use_exif=True)
    sources = {"horizon_row_share": "folder:x", "height_m": "config", "focal_width_share": "config",
               "use_exif": "config", "pitch_deg": "config", "light": "config"}
    rng = np.random.default_rng(0)
    drawn = draw_camera(settings, sources, (640, 480), 28.0, (4000, 3000), 0.16, rng)
    assert drawn.camera.focal_px == pytest.approx(28.0 / 36.0 * 4000 * 0.16)
    assert drawn.camera.horizon_row_px == pytest.approx(120.0)
    assert drawn.sources == {"horizon_row_px": "folder:x", "height_m": "config", "focal_px": "exif"}
    drawn = draw_camera(CameraSettings(focal_width_share=(0.5, 0.5), pitch_deg=-10.0), sources, (640, 480), None,
                        (640, 480), 1.0, rng)
    assert drawn.camera.focal_px == pytest.approx(320.0)
    assert drawn.camera.horizon_row_px == pytest.approx(240 + 320 * math.tan(math.radians(-10.0)))
    assert drawn.sources["horizon_row_px"] == "pitch_deg:config" and drawn.sources["focal_px"] == "config"


def test_the_photos_people_place_the_horizon_unless_the_pitch_is_known():
    sources = {"horizon_row_share": "config", "height_m": "config", "focal_width_share": "config",
               "use_exif": "config", "pitch_deg": "config", "light": "config", "person_height_m": "folder:kids",
               "wheelchair_height_m": "config"}
    people = [("person", (10.0, 200.0, 60.0, 370.0)), ("person", (300.0, 0.0, 340.0, 300.0)),   # whole; cut at the top
              ("manual_wheelchair", (400.0, 260.0, 470.0, 400.0)), ("walker", (500.0, 100.0, 540.0, 200.0))]
    settings = CameraSettings(horizon_row_share=(0.25, 0.25), height_m=(1.2, 1.2), person_height_m=1.2)
    drawn = draw_camera(settings, sources, (640, 480), None, (640, 480), 1.0, np.random.default_rng(0), people)
    assert drawn.camera.horizon_row_px == pytest.approx(370.0 - 170.0 * 1.2 / 1.2)
    assert drawn.sources["horizon_row_px"] == "people:1:folder:kids"
    # the wheelchair user counts where wheelchair_height_m is set: the median of the two rows
    both = draw_camera(replace(settings, wheelchair_height_m=1.4), sources, (640, 480), None, (640, 480), 1.0,
                       np.random.default_rng(0), people)
    assert both.camera.horizon_row_px == pytest.approx(np.median([200.0, 400.0 - 140.0 * 1.2 / 1.4]))
    assert both.sources["horizon_row_px"] == "people:2:folder:kids+config"
    seated = draw_camera(CameraSettings(height_m=(1.2, 1.2), wheelchair_height_m=1.4), sources, (640, 480), None,
                         (640, 480), 1.0, np.random.default_rng(0), people)
    assert seated.camera.horizon_row_px == pytest.approx(280.0)
    assert seated.sources["horizon_row_px"] == "people:1:config"
    # the photo reaching above the frame holds the second person whole: it counts then
    above = draw_camera(settings, sources, (640, 480), None, (640, 480), 1.0, np.random.default_rng(0), people,
                        (-50.0, 480.0))
    assert above.camera.horizon_row_px == pytest.approx(np.median([200.0, 300.0 - 300.0 * 1.2 / 1.2]))
    pitched = draw_camera(replace(settings, pitch_deg=-5.0, wheelchair_height_m=1.4), sources, (640, 480), None,
                          (640, 480), 1.0, np.random.default_rng(0), people)
    assert pitched.sources["horizon_row_px"] == "pitch_deg:config"
    alone = draw_camera(settings, sources, (640, 480), None, (640, 480), 1.0, np.random.default_rng(0), people[1:])
    assert alone.sources["horizon_row_px"] == "config" and alone.camera.horizon_row_px == pytest.approx(120.0)


def test_the_plan_depends_on_the_seed_only(bank):
    config = CompositeConfig()
    camera = PhotoCamera(640, 480, 150.0, 1.5, 500.0)
    runs = [plan_pastes(_drawn(camera), eligible(bank.entries, config), config, [], np.random.default_rng(7))
            for _ in range(2)]
    assert runs[0] == runs[1]
    assert len(default_cutouts()) == len(bank.entries)


def test_sharpening_is_drawn_per_paste_within_its_ranges_and_not_at_all_when_off(bank):
    camera = PhotoCamera(640, 480, 150.0, 1.5, 500.0)
    pastes = {"per_image": [3, 3]}

    def plans(document):
        config = CompositeConfig.from_document({"pastes": pastes, **document})
        return [plan_pastes(_drawn(camera), eligible(bank.entries, config), config, [], np.random.default_rng(seed))
                for seed in range(12)]

    off = plans({})
    assert all(p.sharpen is None for plan in off for p in plan)
    assert plans({"sharpen": {"share": 0.0, "amount": [5, 6]}}) == off   # a share of 0 draws nothing
    every = [p.sharpen for plan in plans({"sharpen": {"share": 1.0, "amount": [1.5, 2.5], "sigma_px": [1, 2]}})
             for p in plan]
    assert every and all(1.5 <= s["amount"] <= 2.5 and 1.0 <= s["sigma_px"] <= 2.0 for s in every)
    half = [p.sharpen is not None for plan in plans({"sharpen": {"share": 0.5}}) for p in plan]
    assert 0.2 < np.mean(half) < 0.8
    # drawn from a generator of their own: the pastes are those of the same config without sharpening
    strip = [[replace(p, sharpen=None) for p in plan] for plan in plans({"sharpen": {"share": 1.0}})]
    assert strip == off


def _in_view(box, width, height):
    return max(box[0], 0.0), max(box[1], 0.0), min(box[2], width), min(box[3], height)


def test_overlap_is_measured_on_the_part_of_an_earlier_paste_in_view(bank):
    """With pastes cut by the frame's sides, ``max_overlap`` holds for the part of the earlier paste the frame shows:
    of two pastes, the later one (the one whose record's ``overlap`` is not 0) covers at most that share of the
    earlier one's box clipped to the frame, recomputed here, and its record says how much. Jobs made before
    7 December 2026 measured the earlier paste's whole box, and then a later paste could hide more of what is seen of
    it (a narrow frame crowded with large pastes shows it)."""
    config = CompositeConfig.from_document({"pastes": {
        "per_image": [2, 2], "height_share": [0.6, 0.8], "max_overlap": 0.3, "placement_tries": 60,
        "when_no_room": "skip", "edge_cut": 0.8}})
    camera = PhotoCamera(160, 240, 60.0, 1.5, 250.0)
    pairs, beyond = {True: 0, False: 0}, {True: 0, False: 0}
    for visible in (True, False):
        for seed in range(300):
            placements = plan_pastes(_drawn(camera), eligible(bank.entries, config), config, [],
                                     np.random.default_rng(seed), visible_overlap=visible, overlap_by_depth=False)
            if len(placements) < 2:
                continue
            a, b = placements
            first, later = (a, b) if a.overlap == 0 else (b, a)
            shown = covered_share(_in_view(first.box, 160.0, 240.0), later.box)
            pairs[visible] += 1
            beyond[visible] += shown > 0.3 + 1e-9
            if visible and later.overlap > 0:
                assert later.overlap == pytest.approx(shown)
    assert pairs[True] >= 100 and beyond[True] == 0, (pairs, beyond)
    assert beyond[False] > 0, (pairs, beyond)


def test_overlap_is_measured_of_the_farther_paste_whichever_was_planned_first(bank):
    """Of two pastes, the nearer one (drawn later, ``order`` 1) covers at most ``max_overlap`` of the farther one's
    box in view, recomputed here from the plan, whichever of the two was planned first; the record's ``overlap``
    (on the paste planned second, the one whose ``overlap`` is not 0) says how much. Jobs made before
    ``job_key.overlap_by_depth`` measured how much of the first-planned paste the second covers, and then a farther
    paste planned second could stand mostly hidden behind the first: pastes of very unlike sizes in a narrow frame
    show it."""
    config = CompositeConfig.from_document({"pastes": {
        "per_image": [2, 2], "height_share": [0.25, 0.95], "max_overlap": 0.3, "placement_tries": 60,
        "when_no_room": "skip", "edge_cut": 0.5}})
    camera = PhotoCamera(200, 240, 60.0, 1.5, 250.0)
    pairs, beyond, second_behind = {True: 0, False: 0}, {True: 0, False: 0}, 0
    for by_depth in (True, False):
        for seed in range(300):
            placements = plan_pastes(_drawn(camera), eligible(bank.entries, config), config, [],
                                     np.random.default_rng(seed), overlap_by_depth=by_depth)
            if len(placements) < 2:
                continue
            far, near = sorted(placements, key=lambda p: p.order)
            hidden = covered_share(_in_view(far.box, 200.0, 240.0), near.box)
            pairs[by_depth] += 1
            beyond[by_depth] += hidden > 0.3 + 1e-9
            if by_depth:
                second = far if far.overlap > 0 else near
                second_behind += second is far
                if second.overlap > 0:
                    assert second.overlap == pytest.approx(hidden)
    assert pairs[True] >= 100 and beyond[True] == 0, (pairs, beyond)
    assert second_behind >= 10, second_behind
    assert beyond[False] > 0, (pairs, beyond)
