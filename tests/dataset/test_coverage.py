"""The coverage report from final records: the aid-user table, quotas asked and achieved, shortfalls."""

import json

from synthua_usd.dataset.config import GenerationConfig
from synthua_usd.dataset.coverage import coverage, occlusion_bucket


def record(image_id, split, camera, rig, condition, instances=(), verdict="accepted"):
    return {"id": image_id, "split": split, "camera": {"prim_path": camera, "rig_type": rig},
            "condition": None if condition is None else {"name": condition}, "instances": list(instances),
            "qa": {"verdict": verdict, "reasons": [], "measures": {}}}


def aid(k, person_area, device_area, device_cls="walker", person_amodal=None, device_amodal=None):
    person = {"prim_path": f"/W/P{k}", "class_name": "person", "area": person_area, "relations": {"uses": f"/W/D{k}"}}
    device = {"prim_path": f"/W/D{k}", "class_name": device_cls, "area": device_area, "relations": {}}
    if person_amodal:
        person["amodal_area"], device["amodal_area"] = person_amodal, device_amodal
    return [person, device]


CONFIG = GenerationConfig.from_document({
    "name": "t", "images": 6, "conditions": ["clear_day", "day_fog"],
    "quotas": {"aid_users": {"min_share": 0.5, "min_pixels": 100},
               "per_condition": {"clear_day": 2, "day_fog": 4}, "per_rig_type": "balanced"}})

RECORDS = [
    record(1, "train", "/C/A", "cctv", "clear_day", aid(1, 90, 30, person_amodal=100, device_amodal=60)),  # occl 0.25
    record(2, "train", "/C/A", "cctv", "day_fog", aid(1, 50, 10, person_amodal=100, device_amodal=20)),    # 60 px
    record(3, "val", "/C/B", None, "day_fog", aid(2, 200, 100, "crutch") + aid(3, 10, 5)),                 # unknown occl
    record(4, "test", "/C/C", "uav_nadir", "clear_day"),
    record(5, "test", "/C/C", "uav_nadir", "day_fog", aid(4, 500, 100), verdict="rejected"),
    record(6, "train", "/C/A", "cctv", "day_fog", verdict="flagged"),
]


def test_occlusion_buckets():
    assert [occlusion_bucket(x) for x in (0.0, 0.2499, 0.25, 0.74, 0.75, 1.0, None)] == [
        "0.00-0.25", "0.00-0.25", "0.25-0.50", "0.50-0.75", "0.75-1.00", "0.75-1.00", "unknown"]


def test_coverage_counts_and_shortfalls():
    pool = {"candidates": 40, "aid_users": 3, "per_condition": {"clear_day": 20, "day_fog": 20},
            "per_rig_type": {"cctv": 20, "none": 10, "uav_nadir": 10}}
    report = coverage(RECORDS, CONFIG, pool=pool)
    json.dumps(report)
    assert report["images"] == {"total": 6, "kept": 5, "accepted": 4, "flagged": 1, "rejected": 1}
    assert report["per_condition"] == {"clear_day": 2, "day_fog": 3}
    assert report["per_rig_type"] == {"cctv": 3, "none": 1, "uav_nadir": 1}
    assert report["splits"]["train"] == {"images": 3, "share": 0.6, "cameras": 1}
    assert report["aid_users"] == {"images": 3, "qualifying_images": 2, "instances": 4}
    assert report["table"] == [
        {"aid_type": "crutch", "rig_type": "none", "condition": "day_fog", "occlusion": "unknown", "aid_users": 1, "images": 1},
        {"aid_type": "walker", "rig_type": "cctv", "condition": "clear_day", "occlusion": "0.25-0.50", "aid_users": 1, "images": 1},
        {"aid_type": "walker", "rig_type": "cctv", "condition": "day_fog", "occlusion": "0.50-0.75", "aid_users": 1, "images": 1},
        {"aid_type": "walker", "rig_type": "none", "condition": "day_fog", "occlusion": "unknown", "aid_users": 1, "images": 1},
    ]
    quotas = {(q["quota"], q["key"]): (q["asked"], q["achieved"], q["met"]) for q in report["quotas"]}
    # per_rig_type balanced over the kept records' rig types (cctv, none, uav_nadir): 6 -> 2, 2, 2
    assert quotas == {("images", None): (6, 5, False), ("aid_users", None): (3, 2, False),
                      ("per_condition", "clear_day"): (2, 2, True), ("per_condition", "day_fog"): (4, 3, False),
                      ("per_rig_type", "cctv"): (2, 3, True), ("per_rig_type", "none"): (2, 1, False),
                      ("per_rig_type", "uav_nadir"): (2, 1, False)}
    assert report["shortfalls"] == [
        "images: asked 6, got 5 (1 rejected by QA; the pool had 40)",
        "aid_users: asked 3 images with an aid user of >= 100 px, got 2 (the pool had 3)",
        "per_condition day_fog: asked 4, got 3 (the pool had 20)",
        "per_rig_type none: asked 2, got 1 (the pool had 10)",
        "per_rig_type uav_nadir: asked 2, got 1 (the pool had 10)",
    ]


def test_targets_from_the_plan_and_no_pool():
    targets = {"images": 6, "aid_users": 3, "per_condition": {"clear_day": 2, "day_fog": 4}, "per_rig_type": {"dashcam": 1}}
    report = coverage(RECORDS, CONFIG, targets=targets)
    assert "per_rig_type dashcam: asked 1, got 0" in report["shortfalls"]
    assert all("pool" not in q for q in report["quotas"])
