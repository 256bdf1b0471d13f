"""Detection sets read from Ultralytics YOLO folders and COCO JSON, written here by hand (PIL images), and their
refusals; a generated dataset's YOLO labels read by our reader and by supervision's agree."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from synthua_usd.analytics.detection_sets import ALL_SPLITS, Box, label_path, parse_yolo_labels, read_coco, read_yolo
from synthua_usd.core.errors import InputError


def _image(path: Path, width: int, height: int) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.zeros((height, width, 3), np.uint8)).save(path)
    return path


def yolo_folder(root: Path, names="[person, wheelchair]") -> Path:
    """test: two images of 40x20 (a .jpg and a .png), one with a box and a polygon, one without a label file."""
    _image(root / "images" / "test" / "a.jpg", 40, 20)
    _image(root / "images" / "test" / "b.png", 40, 20)
    (root / "labels" / "test").mkdir(parents=True)
    # a box centred at (10, 5) px, 8 x 4 px; a polygon from (20, 2) to (30, 18) px
    (root / "labels" / "test" / "a.txt").write_text("0 0.25 0.25 0.2 0.2\n\n1 0.5 0.1 0.75 0.1 0.75 0.9 0.5 0.9\n")
    (root / "data.yaml").write_text(f"path: .\ntest: images/test\nnames: {names}\n")
    return root


def test_yolo_boxes_and_polygons_in_pixels(tmp_path):
    s = read_yolo(yolo_folder(tmp_path / "set"))
    assert s.names == ("person", "wheelchair") and s.layout == "yolo" and s.split == "test"
    a, b = s.images
    assert (a.path.name, a.width, a.height, b.path.name) == ("a.jpg", 40, 20, "b.png")
    assert a.boxes[0] == Box("person", 6.0, 3.0, 8.0, 4.0)
    wheelchair = a.boxes[1]
    assert wheelchair.label == "wheelchair"
    assert np.allclose([wheelchair.x, wheelchair.y, wheelchair.w, wheelchair.h], [20, 2, 10, 16])
    assert b.boxes == ()
    assert s.counts() == {"person": 1, "wheelchair": 1}


def test_yolo_names_as_mapping_and_val_when_no_test(tmp_path):
    root = yolo_folder(tmp_path / "set", names="{0: person, 1: wheelchair}")
    (root / "data.yaml").write_text("val: images/test\nnames: {0: person, 1: wheelchair}\n")
    s = read_yolo(root / "data.yaml")
    assert s.split == "val" and s.names == ("person", "wheelchair") and len(s.images) == 2


def test_all_splits_take_each_image_once(tmp_path):
    root = yolo_folder(tmp_path / "set")
    _image(root / "images" / "val" / "c.png", 40, 20)
    (root / "data.yaml").write_text("train: images/test\nval: [images/val, images/test/a.jpg]\n"
                                    "names: [person, wheelchair]\n")
    s = read_yolo(root, ALL_SPLITS)
    assert s.split == "train+val" and [im.path.name for im in s.images] == ["a.jpg", "b.png", "c.png"]
    assert [im.id for im in s.images] == [1, 2, 3] and s.counts() == {"person": 1, "wheelchair": 1}


def test_a_folder_without_data_yaml(tmp_path):
    """Every image below images/ (or images/<split>); classes from classes.txt, else their indices; auto takes it as
    YOLO."""
    from synthua_usd.analytics.detection_sources import detect_format

    root = yolo_folder(tmp_path / "set")
    (root / "data.yaml").unlink()
    _image(root / "images" / "val" / "c.png", 40, 20)
    assert detect_format(root) == "yolo"
    s = read_yolo(root)
    assert s.names == ("0", "1") and len(s.images) == 3 and s.counts() == {"0": 1, "1": 1}
    assert [im.path.name for im in read_yolo(root, "test").images] == ["a.jpg", "b.png"]
    (root / "labels" / "classes.txt").write_text("person\nwheelchair\n")
    assert read_yolo(root).counts() == {"person": 1, "wheelchair": 1}
    with pytest.raises(InputError, match="images/train: not a folder"):
        read_yolo(root, "train")
    (root / "labels" / "classes.txt").write_text("person\nperson\n")
    with pytest.raises(InputError, match="expected class names, one a line, each once"):
        read_yolo(root)


def test_yolo_split_as_list_file(tmp_path):
    root = yolo_folder(tmp_path / "set")
    (root / "test.txt").write_text("./images/test/a.jpg\n")
    (root / "data.yaml").write_text("test: test.txt\nnames: [person, wheelchair]\n")
    s = read_yolo(root)
    assert [im.path.name for im in s.images] == ["a.jpg"] and len(s.images[0].boxes) == 2


def test_a_split_with_too_many_images_is_refused_early(tmp_path, monkeypatch):
    import synthua_usd.analytics.detection_sets as ds

    root = yolo_folder(tmp_path / "set")
    monkeypatch.setattr(ds, "MAX_IMAGES", 1)
    with pytest.raises(InputError, match="more than 1 images"):
        read_yolo(root)


def test_a_photo_turned_by_its_exif_orientation_is_refused(tmp_path):
    root = yolo_folder(tmp_path / "set")
    exif = Image.Exif()
    exif[0x0112] = 6                                   # Orientation: turn 90 degrees to view
    Image.fromarray(np.zeros((20, 40, 3), np.uint8)).save(root / "images" / "test" / "a.jpg", exif=exif)
    with pytest.raises(InputError, match="EXIF orientation 6; expected images stored upright"):
        read_yolo(root)


def test_label_path_replaces_the_last_images_folder():
    assert label_path(Path("/d/images/x/images/test/a.jpg")) == Path("/d/images/x/labels/test/a.txt")


@pytest.mark.parametrize("text, found", [
    ("2 0.5 0.5 0.1 0.1", "class index 2"),
    ("0 0.5 0.5 0.1", "3 coordinates"),
    ("0 0.5 nan 0.1 0.1", "coordinates"),
    ("0 1.5 0.5 0.1 0.1", "coordinates"),
    ("x 0.5 0.5 0.1 0.1", "expected a class index"),
])
def test_bad_label_lines_are_refused_with_file_and_line(text, found):
    with pytest.raises(InputError) as info:
        parse_yolo_labels("0 0.5 0.5 0.1 0.1\n" + text, ("person", "wheelchair"), 40, 20, "l.txt")
    assert "l.txt: line 2" in str(info.value) and found in str(info.value) and "\n" not in str(info.value)


def test_yolo_refusals(tmp_path):
    root = yolo_folder(tmp_path / "set")
    with pytest.raises(InputError, match="train: not in the file"):
        read_yolo(root, "train")
    (root / "data.yaml").write_text("test: images/test\nnames: [person, person]\n")
    with pytest.raises(InputError, match="each class name once"):
        read_yolo(root)
    (root / "data.yaml").write_text("test: images/test\nnames: [person\n")
    with pytest.raises(InputError, match="not valid YAML"):
        read_yolo(root)
    (root / "data.yaml").write_text("test: nowhere\nnames: [person]\n")
    with pytest.raises(InputError, match="does not exist"):
        read_yolo(root)


def coco_file(root: Path) -> Path:
    _image(root / "imgs" / "p1.png", 30, 10)
    _image(root / "imgs" / "p2.png", 30, 10)
    doc = {"images": [{"id": 7, "file_name": "p2.png", "width": 30, "height": 10},
                      {"id": 3, "file_name": "p1.png", "width": 30, "height": 10}],
           "annotations": [{"id": 1, "image_id": 3, "category_id": 5, "bbox": [1, 2, 3, 4]},
                           {"id": 2, "image_id": 3, "category_id": 9, "bbox": [5, 0, 10, 10], "iscrowd": 1},
                           {"id": 3, "image_id": 7, "category_id": 9, "bbox": [0, 0, 2, 2]}],
           "categories": [{"id": 9, "name": "wheelchair"}, {"id": 5, "name": "person"}]}
    path = root / "instances.json"
    path.write_text(json.dumps(doc))
    return path


def test_coco_images_by_id_boxes_and_crowds(tmp_path):
    s = read_coco(coco_file(tmp_path), tmp_path / "imgs")
    assert s.names == ("person", "wheelchair") and s.layout == "coco"
    first, second = s.images
    assert first.path.name == "p1.png" and first.id == 1 and second.path.name == "p2.png"
    assert first.boxes == (Box("person", 1, 2, 3, 4), Box("wheelchair", 5, 0, 10, 10, ignore=True))
    assert second.boxes == (Box("wheelchair", 0, 0, 2, 2),)
    assert s.counts() == {"person": 1, "wheelchair": 1}


def test_coco_refusals(tmp_path):
    path = coco_file(tmp_path)
    with pytest.raises(InputError, match="file not found; expected the image"):
        read_coco(path)                      # the images are in imgs/, not beside the file
    doc = json.loads(path.read_text())
    doc["annotations"][0]["bbox"] = [1, 2, -3, 4]
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError, match=r"annotations\[0\].bbox"):
        read_coco(path, tmp_path / "imgs")


def test_generated_yolo_labels_agree_with_supervision(generated_random):
    """Our reader on a generated dataset's YOLO polygons, against supervision's loader (boxes of the polygons)."""
    import supervision as sv

    s = read_yolo(generated_random, "val")
    theirs = sv.DetectionDataset.from_yolo(str(generated_random / "images" / "val"),
                                           str(generated_random / "labels" / "val"), str(generated_random / "data.yaml"))
    by_name = {Path(p).name: det for p, _, det in theirs}
    assert len(by_name) == len(s.images)
    for im in s.images:
        det = by_name[im.path.name]
        ours = np.array([[b.x, b.y, b.x + b.w, b.y + b.h] for b in im.boxes]).reshape(-1, 4)
        assert np.allclose(ours, det.xyxy, atol=1e-2)
        assert [b.label for b in im.boxes] == [s.names[k] for k in det.class_id]
