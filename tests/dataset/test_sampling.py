"""Candidates of a sweep, the quota plan on a synthetic pool, and the camera-grouped split."""

from collections import Counter

import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.dataset.config import GenerationConfig, SplitRatios
from synthua_usd.dataset.sampling import (
    ViewScore, candidates, plan, pool_summary, quota_targets, replacements, select_cameras, split_counts, split_of,
)

CAMERAS = [("/World/Cameras/CCTV_A", "CCTV_A", "cctv"), ("/World/Cameras/CCTV_B", "CCTV_B", "cctv"),
           ("/World/Cameras/Drone", "Drone", "uav_nadir"), ("/World/Cameras/Street", "Street", None)]
STAGE_TIMES = [float(t) for t in range(1, 49)]
CONDITIONS = ["clear_day", "day_fog", "clear_night", "snow"]
AID_TIMES = (1.0, 6.0, 11.0, 16.0, 21.0)
#: Aid users: CCTV_A sees a big one at five time codes; Drone sees a small one (below min_pixels) at two.
SCORES = ([ViewScore.from_rows("/World/Cameras/CCTV_A", t, [("walker", 250, 60, 0.2)]) for t in AID_TIMES]
          + [ViewScore.from_rows("/World/Cameras/Drone", t, [("crutch", 20, 5, None)]) for t in (1.0, 6.0)])


def config(**changes) -> GenerationConfig:
    doc = {"name": "t", "images": 30, "time_codes": "1:46:5", "conditions": ["clear_day", "day_fog", "clear_night"],
           "seeds": [0, 1]}
    return GenerationConfig.from_document({**doc, **changes})


def test_candidates_sweep_in_order():
    pool = candidates(config(), CAMERAS, STAGE_TIMES, CONDITIONS)
    assert len(pool) == 3 * 4 * 10 * 2
    first = pool[0]
    assert (first.condition, first.camera_path, first.time_code, first.seed) == ("clear_day", "/World/Cameras/CCTV_A", 1.0, 0)
    assert [c.seed for c in pool[:2]] == [0, 1]
    assert pool[2].time_code == 6.0 and pool[20].camera_path == "/World/Cameras/CCTV_B"
    assert pool[-1].condition == "clear_night"
    stage_own = candidates(config(conditions=[], time_codes=[]), CAMERAS, STAGE_TIMES, CONDITIONS)
    assert {c.condition for c in stage_own} == {None} and len(stage_own) == 4 * 48 * 2
    assert {c.condition for c in candidates(config(conditions="all"), CAMERAS, STAGE_TIMES, CONDITIONS)} == set(CONDITIONS)


def test_camera_selectors():
    pick = lambda *items: [p for p, _, _ in select_cameras(config(cameras=list(items)), CAMERAS)]  # noqa: E731
    assert pick() == [p for p, _, _ in CAMERAS]
    assert pick("/World/Cameras/CCTV_*") == ["/World/Cameras/CCTV_A", "/World/Cameras/CCTV_B"]
    assert pick({"rig_types": ["none", "uav_nadir"]}, "/World/Cameras/CCTV_B") == [
        "/World/Cameras/CCTV_B", "/World/Cameras/Drone", "/World/Cameras/Street"]
    with pytest.raises(InputError, match=r"^cameras\[1\]: '/World/Cam/X' matches no camera; expected a camera"):
        pick("/World/Cameras/Drone", "/World/Cam/X")
    with pytest.raises(InputError, match=r"^cameras\[0\]: rig types dashcam match no camera"):
        pick({"rig_types": ["dashcam"]})


def test_sweep_names_checked_against_the_stage():
    with pytest.raises(InputError, match="^conditions: rain not offered by the stage; expected among clear_day"):
        candidates(config(conditions=["rain"]), CAMERAS, STAGE_TIMES, CONDITIONS)
    with pytest.raises(InputError, match=r"^time_codes: 50 outside the stage's time range; expected time codes within 1..48"):
        candidates(config(time_codes=[1, 50]), CAMERAS, STAGE_TIMES, CONDITIONS)
    with pytest.raises(InputError, match='^conditions: "all" but the stage offers no conditions'):
        candidates(config(conditions="all"), CAMERAS, STAGE_TIMES, [])


def count_qualifying(images, min_pixels):
    """Independently: images whose view has an aid user of >= min_pixels (person + device)."""
    big = {(s.camera_path, s.time_code) for s in SCORES
           if any(a.person_pixels + a.device_pixels >= min_pixels for a in s.aid_users)}
    return sum((i.camera_path, i.time_code) in big for i in images)


def test_plan_meets_quotas_on_a_synthetic_pool():
    cfg = config(quotas={"aid_users": {"min_share": 0.5, "min_pixels": 100}, "per_condition": "balanced",
                         "per_rig_type": {"uav_nadir": 6, "none": 6}})
    pool = candidates(cfg, CAMERAS, STAGE_TIMES, CONDITIONS)
    images = plan(pool, SCORES, cfg)
    assert len(images) == 30 and [i.id for i in images] == list(range(1, 31))
    assert len({(i.camera_path, i.time_code, i.condition, i.seed) for i in images}) == 30
    assert count_qualifying(images, 100) >= 15
    assert sum(i.aid_user for i in images) == count_qualifying(images, 100)
    assert Counter(i.condition for i in images) == {"clear_day": 10, "day_fog": 10, "clear_night": 10}
    rigs = Counter(i.rig_type or "none" for i in images)
    assert rigs["uav_nadir"] >= 6 and rigs["none"] >= 6
    assert quota_targets(pool, cfg) == {"images": 30, "aid_users": 15,
                                        "per_condition": {"clear_day": 10, "day_fog": 10, "clear_night": 10},
                                        "per_rig_type": {"uav_nadir": 6, "none": 6}}


def test_plan_takes_all_the_pool_has_when_a_quota_cannot_be_met():
    cfg = config(images=40, quotas={"aid_users": {"min_share": 1.0, "min_pixels": 100}})
    pool = candidates(cfg, CAMERAS, STAGE_TIMES, CONDITIONS)
    summary = pool_summary(pool, SCORES, cfg)
    assert summary["aid_users"] == 5 * 3 * 2  # CCTV_A's five time codes x 3 conditions x 2 seeds
    images = plan(pool, SCORES, cfg)
    assert len(images) == 40 and count_qualifying(images, 100) == 30
    # An occlusion bound the views exceed leaves only the views whose occlusion is unknown (the planner's label
    # pass knows pixels only: Drone's two time codes x 3 conditions x 2 seeds); QA and coverage know it.
    strict = config(quotas={"aid_users": {"min_share": 0.5, "min_pixels": 10, "max_occlusion": 0.1}})
    assert pool_summary(pool, SCORES, strict)["aid_users"] == 12
    loose = config(quotas={"aid_users": {"min_share": 0.5, "min_pixels": 10, "max_occlusion": 0.5}})
    assert pool_summary(pool, SCORES, loose)["aid_users"] == 30 + 12


def test_plan_is_deterministic_and_seeded():
    cfg = config(quotas={"per_condition": "balanced"})
    pool = candidates(cfg, CAMERAS, STAGE_TIMES, CONDITIONS)
    assert plan(pool, SCORES, cfg) == plan(list(pool), {(s.camera_path, s.time_code): s for s in SCORES}, cfg)
    other = config(quotas={"per_condition": "balanced"}, sampling_seed=7)
    assert plan(pool, SCORES, other) != plan(pool, SCORES, cfg)


def test_a_pool_smaller_than_asked_is_taken_whole():
    cfg = config(images=1000)
    pool = candidates(cfg, CAMERAS, STAGE_TIMES, CONDITIONS)
    assert len(plan(pool, SCORES, cfg)) == len(pool)


def test_splits_keep_each_camera_whole():
    cfg = config(images=60, split={"train": 0.5, "val": 0.25, "test": 0.25, "seed": 3})
    images = plan(candidates(cfg, CAMERAS, STAGE_TIMES, CONDITIONS), SCORES, cfg)
    by_camera = {}
    for image in images:
        by_camera.setdefault(image.camera_path, set()).add(image.split)
    assert all(len(splits) == 1 for splits in by_camera.values())
    assert Counter(s for (s,) in by_camera.values()) == {"train": 2, "val": 1, "test": 1}


@pytest.mark.parametrize("groups, ratios, expected", [
    (12, (0.8, 0.1, 0.1), (10, 1, 1)),   # 9.6, 1.2, 1.2: floors 9, 1, 1 and the remainder to train
    (10, (0.8, 0.1, 0.1), (8, 1, 1)),
    (3, (0.8, 0.1, 0.1), (1, 1, 1)),     # 2.4, .3, .3 -> 3, 0, 0; then val and test get one each from train
    (2, (0.8, 0.1, 0.1), (2, 0, 0)),     # too few groups to give every split one
    (5, (0.5, 0.5, 0.0), (3, 2, 0)),     # tied remainders go in train, val, test order
    (3, (0.34, 0.33, 0.33), (1, 1, 1)),
    (0, (0.8, 0.1, 0.1), (0, 0, 0)),
])
def test_split_counts_by_largest_remainder(groups, ratios, expected):
    train, val, test = ratios
    counts = split_counts(groups, SplitRatios(train, val, test))
    assert (counts["train"], counts["val"], counts["test"]) == expected


def test_split_of_ignores_order_and_depends_on_the_seed():
    groups = [f"/World/Cameras/C{k}" for k in range(20)]
    ratios = SplitRatios(0.6, 0.2, 0.2, seed=1)
    assert split_of(groups, ratios) == split_of(reversed(groups + groups), ratios)
    assert Counter(split_of(groups, ratios).values()) == {"train": 12, "val": 4, "test": 4}
    assert split_of(groups, ratios) != split_of(groups, SplitRatios(0.6, 0.2, 0.2, seed=2))


def test_replacements_restore_the_quotas_of_rejected_images():
    cfg = config(images=12, quotas={"aid_users": {"min_share": 0.25, "min_pixels": 100},
                                    "per_condition": "balanced"})
    pool = candidates(cfg, CAMERAS, STAGE_TIMES, CONDITIONS)
    planned = plan(pool, SCORES, cfg)
    # QA rejects every clear_day image and one aid-user image
    rejected = {p.id for p in planned if p.condition == "clear_day"}
    rejected.add(next(p.id for p in planned if p.aid_user))
    extra = replacements(pool, SCORES, cfg, planned, rejected)
    assert len(extra) == len(rejected)
    assert [p.id for p in extra] == list(range(len(planned) + 1, len(planned) + 1 + len(extra)))
    key = lambda p: (p.camera_path, p.time_code, p.condition, p.seed)  # noqa: E731
    assert not {key(p) for p in extra} & {key(p) for p in planned}
    splits = {p.camera_path: p.split for p in planned}
    assert all(splits[p.camera_path] == p.split for p in extra)  # cameras of the plan, splits unchanged
    kept = [p for p in planned if p.id not in rejected] + extra
    assert Counter(p.condition for p in kept) == Counter(p.condition for p in planned)
    assert sum(p.aid_user for p in kept) >= quota_targets(pool, cfg)["aid_users"]
    assert replacements(pool, SCORES, cfg, planned, rejected) == extra  # deterministic
