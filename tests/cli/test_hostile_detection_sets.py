"""Hostile test and training sets for ``synthua evaluate-real`` and ``synthua train``: a set is read whole or refused
with one line naming the file, before the detector runs (``--python`` names no interpreter here: a case that got as
far as the detector would fail differently). Sets are written by hand: 40x30 images (PIL), a YOLO folder and a COCO
file beside them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

W, H = 40, 30
NO_DETECTOR = ("--python", "/nonexistent/detector-python")


def _image(path: Path, width: int = W, height: int = H) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    pixels = np.random.default_rng(len(path.name)).integers(0, 255, (height, width, 3), np.uint8)
    Image.fromarray(pixels).save(path, quality=90) if path.suffix == ".jpg" else Image.fromarray(pixels).save(path)
    return path


def _truncated(path: Path) -> Path:
    data = _image(path).read_bytes()
    path.write_bytes(data[: len(data) * 2 // 3])   # the header reads; the last rows are missing
    return path


def _run(folder: Path) -> Path:
    """A run folder of `synthua train` (weights a stand-in: every refusal here comes before the detector)."""
    folder.mkdir()
    (folder / "weights.pt").write_bytes(b"weights")
    (folder / "train.json").write_text(json.dumps({"classes": ["person", "manual_wheelchair"],
                                                   "budget": {"imgsz": 320}, "targets": None}))
    return folder


def _coco(folder: Path, **spoil) -> Path:
    """photos/instances.json: two images a.jpg, b.jpg, a box on each; ``spoil`` replaces images[0] or
    annotations[0] fields (``image_width=0``, ``annotation_bbox=[...]``)."""
    _image(folder / "a.jpg")
    _image(folder / "b.jpg")
    doc = {"images": [{"id": 1, "file_name": "a.jpg", "width": W, "height": H},
                      {"id": 2, "file_name": "b.jpg", "width": W, "height": H}],
           "annotations": [{"id": 1, "image_id": 1, "category_id": 1, "bbox": [4, 4, 10, 12], "area": 120,
                            "iscrowd": 0},
                           {"id": 2, "image_id": 2, "category_id": 2, "bbox": [20, 10, 12, 16], "area": 192,
                            "iscrowd": 0}],
           "categories": [{"id": 1, "name": "person"}, {"id": 2, "name": "wheelchair"}]}
    for key, value in spoil.items():
        part, field = key.split("_", 1)
        doc[f"{part}s"][0][field] = value
    path = folder / "instances.json"
    path.write_text(json.dumps(doc))
    return path


def _yolo(root: Path, splits=("test",)) -> Path:
    for split in splits:
        for name in ("a.jpg", "b.png"):
            _image(root / "images" / split / name)
        (root / "labels" / split).mkdir(parents=True)
        (root / "labels" / split / "a.txt").write_text("0 0.25 0.3 0.2 0.3\n1 0.6 0.5 0.3 0.5\n")
        (root / "labels" / split / "b.txt").write_text("1 0.5 0.5 0.4 0.6\n")
    (root / "data.yaml").write_text("path: .\n" + "".join(f"{s}: images/{s}\n" for s in splits) +
                                    "names: [person, wheelchair]\n")
    return root


def _evaluate(refuse, workdir, test_set, *extra, mentions):
    return refuse("evaluate-real", _run(workdir / "run"), test_set, *extra, *NO_DETECTOR, "--out",
                  workdir / "report", mentions=mentions)


# --- COCO: annotations, sizes, names ------------------------------------------------------------------------------

@pytest.mark.parametrize("spoil, mentions", [
    # every box on an image the file does not hold: 0 boxes were scored
    ({"annotation_image_id": 99}, ("annotations[0].image_id", "99")),
    ({"image_width": 0}, ("images[0].width", "0")),
    ({"image_height": -3}, ("images[0].height",)),
    # 10000x10000 claimed for a 40x30 file
    ({"image_width": 10_000, "image_height": 10_000}, ("a.jpg", "40x30", "10000x10000")),
    ({"image_file_name": "../../etc/passwd"}, ("images[0].file_name", "../../etc/passwd", "leaves the images folder")),
    ({"image_file_name": "/etc/passwd"}, ("images[0].file_name", "/etc/passwd")),
    # a box far outside its image: ValueError in analytics/plots.py once the detector had run
    ({"annotation_bbox": [5000, 5000, 10, 10]}, ("annotations[0].bbox", "inside its image", "40x30")),
    ({"annotation_bbox": [-20, 0, 10, 10]}, ("annotations[0].bbox",)),
])
def test_evaluate_real_refuses_a_coco_set_it_cannot_read_whole(refuse, workdir, spoil, mentions):
    coco = _coco(workdir / "photos", **spoil)
    _evaluate(refuse, workdir, coco, mentions=("instances.json", *mentions))


def test_a_box_at_the_edge_is_clipped_not_refused(tmp_path):
    from synthua_usd.analytics.detection_sets import read_coco

    coco = _coco(tmp_path / "photos", annotation_bbox=[30.5, 20.5, 10, 10])  # 0.5 px past the corner: rounding
    box = read_coco(coco).images[0].boxes[0]
    assert (box.x, box.y, box.w, box.h) == (30.5, 20.5, 9.5, 9.5)


# --- broken images --------------------------------------------------------------------------------------------------

BROKEN = ["truncated jpeg", "truncated png", "heic", "heic named .jpg", "text named .png"]


@pytest.mark.parametrize("layout, broken", [("coco", b) for b in BROKEN] +
                         [("yolo", "truncated jpeg"), ("yolo", "truncated png")])
def test_a_broken_image_is_refused_by_name_before_the_detector(refuse, workdir, layout, broken):
    """They failed inside the detector with a message that named no image (one: "No module named 'pi_heif'"); a
    truncated JPEG decodes with grey rows and only a warning. (A YOLO folder's header check already refused the
    others.)"""
    root = workdir / "photos"
    name = {"truncated jpeg": "a.jpg", "truncated png": "b.png", "heic": "c.heic", "heic named .jpg": "a.jpg",
            "text named .png": "b.png"}[broken]
    if layout == "coco":
        test_set = _coco(root, image_file_name=name)
        image = root / name
    else:
        test_set = _yolo(root)
        image = root / "images" / "test" / name
    if broken.startswith("truncated"):
        _truncated(image)
    elif broken.startswith("heic"):
        image.write_bytes(b"\0\0\0\x18ftypheic\0\0\0\0mif1heic" + bytes(200))
    else:
        image.write_text("not an image")
    _evaluate(refuse, workdir, test_set, mentions=(name,))


# --- YOLO ------------------------------------------------------------------------------------------------------------

def test_a_yolo_label_path_that_is_a_folder_is_refused(refuse, workdir):
    """Its boxes were dropped: the image was scored as one without objects."""
    root = _yolo(workdir / "photos")
    (root / "labels" / "test" / "a.txt").unlink()
    (root / "labels" / "test" / "a.txt").mkdir()
    _evaluate(refuse, workdir, root, mentions=("a.txt", "folder"))


# --- train ------------------------------------------------------------------------------------------------------------

def test_train_refuses_an_image_of_width_zero(refuse, workdir):
    """ZeroDivisionError in pipeline/detector/yolo_data.py."""
    coco = _coco(workdir / "photos", image_width=0)
    refuse("train", coco, "--epochs", "1", *NO_DETECTOR, "--out", workdir / "o", mentions=("images[0].width",))


def test_train_refuses_a_class_out_of_range_in_the_val_split(refuse, workdir):
    """The same line in the train split was refused; in the val split it was a warning, and training went on."""
    root = _yolo(workdir / "set", splits=("train", "val"))
    (root / "labels" / "val" / "b.txt").write_text("7 0.5 0.5 0.4 0.6\n")
    refuse("train", root, "--epochs", "1", *NO_DETECTOR, "--out", workdir / "o",
           mentions=(str(Path("labels") / "val" / "b.txt"), "class index 7"))


def test_train_without_a_val_split_still_validates_on_train(tmp_path):
    """Only a missing split falls back to the train split (what the val refusal above must not become)."""
    from synthua_usd.pipeline.train import TrainRequest, _splits

    root = _yolo(tmp_path / "set", splits=("train",))
    splits, train = _splits(TrainRequest(root, tmp_path / "o"))
    assert splits["val"] is train and len(train.images) == 2
