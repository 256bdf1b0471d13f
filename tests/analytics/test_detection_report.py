"""`evaluate-real`'s report files against the evaluation they are written from: every false positive in
false_positives.csv with what it lands on, the per-class counts in per_class.csv and the page, and both figures."""

from __future__ import annotations

import csv
import json

import numpy as np
from PIL import Image

from synthua_usd.analytics.class_mapping import build_mapping
from synthua_usd.analytics.detection_metrics import FP_KINDS, Detection, evaluate_detections
from synthua_usd.analytics.detection_report import REPORT_FILES, write_detection_report
from synthua_usd.analytics.detection_sets import Box, DetectionSet, SetImage

MODEL = ("person", "manual_wheelchair", "electric_wheelchair")
ABOUT = {"test_set": {"source": "hand-made", "layout": "yolo", "split": "test"}, "model": {"weights": "none"},
         "mapping_options": "--map wheelchair=manual_wheelchair"}


def _set(tmp_path, boxes_per_image) -> DetectionSet:
    images = []
    for i, boxes in enumerate(boxes_per_image, 1):
        path = tmp_path / f"photo{i}.png"
        Image.fromarray(np.full((100, 200, 3), 40 * i, np.uint8)).save(path)
        images.append(SetImage(i, path, 200, 100, tuple(boxes)))
    return DetectionSet(("wheelchair", "person"), tuple(images), "yolo", "hand-made", "test")


def _rows(path) -> list[dict]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def test_false_positives_written_as_evaluated(tmp_path):
    w, p = Box("wheelchair", 10, 10, 40, 40), Box("person", 100, 10, 20, 60)
    test = _set(tmp_path, [[w, p], [w]])
    dets = [Detection(1, "manual_wheelchair", 0.9, 10, 10, 40, 40), Detection(1, "manual_wheelchair", 0.7, 100, 10, 20, 60),
            Detection(2, "manual_wheelchair", 0.8, 150, 50, 30, 30), Detection(2, "manual_wheelchair", 0.6, 30, 10, 40, 40)]
    mapping = build_mapping(["wheelchair=manual_wheelchair"], test.names, MODEL)
    ev = evaluate_detections(test, dets, mapping)
    out = write_detection_report(tmp_path / "report", test, ev, dets, ABOUT)
    assert sorted(f.name for f in out.iterdir()) == sorted(REPORT_FILES)
    rows = _rows(out / "false_positives.csv")
    assert [(r["image"], r["class"], float(r["score"]), r["lands_on"], r["on_class"], float(r["iou"])) for r in rows] == [
        (str(tmp_path / "photo2.png"), "wheelchair", 0.8, "background", "", 0.0),
        (str(tmp_path / "photo1.png"), "wheelchair", 0.7, "other_class", "person", 1.0),
        (str(tmp_path / "photo2.png"), "wheelchair", 0.6, "localisation", "wheelchair", round(800 / 2400, 4))]
    (row,) = [r for r in _rows(out / "per_class.csv") if r["class"] == "wheelchair"]
    assert [int(row[f"fp_{k}"]) for k in FP_KINDS] == [1, 1, 0, 1, 0] and int(row["fp"]) == 3
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["false_positives"] == 3
    assert next(c for c in metrics["classes"] if c["class"] == "wheelchair")["fp_on"] == {"person": 1}
    page = (out / "report.html").read_text()
    assert "<td>wheelchair</td><td>3</td><td>1</td><td>1</td><td>0</td><td>1</td><td>0</td><td>person 1</td>" in page
    assert 'src="false_positives.png"' in page and 'href="false_positives.csv"' in page
    assert Image.open(out / "false_positives.png").size[0] > 500


def test_a_dollar_in_a_file_name_is_shown_as_itself(tmp_path):
    """matplotlib reads `$...$` in a title as mathtext: `cost$_$x.png` failed the whole report."""
    w = Box("wheelchair", 10, 10, 40, 40)
    test = _set(tmp_path, [[w]])
    odd = tmp_path / "cost$_$x.png"
    test.images[0].path.rename(odd)
    test = DetectionSet(test.names, (SetImage(1, odd, 200, 100, (w,)),), "yolo", "hand-made", "test")
    dets = [Detection(1, "manual_wheelchair", 0.9, 120, 10, 40, 40)]     # a miss and a false positive
    ev = evaluate_detections(test, dets, build_mapping(["wheelchair=manual_wheelchair"], test.names, MODEL))
    out = write_detection_report(tmp_path / "report", test, ev, dets, ABOUT)
    assert _rows(out / "false_positives.csv")[0]["image"] == str(odd)
    assert Image.open(out / "false_negatives.png").size[0] > 500


def test_no_false_positives_still_writes_both_files(tmp_path):
    w = Box("wheelchair", 10, 10, 40, 40)
    test = _set(tmp_path, [[w]])
    dets = [Detection(1, "manual_wheelchair", 0.9, 10, 10, 40, 40)]
    ev = evaluate_detections(test, dets, build_mapping(["wheelchair=manual_wheelchair"], test.names, MODEL))
    out = write_detection_report(tmp_path / "report", test, ev, dets, ABOUT)
    assert ev.false_positives == () and len(_rows(out / "false_positives.csv")) == 0
    assert (out / "false_positives.csv").read_text().startswith("image,class,score,")
    assert Image.open(out / "false_positives.png").size[0] > 500
