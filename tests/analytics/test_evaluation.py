"""``synthua eval`` on the hand-made dataset: metrics worked out by hand, class-id and colour predictions,
COCO results through pycocotools, and one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from analytics import tiny_dataset
from analytics.tiny_dataset import BUILDING, NAMES, PERSON, ROAD, WALKER, WHEELCHAIR

SIDEWALK, CAR = 3, 19


@pytest.fixture()
def dataset(tmp_path) -> Path:
    return tiny_dataset.write(tmp_path / "ds")


def predictions() -> list[np.ndarray]:
    """Image 1: the wheelchair taken for the person, 2 road pixels for sidewalk; image 2: right, and a car in
    the unlabelled pixels (void: not evaluated)."""
    (c1, _), (c2, _), _ = tiny_dataset.label_maps()
    p1, p2 = c1.copy(), c2.copy()
    p1[c1 == WHEELCHAIR] = PERSON
    p1[4, 0:2] = SIDEWALK
    p2[c2 == 0] = CAR
    return [p1, p2]


def write_predictions(folder: Path, colour: bool = False, palette=None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name, pred in zip(NAMES[:2], predictions()):
        Image.fromarray(palette[pred] if colour else pred).save(folder / f"{name}.png")
    return folder


EXPECTED = {  # class: (IoU, precision, recall, F1, accuracy) over the 53 evaluated pixels
    ROAD: (22 / 24, 1.0, 22 / 24, 44 / 46, 51 / 53),
    BUILDING: (1.0, 1.0, 1.0, 1.0, 1.0),
    PERSON: (2 / 5, 2 / 5, 1.0, 4 / 7, 50 / 53),
    WHEELCHAIR: (0.0, None, 0.0, 0.0, 50 / 53),
    WALKER: (1.0, 1.0, 1.0, 1.0, 1.0),
    SIDEWALK: (0.0, 0.0, None, 0.0, 51 / 53),
}


def check_metrics(document: dict) -> None:
    rows = {r["id"]: r for r in document["classes"]}
    for cid, values in EXPECTED.items():
        r = rows[cid]
        got = (r["iou"], r["precision"], r["recall"], r["f1"], r["accuracy"])
        for g, e in zip(got, values):
            assert g == (None if e is None else pytest.approx(e)), (cid, got, values)
    assert rows[CAR]["pred_pixels"] == 0                  # predicted only on void pixels
    s = document["summary"]
    assert s["pixels"] == 53 and s["pixel_accuracy"] == pytest.approx(48 / 53)
    assert s["mean_iou"] == pytest.approx((22 / 24 + 1 + 0.4 + 0 + 1 + 0) / 6) and s["mean_iou_classes"] == 6
    assert s["frequency_weighted_iou"] == pytest.approx((24 * 22 / 24 + 22 + 2 * 0.4 + 2) / 53)


@pytest.mark.parametrize("colour", [False, True], ids=["class-ids", "colours"])
def test_metrics_by_hand(run_cli, dataset, tmp_path, class_map, colour):
    pred = write_predictions(tmp_path / "pred", colour, class_map.palette())
    code, out, err = run_cli("eval", "--gt", dataset, "--pred", pred, "--out", tmp_path / "eval")
    assert code == 0, err
    assert "2 images, 53 pixels evaluated: pixel accuracy 0.9057" in out
    document = json.loads((tmp_path / "eval" / "metrics.json").read_text())
    check_metrics(document)
    confusion = (tmp_path / "eval" / "confusion.csv").read_text().splitlines()
    header = confusion[0].split(",")
    road_row = next(line.split(",") for line in confusion if line.startswith("road,"))
    assert road_row[header.index("road")] == "22" and road_row[header.index("sidewalk")] == "2"
    assert (tmp_path / "eval" / "confusion.png").stat().st_size > 1000
    assert "manual_wheelchair" in (tmp_path / "eval" / "metrics.csv").read_text()


def test_split_option_evaluates_one_split(run_cli, dataset, tmp_path):
    pred = write_predictions(tmp_path / "pred")
    code, out, _ = run_cli("eval", "--gt", dataset, "--pred", pred, "--out", tmp_path / "e", "--split", "val")
    assert code == 0 and "1 images, 20 pixels evaluated: pixel accuracy 1.0000" in out


def one_error(err: str) -> str:
    lines = [line for line in err.splitlines() if line.startswith("synthua: error:")]
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_errors_are_one_line(run_cli, dataset, tmp_path, class_map):
    pred = write_predictions(tmp_path / "pred")
    out = tmp_path / "eval"
    Image.fromarray(np.zeros((3, 4), np.uint8)).save(pred / f"{NAMES[1]}.png")
    code, _, err = run_cli("eval", "--gt", dataset, "--pred", pred, "--out", out)
    assert code == 2 and "4x3 pixels; expected 8x6, the size of its ground truth" in one_error(err)

    bad = predictions()[1]
    colour = class_map.palette()[bad]
    colour[2, 5] = (1, 2, 3)
    Image.fromarray(colour).save(pred / f"{NAMES[1]}.png")
    code, _, err = run_cli("eval", "--gt", dataset, "--pred", pred, "--out", out)
    assert code == 2 and "colour (1, 2, 3) at pixel (x=5, y=2) is not a class colour" in one_error(err)

    ids = bad.copy()
    ids[1, 7] = 200
    Image.fromarray(ids).save(pred / f"{NAMES[1]}.png")
    code, _, err = run_cli("eval", "--gt", dataset, "--pred", pred, "--out", out)
    assert code == 2 and "class id 200 at pixel (x=7, y=1) is not in the class map" in one_error(err)

    (pred / f"{NAMES[1]}.png").unlink()
    code, _, err = run_cli("eval", "--gt", dataset, "--pred", pred, "--out", out)
    line = one_error(err)
    assert code == 2 and f"{NAMES[1]}.png: file not found; expected a prediction for each of the 2 images" in line
    code, _, err = run_cli("eval", "--gt", tmp_path / "nowhere", "--pred", pred, "--out", out)
    assert code == 2 and "not a folder; expected a dataset folder" in one_error(err)
    assert not out.exists()


def coco_results(dataset: Path, drop_class: int | None = None) -> list[dict]:
    results = []
    for split in ("train", "val"):
        for a in json.loads((dataset / "annotations" / f"instances_{split}.json").read_text())["annotations"]:
            if a["category_id"] != drop_class:
                results.append({"image_id": a["image_id"], "category_id": a["category_id"], "score": 0.9,
                                "segmentation": a["segmentation"], "bbox": a["bbox"]})
    return results


def test_coco_results_give_map_through_pycocotools(run_cli, dataset, tmp_path):
    path = tmp_path / "results.json"
    path.write_text(json.dumps(coco_results(dataset)))
    code, out, err = run_cli("eval", "--gt", dataset, "--pred", path, "--out", tmp_path / "e")
    assert code == 0, err
    assert "segm: mAP 1.0000" in out and "bbox: mAP 1.0000" in out
    coco = json.loads((tmp_path / "e" / "coco.json").read_text())
    assert coco["iou_types"]["segm"]["ap_per_class"]["manual_wheelchair"] == pytest.approx(1.0)
    path.write_text(json.dumps(coco_results(dataset, drop_class=WHEELCHAIR)))
    code, out, _ = run_cli("eval", "--gt", dataset, "--pred", path, "--out", tmp_path / "e2")
    coco = json.loads((tmp_path / "e2" / "coco.json").read_text())
    assert coco["iou_types"]["segm"]["ap_per_class"]["manual_wheelchair"] == 0.0
    assert coco["iou_types"]["segm"]["ap_per_class"]["building"] == pytest.approx(1.0)
    # four classes with ground truth (building, person, wheelchair, walker), one missed entirely
    assert coco["iou_types"]["segm"]["stats"]["AP"] == pytest.approx(0.75)


def test_coco_results_naming_another_image_are_refused(run_cli, dataset, tmp_path):
    path = tmp_path / "results.json"
    path.write_text(json.dumps([{"image_id": 3, "category_id": ROAD, "score": 1.0, "bbox": [0, 0, 1, 1]}]))
    code, _, err = run_cli("eval", "--gt", dataset, "--pred", path, "--out", tmp_path / "e")
    assert code == 2 and "[0].image_id: 3 is not an image of the evaluated ground truth" in one_error(err)


@pytest.mark.parametrize("field, value, expected", [
    ("score", "high", "[0].score: 'high'; expected a finite number"),
    ("bbox", [0, 0, -1, 2], "[0].bbox: [0, 0, -1, 2]; expected [x, y, width, height]"),
    ("segmentation", {"size": [2, 2], "counts": "0"}, "[0].segmentation: "),
])
def test_malformed_detections_are_refused(run_cli, dataset, tmp_path, field, value, expected):
    detection = coco_results(dataset)[0] | {field: value}
    path = tmp_path / "results.json"
    path.write_text(json.dumps([detection]))
    code, _, err = run_cli("eval", "--gt", dataset, "--pred", path, "--out", tmp_path / "e")
    line = one_error(err)
    assert code == 2 and expected in line, line


@pytest.mark.parametrize("counts, expected", [
    ("!!not rle!!", "counts[0] is '!'"),
    ("o", "the last character continues"),
    ("5", "runs of 5 pixels in all"),
    ("PPYo0", "runs of 1025024 pixels in all"),  # pycocotools would write past the mask
    ("0@", "a negative run"),
])
def test_garbage_rle_counts_are_refused_before_pycocotools_reads_them(run_cli, dataset, tmp_path, counts, expected):
    detection = coco_results(dataset)[0]
    detection["segmentation"] = {"size": detection["segmentation"]["size"], "counts": counts}
    path = tmp_path / "results.json"
    path.write_text(json.dumps([detection]))
    code, _, err = run_cli("eval", "--gt", dataset, "--pred", path, "--out", tmp_path / "e")
    line = one_error(err)
    assert code == 2 and "[0].segmentation: " in line and expected in line, line
    assert not (tmp_path / "e").exists()
