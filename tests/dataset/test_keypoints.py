"""Keypoint annotations on hand-made label maps and records: the visibility rule, the projection, the COCO
fields, and pycocotools' keypoint evaluation of the ground truth against itself."""

from __future__ import annotations

import contextlib
import copy
import io
import json

import numpy as np
import pytest
from pycocotools.coco import COCO

from format_readers import coco_keypoint_self_evaluation
from label_scenes import record
from synthua_usd.core.errors import InputError
from synthua_usd.dataset.formats.coco import coco_instances
from synthua_usd.dataset.keypoints import DEPTH_TOLERANCE_M, WINDOW_PX, annotate_keypoints, visibility
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES, PERSON_KEYPOINTS
from synthua_usd.model.scene import Keypoints


def test_visibility_follows_the_stated_rule():
    ids = np.zeros((20, 30), np.uint16)
    z = np.zeros((20, 30))
    ids[5:10, 5:10], z[5:10, 5:10] = 3, 4.0           # instance 3 at 4 m
    ids[12:18, 20:26], z[12:18, 20:26] = 4, 2.0       # instance 4 at 2 m
    uv = np.array([[7.5, 7.5],                        # on instance 3, keypoint 0.1 m behind its surface -> 2
                   [5.0 + 5 + WINDOW_PX - 0.5, 7.5],  # 2 px right of its edge: still in the window -> 2
                   [5.0 + 5 + WINDOW_PX + 0.5, 7.5],  # 3 px right: outside the window -> 1
                   [7.5, 7.5],                        # behind its surface by more than the tolerance -> 1
                   [22.5, 14.5],                      # on instance 4 (something else in front) -> 1
                   [-0.5, 3.0], [30.0, 3.0],          # outside the image -> 0
                   [7.5, 7.5]])                       # behind the near plane -> 0
    depth = np.array([4.1, 4.1, 4.1, 4.0 + DEPTH_TOLERANCE_M + 0.01, 3.0, 4.0, 4.0, 0.01])
    assert visibility(uv, depth, 3, ids, z, near_m=0.05).tolist() == [2, 2, 1, 1, 1, 0, 0, 0]
    nan = np.array([[np.nan, np.nan]])
    assert visibility(nan, np.array([-1.0]), 3, ids, z, 0.05).tolist() == [0]


def test_keypoints_are_projected_by_the_camera_and_scaled_to_the_written_size():
    # The USD camera at the origin looks down -Z with +Y up: 50 mm on 36 mm across 320 px.
    camera = PinholeCamera("/C", 50.0, 36.0, 27.0, 0.05, 100.0, np.eye(4))
    f_px = 50.0 * 320 / 36.0
    points = np.array([[0.0, 0.0, -5.0], [1.0, 0.5, -5.0], [0.0, 0.0, 5.0]])
    entries = [{"id": 3}, {"id": 4}]
    ids = np.full((120, 160), 3, np.uint16)                         # written at half the render size
    annotate_keypoints(entries, {3: Keypoints(3, ("a", "b", "c"), points)}, camera, (320, 240), ids,
                       np.full((120, 160), 5.0))
    assert "keypoints" not in entries[1]
    kp = np.array(entries[0]["keypoints"]["keypoints"]).reshape(-1, 3)
    expected = np.array([[160.0, 120.0], [160 + f_px * 1.0 / 5, 120 - f_px * 0.5 / 5]]) / 2
    assert np.abs(kp[:2, :2] - expected).max() < 0.01
    assert kp[:, 2].tolist() == [2, 2, 0] and kp[2, :2].tolist() == [0, 0]  # the third is behind the camera
    assert entries[0]["keypoints"]["num_keypoints"] == 2 and entries[0]["keypoints"]["names"] == ["a", "b", "c"]


def _with_keypoints(rec: dict, rng: np.random.Generator) -> dict:
    """``rec`` with keypoints on its people and wheelchairs: random points inside each one's box, flags
    cycling 0/1/2 (x = y = 0 where 0)."""
    rec = copy.deepcopy(rec)
    for inst in rec["instances"]:
        if inst["class_name"] not in KEYPOINT_CLASSES or inst["id"] == 11:  # 11 (one pixel) keeps none
            continue
        names = KEYPOINT_CLASSES[inst["class_name"]].names
        x, y, w, h = inst["bbox"]
        flat = []
        for k in range(len(names)):
            v = (k + 1) % 3
            flat += [0.0, 0.0, 0] if v == 0 else [float(x + rng.uniform(0, w)), float(y + rng.uniform(0, h)), v]
        inst["keypoints"] = {"names": list(names), "keypoints": flat, "num_keypoints": sum(f > 0 for f in flat[2::3])}
    return rec


@pytest.fixture(scope="module")
def coco_doc(class_map):
    rng = np.random.default_rng(0)
    records = [_with_keypoints(record(i, "train", class_map, flip=i == 2)[0], rng) for i in (1, 2)]
    return coco_instances(records, class_map, "train")


def test_coco_categories_and_annotations_carry_keypoints(coco_doc):
    cats = {c["name"]: c for c in coco_doc["categories"]}
    assert cats["person"]["keypoints"] == list(PERSON_KEYPOINTS) and len(cats["person"]["skeleton"]) == 19
    assert cats["manual_wheelchair"]["keypoints"] == ["left_hand_rim", "right_hand_rim", "seat"]
    assert "keypoints" not in cats["car"]
    for name, kc in KEYPOINT_CLASSES.items():
        assert all(1 <= i <= len(kc.names) for pair in cats[name]["skeleton"] for i in pair)
    for ann in coco_doc["annotations"]:
        name = {c["id"]: c["name"] for c in coco_doc["categories"]}[ann["category_id"]]
        if name not in KEYPOINT_CLASSES:
            assert "keypoints" not in ann
            continue
        flags = ann["keypoints"][2::3]
        assert len(ann["keypoints"]) == 3 * len(KEYPOINT_CLASSES[name].names)
        assert ann["num_keypoints"] == sum(v > 0 for v in flags)
    one_pixel = [a for a in coco_doc["annotations"] if a["prim_path"] == "/World/Agents/P3"]
    assert one_pixel and one_pixel[0]["keypoints"] == [0] * 51 and one_pixel[0]["num_keypoints"] == 0


def test_cocoeval_keypoints_of_gt_against_itself_is_one_for_every_category(tmp_path, coco_doc):
    path = tmp_path / "instances.json"
    path.write_text(json.dumps(coco_doc))
    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO(str(path))
    assert coco_keypoint_self_evaluation(gt) == {"person": pytest.approx(1.0), "manual_wheelchair": pytest.approx(1.0)}


def test_coco_refuses_keypoints_named_otherwise(class_map):
    rec = _with_keypoints(record(1, "train", class_map)[0], np.random.default_rng(1))
    person = next(i for i in rec["instances"] if i["class_name"] == "person")
    person["keypoints"]["names"][0] = "snout"
    with pytest.raises(InputError, match="expected \\['nose'"):
        coco_instances([rec], class_map, "train")
