"""The boxes a detector trains on, from hand-written record instances and from a generated dataset's records,
checked against the dataset's COCO instances (pycocotools) and the union worked out by hand."""

from __future__ import annotations

import json

import pytest

from synthua_usd.analytics.detection_sets import Box
from synthua_usd.analytics.detection_targets import (DEFAULT_CLASSES, DetectionTargets, image_boxes, read_generated,
                                                     targets_for)
from synthua_usd.core.errors import InputError
from synthua_usd.model.box_conventions import CONVENTIONS, DEFAULT_CONVENTION

CHAIR = "/W/A/ManualWheelchair"
INSTANCES = [
    # a wheelchair user: person box (10, 5) 6x12, chair box (8, 10) 10x9 -> union (8, 5) 10x14
    {"class_name": "person", "prim_path": "/W/A/Person", "area": 40, "bbox": [10, 5, 6, 12],
     "relations": {"uses": CHAIR, "uses_class": "manual_wheelchair"}},
    {"class_name": "manual_wheelchair", "prim_path": CHAIR, "area": 30, "bbox": [8, 10, 10, 9], "relations": {}},
    # a pedestrian 3 px high (ignored below 8 px), a bench (not trained), a cane user whose cane is out of view
    {"class_name": "person", "prim_path": "/W/B/Person", "area": 3, "bbox": [30, 30, 1, 3], "relations": {}},
    {"class_name": "furniture", "prim_path": "/W/Bench", "area": 50, "bbox": [0, 0, 10, 5], "relations": {}},
    {"class_name": "person", "prim_path": "/W/C/Person", "area": 60, "bbox": [40, 2, 5, 15],
     "relations": {"uses": "/W/C/WoodenCane", "uses_class": "wooden_cane"}},
    {"class_name": "manual_wheelchair", "prim_path": "/W/D/Chair", "area": 0, "bbox": [0, 0, 0, 0], "relations": {}},
]


def test_default_wheelchair_box_covers_its_user():
    boxes = image_boxes(INSTANCES, DetectionTargets())
    assert boxes == (Box("person", 10, 5, 6, 12), Box("manual_wheelchair", 8, 5, 10, 14),
                     Box("person", 30, 30, 1, 3, ignore=True), Box("person", 40, 2, 5, 15))


def test_device_box_and_aid_users_not_persons():
    boxes = image_boxes(INSTANCES, DetectionTargets(aid_box="device", aid_users_as_person=False, min_height_px=0))
    # neither aid user is a person box (a wooden cane is a default class too, though out of view)
    assert boxes == (Box("manual_wheelchair", 8, 10, 10, 9), Box("person", 30, 30, 1, 3))
    only_chairs = DetectionTargets(classes=("person", "manual_wheelchair"), aid_users_as_person=False)
    assert [b.label for b in image_boxes(INSTANCES, only_chairs)] == ["manual_wheelchair", "person", "person"]


def test_the_wheelchair_sets_convention_boxes_the_seated_user_inside_the_chair():
    """As lexra/wheelchair's README draws them: the chair's box is the union worked out above, its user has no person
    box, and the cane user (on foot; canes are not among the convention's classes) stays a person."""
    targets = targets_for("wheelchair-sets")
    assert targets == DetectionTargets(("person", "manual_wheelchair", "electric_wheelchair"), "with_user", False)
    assert targets.convention == "wheelchair-sets"
    assert image_boxes(INSTANCES, targets) == (Box("manual_wheelchair", 8, 5, 10, 14),
                                               Box("person", 30, 30, 1, 3, ignore=True), Box("person", 40, 2, 5, 15))


def test_conventions_have_one_owner_and_refuse_contradicting_options():
    assert DEFAULT_CONVENTION in CONVENTIONS and targets_for() == DetectionTargets()
    assert DetectionTargets().convention == DEFAULT_CONVENTION
    assert targets_for(None, aid_users_as_person=False) == DetectionTargets(aid_users_as_person=False)
    assert targets_for(None, aid_users_as_person=False).convention is None
    assert targets_for("wheelchair-sets", aid_users_as_person=False, aid_box="with_user") == targets_for("wheelchair-sets")
    assert targets_for("wheelchair-sets", ("person", "manual_wheelchair")).classes == ("person", "manual_wheelchair")
    for options, found in (({"aid_users_as_person": True}, "--aid-users-as-person on: --convention wheelchair-sets "
                                                             "sets it off"),
                           ({"aid_box": "device"}, "--aid-box device: --convention wheelchair-sets sets it with_user")):
        with pytest.raises(InputError, match=found):
            targets_for("wheelchair-sets", **options)
    with pytest.raises(InputError, match="--convention: 'coco'; expected one of synthua, wheelchair-sets"):
        targets_for("coco")


def test_targets_refuse_bad_values():
    with pytest.raises(InputError, match="--aid-box"):
        DetectionTargets(aid_box="both")
    with pytest.raises(InputError, match="each once"):
        DetectionTargets(classes=("person", "person"))
    assert DetectionTargets.from_document(DetectionTargets().document()) == DetectionTargets()


def test_generated_dataset_boxes_against_its_coco_instances(generated_random):
    """Person boxes equal the COCO instances' boxes of the same images (read by pycocotools); a wheelchair's box
    contains its own COCO box and its user's."""
    from pycocotools.coco import COCO

    targets = DetectionTargets(min_height_px=0)
    s = read_generated(generated_random, "val", targets)
    assert s.layout == "synthua" and s.names == DEFAULT_CLASSES and s.images
    coco = COCO(str(generated_random / "annotations" / "instances_val.json"))
    by_file = {im["file_name"]: im["id"] for im in coco.dataset["images"]}
    unions = 0
    for image in s.images:
        anns = coco.loadAnns(coco.getAnnIds(imgIds=by_file[image.path.name]))
        names = {c["id"]: c["name"] for c in coco.dataset["categories"]}
        persons = sorted(tuple(a["bbox"]) for a in anns if names[a["category_id"]] == "person")
        assert sorted((b.x, b.y, b.w, b.h) for b in image.boxes if b.label == "person") == persons
        by_prim = {a["prim_path"]: a for a in anns}
        for a in anns:
            device = by_prim.get((a.get("relations") or {}).get("uses"))
            if names[a["category_id"]] == "person" and device is not None:
                (px, py, pw, ph), (dx, dy, dw, dh) = a["bbox"], device["bbox"]
                x0, y0 = min(px, dx), min(py, dy)
                union = (x0, y0, max(px + pw, dx + dw) - x0, max(py + ph, dy + dh) - y0)
                assert union in [(b.x, b.y, b.w, b.h) for b in image.boxes if b.label == names[device["category_id"]]]
                unions += 1
    assert unions > 0


def test_generated_dataset_refusals(generated_random):
    with pytest.raises(InputError, match="not thing classes"):
        read_generated(generated_random, "val", DetectionTargets(classes=("person", "road")))
    with pytest.raises(InputError, match="no images in split test"):
        read_generated(generated_random, "test", DetectionTargets())
    manifest = json.loads((generated_random / "manifest.json").read_text())
    assert any(e["split"] == "train" for e in manifest["images"])
