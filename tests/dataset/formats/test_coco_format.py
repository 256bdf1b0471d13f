"""COCO instances and COCO panoptic read by the real tools: pycocotools (COCO, COCOeval) and panopticapi
(pq_compute, from the panopticapi-lite wheel: the cocodataset/panopticapi code)."""

from __future__ import annotations

import contextlib
import io
import json
import multiprocessing

import numpy as np
import pytest
from pycocotools import mask as mask_utils
from pycocotools.coco import COCO

from format_readers import coco_self_evaluation
from label_scenes import record
from synthua_usd.core.images import write_color_png
from synthua_usd.dataset.annotations import panoptic
from synthua_usd.dataset.formats.coco import coco_instances
from synthua_usd.dataset.formats.panoptic import coco_panoptic
from synthua_usd.dataset.layout import Layout
from label_scenes import INSTANCES


@pytest.fixture(scope="module")
def dataset(class_map):
    """Records in a scrambled order: two train images, one val, one rejected train image."""
    made = [record(3, "val", class_map), record(1, "train", class_map),
            record(4, "train", class_map, verdict="rejected"), record(2, "train", class_map, flip=True)]
    return [r for r, _ in made], {r["id"]: maps for r, maps in made}


def test_pycocotools_loads_it_and_cocoeval_of_gt_against_itself_is_one(tmp_path, class_map, dataset):
    records, maps = dataset
    doc = coco_instances(records, class_map, "train")
    assert [i["id"] for i in doc["images"]] == [1, 2]                      # rejected 4 left out, val elsewhere
    assert doc["images"][0]["file_name"] == f"{records[1]['name']}.png"
    path = tmp_path / "instances_train.json"
    path.write_text(json.dumps(doc))
    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO(str(path))
    things = {c.id for c in class_map.classes if c.isthing}
    for ann in gt.loadAnns(gt.getAnnIds()):
        cls, ins, _ = maps[ann["image_id"]]
        mask = ins == ann["instance_id"]
        assert np.array_equal(gt.annToMask(ann).astype(bool), mask)
        ys, xs = np.nonzero(mask)
        assert ann["bbox"] == [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1]
        assert ann["area"] == mask.sum() and ann["category_id"] in things and ann["id"] >= 1
    assert {c["id"] for c in doc["categories"]} == {c.id for c in class_map.classes if c.isthing and c.id >= 1}
    for kind, stats in coco_self_evaluation(gt, doc["annotations"]).items():
        assert stats[0] == pytest.approx(1.0) and stats[1] == pytest.approx(1.0), kind


def test_annotation_ids_are_unique_across_splits_and_relations_point_to_annotations(class_map, dataset):
    records, _ = dataset
    docs = {s: coco_instances(records, class_map, s) for s in ("train", "val", "test")}
    ids = [a["id"] for d in docs.values() for a in d["annotations"]]
    assert sorted(ids) == list(range(1, len(ids) + 1))
    assert docs["test"]["images"] == [] and docs["val"]["images"][0]["id"] == 3
    assert coco_instances(list(reversed(records)), class_map, "train") == docs["train"]  # order-free
    for doc in (docs["train"], docs["val"]):
        by_id = {a["id"]: a for a in doc["annotations"]}
        related = [a for a in doc["annotations"] if a["relations"]]
        assert {"uses", "pushes", "accompanies"} <= {name for a in related for name in a["relations"]}
        for a in related:
            for name in ("uses", "pushes", "accompanies"):
                if name not in a["relations"]:
                    continue
                target = by_id[a["relations"][f"{name}_annotation_id"]]  # every target here is in view
                assert target["prim_path"] == a["relations"][name] and target["image_id"] == a["image_id"]
                assert a["relations"][f"{name}_class"] == {"uses": "manual_wheelchair", "pushes": "manual_wheelchair",
                                                           "accompanies": "person"}[name]
        occluded = [a for a in doc["annotations"] if a["prim_path"] == "/World/Car"][0]
        assert 0 < occluded["occlusion"] < 1
        assert mask_utils.area(occluded["amodal_segmentation"]) == occluded["amodal_area"] > occluded["area"]
    assert all(a["category_id"] != 1 for d in docs.values() for a in d["annotations"])  # stuff road not in COCO


def test_panopticapi_pq_of_gt_against_itself_is_100(tmp_path, class_map, dataset, monkeypatch):
    from panopticapi import evaluation  # installed by tools/setup.sh (see there)
    records, maps = dataset
    layout = Layout(tmp_path)
    for split in ("train", "val"):
        doc = coco_panoptic(records, class_map, split)
        json_path = layout.path(Layout.coco_panoptic(split))
        json_path.parent.mkdir(parents=True, exist_ok=True)
        json_path.write_text(json.dumps(doc))
        for ann in doc["annotations"]:
            cls, ins, _ = maps[ann["image_id"]]
            rgb, segments = panoptic(cls, ins, INSTANCES, class_map)
            png = layout.path(Layout.panoptic_png(split, ann["file_name"][:-4]))
            png.parent.mkdir(parents=True, exist_ok=True)
            write_color_png(png, rgb)  # the pipeline's writer (OpenImageIO), read back by panopticapi's PIL
            assert ann["segments_info"] == segments
        # One worker: panopticapi starts a pool of cpu_count() processes and never closes it.
        monkeypatch.setattr(multiprocessing, "cpu_count", lambda: 1)
        with contextlib.redirect_stdout(io.StringIO()):
            result = evaluation.pq_compute(str(json_path), str(json_path))
        assert result["All"]["pq"] == pytest.approx(1.0) and result["All"]["sq"] == pytest.approx(1.0)
        assert result["Things"]["n"] > 0 and result["Stuff"]["n"] == 3
    assert {c["id"]: c["isthing"] for c in doc["categories"]}[1] == 0
    assert [a["image_id"] for a in coco_panoptic(records, class_map, "train")["annotations"]] == [1, 2]


def test_every_annotation_has_num_keypoints_and_person_keypoints_is_the_person_part(class_map, dataset):
    """COCOeval(gt, dt, "keypoints") reads num_keypoints of every annotation of every category (KeyError
    before); COCO's person_keypoints file holds the person category and its annotations only."""
    from synthua_usd.dataset.formats.coco import person_keypoints
    from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES

    records, _ = dataset
    doc = coco_instances(records, class_map, "train")
    names = {c["id"]: c["name"] for c in doc["categories"]}
    assert all("num_keypoints" in a for a in doc["annotations"])
    assert all(a["num_keypoints"] == 0 and "keypoints" not in a for a in doc["annotations"]
               if names[a["category_id"]] not in KEYPOINT_CLASSES)
    people = person_keypoints(doc)
    assert [c["name"] for c in people["categories"]] == ["person"] and people["images"] == doc["images"]
    assert people["annotations"] == [a for a in doc["annotations"] if names[a["category_id"]] == "person"]
    assert people["annotations"]
