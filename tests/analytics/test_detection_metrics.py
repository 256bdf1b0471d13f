"""Detection scores from pycocotools checked against values worked out by hand and against an independent greedy
matcher written here in numpy (precision and recall at a fixed confidence on random boxes, and what each false
positive lands on)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from synthua_usd.analytics.class_mapping import build_mapping
from synthua_usd.analytics.detection_metrics import FP_KINDS, Detection, evaluate_detections, merge_detections
from synthua_usd.analytics.detection_sets import Box, DetectionSet, SetImage

MODEL = ("person", "manual_wheelchair", "electric_wheelchair")


def one_set(boxes_per_image: list[list[Box]], names=("person", "wheelchair"), size=(200, 100)) -> DetectionSet:
    images = tuple(SetImage(i, Path(f"/nowhere/{i}.png"), size[0], size[1], tuple(b)) for i, b in
                   enumerate(boxes_per_image, 1))
    return DetectionSet(tuple(names), images, "yolo", "hand-made", "test")


def test_perfect_detections_score_one():
    gt = [[Box("person", 10, 10, 20, 40), Box("wheelchair", 50, 20, 30, 30)], [Box("person", 100, 5, 10, 30)]]
    dets = [Detection(i, "person" if b.label == "person" else "manual_wheelchair", 0.9, b.x, b.y, b.w, b.h)
            for i, boxes in enumerate(gt, 1) for b in boxes]
    ev = evaluate_detections(one_set(gt), dets, build_mapping([], ("person", "wheelchair"), MODEL))
    for c in ev.classes:
        assert (c.ap50, c.ap50_95, c.precision, c.recall) == pytest.approx((1.0, 1.0, 1.0, 1.0))
    assert ev.misses == () and ev.stats["AP"] == pytest.approx(1.0)


def test_ap_worked_out_by_hand():
    """Two people; a false positive above a true positive, the other person missed. Precision after each
    detection: 0 (recall 0), 1/2 (recall 1/2). COCO's 101 recall points: the 51 at recall <= 0.5 take the best
    precision at or beyond them, 1/2; the other 50 nothing: AP = 51 * 0.5 / 101, at every IoU (the hit is exact)."""
    gt = [[Box("person", 10, 10, 20, 40), Box("person", 120, 10, 20, 40)]]
    dets = [Detection(1, "person", 0.9, 60, 50, 10, 10), Detection(1, "person", 0.8, 10, 10, 20, 40)]
    ev = evaluate_detections(one_set(gt, names=("person",)), dets, build_mapping([], ("person",), MODEL), 0.5)
    (person,) = ev.classes
    assert person.ap50 == pytest.approx(51 * 0.5 / 101) and person.ap50_95 == pytest.approx(51 * 0.5 / 101)
    assert (person.tp, person.fp, person.fn) == (1, 1, 1)
    assert (person.precision, person.recall) == (0.5, 0.5)
    high = evaluate_detections(one_set(gt, names=("person",)), dets, build_mapping([], ("person",), MODEL), 0.85)
    assert (high.classes[0].tp, high.classes[0].fp, high.classes[0].fn) == (0, 1, 2)
    # the misses, largest first (equal sizes: by image, then x); the one at x = 120 has no overlapping detection
    assert [(m.box.x, m.best_iou) for m in ev.misses] == [(120, 0.0)]
    assert [m.box.x for m in high.misses] == [10, 120] and high.misses[0].best_iou == pytest.approx(1.0)
    assert high.misses[0].best_score == pytest.approx(0.8) and high.misses[0].best_box == (10, 10, 20, 40)
    assert ev.misses[0].best_box is None


def test_class_without_boxes_has_no_ap_and_ignored_boxes_cost_nothing():
    gt = [[Box("person", 10, 10, 20, 40), Box("person", 100, 10, 4, 4, ignore=True)]]
    dets = [Detection(1, "person", 0.9, 10, 10, 20, 40), Detection(1, "person", 0.8, 100, 10, 4, 4)]
    ev = evaluate_detections(one_set(gt), dets, build_mapping([], ("person", "wheelchair"), MODEL))
    person, wheelchair = ev.classes
    assert (person.tp, person.fp, person.fn, person.boxes) == (1, 0, 0, 1) and person.ap50 == pytest.approx(1.0)
    assert (wheelchair.ap50, wheelchair.ap50_95, wheelchair.boxes, wheelchair.precision) == (None, None, 0, None)


def test_regions_and_unmapped_boxes_cost_nothing_when_asked():
    """`evaluate-real --boxes`: an image's regions are crowd regions of every scored class, and so, when asked, are
    its boxes of classes no mapping scores; worked out by hand: one hit, then one detection on a region and one on
    an unmapped cane, each a false positive unless it lies on an ignored region."""
    hit, region, cane = Box("wheelchair", 10, 10, 20, 40), Box("person", 100, 10, 20, 40), Box("cane", 150, 10, 20, 40)
    dets = [Detection(1, "manual_wheelchair", score, b.x, b.y, b.w, b.h) for score, b in
            ((0.9, hit), (0.8, region), (0.7, cane))]
    mapping = build_mapping(["wheelchair=manual_wheelchair"], ("wheelchair", "cane"), MODEL)
    plain = one_set([[hit, cane]], names=("wheelchair", "cane"))
    with_region = DetectionSet(plain.names, (SetImage(1, plain.images[0].path, 200, 100, (hit, cane), (region,)),),
                               "synthua", "hand-made", "test")
    for test, unmapped, fp in ((plain, False, 2), (with_region, False, 1), (with_region, True, 0)):
        (wheelchair,) = evaluate_detections(test, dets, mapping, unmapped_as_regions=unmapped).classes
        assert (wheelchair.tp, wheelchair.fp, wheelchair.fn, wheelchair.boxes) == (1, fp, 0, 1)
        assert wheelchair.ap50 == pytest.approx(1.0)      # the hit ranks first: precision 1 at every recall


def test_merged_model_classes_count_once():
    """A chair both wheelchair classes predicted is one detection of 'wheelchair', not a true and a false one."""
    gt = [[Box("wheelchair", 50, 20, 30, 30)]]
    dets = [Detection(1, "manual_wheelchair", 0.9, 50, 20, 30, 30), Detection(1, "electric_wheelchair", 0.6, 51, 20, 30, 30),
            Detection(1, "electric_wheelchair", 0.7, 150, 20, 30, 30)]
    mapping = build_mapping([], ("wheelchair",), MODEL)
    merged = merge_detections(dets, mapping, 0.7)
    assert [(d.label, d.score) for d in merged] == [("wheelchair", 0.9), ("wheelchair", 0.7)]
    (c,) = evaluate_detections(one_set(gt, names=("wheelchair",)), dets, mapping).classes
    assert (c.tp, c.fp, c.fn) == (1, 1, 0)


def _iou(a, b) -> float:
    ax1, ay1, bx1, by1 = a[0] + a[2], a[1] + a[3], b[0] + b[2], b[1] + b[3]
    w, h = max(0.0, min(ax1, bx1) - max(a[0], b[0])), max(0.0, min(ay1, by1) - max(a[1], b[1]))
    inter = w * h
    return inter / (a[2] * a[3] + b[2] * b[3] - inter)


def greedy_counts(gt_boxes, dets, confidence, label="person"):
    """TP, FP, FN at IoU 0.5 of class ``label`` over images, and the false positives with what each lands on:
    detections above ``confidence`` by falling score, each to the unmatched box of its class it overlaps most
    (COCO's rule); a false positive then by its best IoU with its class's boxes and the others' (TIDE's order)."""
    tp = fp = fn = 0
    lands = {}
    for image_id, every in gt_boxes.items():
        boxes = [b for b in every if b.label == label]
        others = [b for b in every if b.label != label]
        taken = [False] * len(boxes)
        for d in sorted((d for d in dets if d.image_id == image_id and d.score >= confidence), key=lambda d: -d.score):
            ious = [(-1.0 if taken[k] else _iou((d.x, d.y, d.w, d.h), (b.x, b.y, b.w, b.h))) for k, b in enumerate(boxes)]
            best = int(np.argmax(ious)) if ious else -1
            if best >= 0 and ious[best] >= 0.5:
                taken[best] = True
                tp += 1
                continue
            fp += 1
            own = max([_iou((d.x, d.y, d.w, d.h), (b.x, b.y, b.w, b.h)) for b in boxes], default=0.0)
            other = max([_iou((d.x, d.y, d.w, d.h), (b.x, b.y, b.w, b.h)) for b in others], default=0.0)
            lands[d] = ("localisation" if 0.1 <= own <= 0.5 else "other_class" if other >= 0.5 else "duplicate"
                        if own >= 0.5 else "background" if max(own, other) <= 0.1 else "near_other_class")
        fn += taken.count(False)
    return tp, fp, fn, lands


def test_precision_recall_against_an_independent_matcher():
    rng = np.random.default_rng(3)
    gt, dets = [], []
    for image_id in range(1, 21):
        boxes = []
        for _ in range(rng.integers(0, 6)):
            x, y, w, h = rng.uniform(0, 150), rng.uniform(0, 60), rng.uniform(5, 40), rng.uniform(5, 40)
            boxes.append(Box(str(rng.choice(["person", "person", "cane"])), x, y, w, h))
            for _ in range(rng.integers(0, 4)):    # jittered detections: some match, some not
                j = rng.normal(0, rng.choice([0.1, 0.3]), 4) * [w, h, w, h]
                dets.append(Detection(image_id, "person", float(rng.uniform()), x + j[0], y + j[1],
                                      max(1.0, w + j[2]), max(1.0, h + j[3])))
        for _ in range(rng.integers(0, 3)):        # stray detections
            dets.append(Detection(image_id, "person", float(rng.uniform()), *rng.uniform(0, 100, 2), 10.0, 10.0))
        gt.append(boxes)
    mapping = build_mapping([], ("person", "cane"), MODEL)
    test = one_set(gt, names=("person", "cane"))
    gt_by_image = {im.id: list(im.boxes) for im in test.images}
    for confidence in (0.1, 0.25, 0.5, 0.8):
        ev = evaluate_detections(test, dets, mapping, confidence)
        (c,) = ev.classes
        tp, fp, fn, lands = greedy_counts(gt_by_image, dets, confidence)
        assert (c.tp, c.fp, c.fn) == (tp, fp, fn)
        assert len(ev.misses) == c.fn
        assert {f.detection: f.kind for f in ev.false_positives} == lands
        assert c.fp_kinds == {k: list(lands.values()).count(k) for k in FP_KINDS}
        assert sum(c.fp_on.values()) == c.fp_kinds["other_class"] + c.fp_kinds["near_other_class"]
        assert [f.detection.score for f in ev.false_positives] == sorted((d.score for d in lands), reverse=True)
    assert {"duplicate", "other_class", "localisation", "near_other_class", "background"} <= {
        f.kind for f in evaluate_detections(test, dets, mapping, 0.1).false_positives}


def test_false_positives_by_what_they_land_on_worked_out_by_hand():
    """A wheelchair box W (10, 10, 40, 40), a person's P (100, 10, 20, 60) and a cane's C (150, 10, 30, 30);
    wheelchair detections by falling score: W itself (the hit), W moved 2 px (IoU 1520 / 1680 with W: a duplicate),
    P itself (on another class's box), W moved 20 px (IoU 800 / 2400: badly placed), P moved 10 px (IoU 600 / 1800:
    near another class's box), C itself, one on nothing, and one under the confidence."""
    w, p, c = Box("wheelchair", 10, 10, 40, 40), Box("person", 100, 10, 20, 60), Box("cane", 150, 10, 30, 30)
    dets = [Detection(1, "manual_wheelchair", score, *box) for score, box in (
        (0.9, (10, 10, 40, 40)), (0.8, (12, 10, 40, 40)), (0.7, (100, 10, 20, 60)), (0.6, (30, 10, 40, 40)),
        (0.5, (110, 10, 20, 60)), (0.45, (150, 10, 30, 30)), (0.4, (60, 70, 20, 20)), (0.1, (160, 70, 10, 10)))]
    mapping = build_mapping(["wheelchair=manual_wheelchair"], ("wheelchair", "person", "cane"), MODEL)
    ev = evaluate_detections(one_set([[w, p, c]], names=("wheelchair", "person", "cane")), dets, mapping)
    wheelchair = next(k for k in ev.classes if k.name == "wheelchair")
    assert (wheelchair.tp, wheelchair.fp, wheelchair.fn) == (1, 6, 0)
    assert [(f.detection.score, f.kind, f.on and f.on.label) for f in ev.false_positives] == [
        (0.8, "duplicate", "wheelchair"), (0.7, "other_class", "person"), (0.6, "localisation", "wheelchair"),
        (0.5, "near_other_class", "person"), (0.45, "other_class", "cane"), (0.4, "background", None)]
    assert [f.iou for f in ev.false_positives] == pytest.approx([1520 / 1680, 1, 1 / 3, 1 / 3, 1, 0])
    assert wheelchair.fp_kinds == {"duplicate": 1, "other_class": 2, "localisation": 1, "near_other_class": 1,
                                   "background": 1}
    assert wheelchair.fp_on == {"cane": 1, "person": 2}
    row = wheelchair.row()
    assert [row[f"fp_{k}"] for k in FP_KINDS] == [1, 2, 1, 1, 1]


def test_false_positives_in_tides_order_at_its_edges_and_on_regions():
    """TIDE's order where boxes overlap: a seated user's person box P inside a wheelchair's W (the synthua
    convention). A person detection takes P; a wheelchair detection on P (IoU 2500 / 5100 with W: 0.1 to 0.5) is
    badly placed, not on another class's box; one on P's twin P2 inside W2 at IoU 0.5 or more with both is on another
    class's box, not a duplicate. At the edges: IoU exactly 0.5 with a taken box of its class is badly placed, exactly
    0.1 with another label's is nothing labelled. An ignored box of its class and a crowd region count as boxes."""
    w, p = Box("wheelchair", 100, 50, 60, 60), Box("person", 105, 20, 50, 80)
    w2, p2 = Box("wheelchair", 300, 0, 100, 100), Box("person", 300, 0, 100, 80)
    ignored, region = Box("wheelchair", 0, 150, 40, 40, ignore=True), Box("person", 500, 150, 30, 60)
    hit = Box("wheelchair", 0, 300, 100, 100)
    model = [(0.95, "person", (105, 20, 50, 80)), (0.9, "manual_wheelchair", (105, 20, 50, 80)),
             (0.92, "manual_wheelchair", (300, 0, 100, 100)), (0.85, "manual_wheelchair", (300, 0, 100, 90)),
             (0.97, "manual_wheelchair", (0, 300, 100, 100)), (0.8, "manual_wheelchair", (0, 300, 100, 50)),
             (0.75, "manual_wheelchair", (0, 130, 50, 40)), (0.7, "manual_wheelchair", (490, 140, 50, 120)),
             (0.65, "manual_wheelchair", (600, 150, 20, 20)), (0.6, "manual_wheelchair", (620, 150, 100, 100))]
    dets = [Detection(1, label, score, *box) for score, label, box in model]
    far = Box("person", 620, 150, 10, 100)               # IoU with the last detection: 1000 / 10000 = 0.1
    test = DetectionSet(("wheelchair", "person"), (SetImage(1, Path("/nowhere/1.png"), 800, 500,
                                                            (w, p, w2, p2, ignored, hit, far), (region,)),),
                        "synthua", "hand-made", "test")
    mapping = build_mapping(["wheelchair=manual_wheelchair", "person=person"], test.names, MODEL)
    ev = evaluate_detections(test, dets, mapping)
    got = {f.detection.score: (f.kind, f.on and f.on.label, round(f.iou, 4)) for f in ev.false_positives}
    assert got == {
        0.9: ("localisation", "wheelchair", round(2500 / 5100, 4)),
        0.85: ("other_class", "person", round(8000 / 9000, 4)),       # and 0.9 with the taken W2: not a duplicate
        0.8: ("localisation", "wheelchair", 0.5),                     # exactly 0.5 with the taken hit
        0.75: ("localisation", "wheelchair", round(800 / 2800, 4)),   # the ignored box: 40 x 20 of 50 x 40 + 40 x 40
        0.7: ("near_other_class", "person", round(1800 / 6000, 4)),   # the region
        0.65: ("background", None, 0.0),
        0.6: ("background", None, 0.1)}
