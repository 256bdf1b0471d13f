"""YOLO labels read by supervision's YOLO loader, and the pixel-edge outlines checked against the masks."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from label_scenes import W, H, record, scene
from synthua_usd.backends.images import write_color_png
from synthua_usd.dataset.formats.yolo import class_index, data_yaml, merge_parts, outer_outlines, yolo_lines
from synthua_usd.dataset.layout import Layout


def filled(polygon: np.ndarray, shape) -> np.ndarray:
    """Pixels whose centre lies inside ``polygon`` (even-odd rule), computed independently of the tracer."""
    ys, xs = np.mgrid[0:shape[0], 0:shape[1]] + 0.5
    inside = np.zeros(shape, bool)
    for (x0, y0), (x1, y1) in zip(polygon, np.roll(polygon, -1, axis=0)):
        if y0 == y1:
            continue
        crosses = ((ys >= min(y0, y1)) & (ys < max(y0, y1))) & (xs < x0 + (ys - y0) * (x1 - x0) / (y1 - y0))
        inside ^= crosses
    return inside


def test_outlines_are_one_per_8_connected_part_and_fill_the_mask_without_holes():
    cls, ins, _, _ = scene()
    for inst_id in (int(i) for i in np.unique(ins) if i):
        mask = ins == inst_id
        parts = outer_outlines(mask)
        _, count = ndimage.label(mask, structure=np.ones((3, 3)))
        assert len(parts) == count, inst_id
        union = np.zeros_like(mask)
        for part in parts:
            union |= filled(part, mask.shape)
        # 8-connected parts leave 4-connected background: holes are what a 4-connected fill does not reach
        assert np.array_equal(union, ndimage.binary_fill_holes(mask)), inst_id
        merged = merge_parts(parts)
        ys, xs = np.nonzero(mask)
        assert [merged[:, 0].min(), merged[:, 1].min(), merged[:, 0].max(), merged[:, 1].max()] == [
            xs.min(), ys.min(), xs.max() + 1, ys.max() + 1]


def test_supervision_loads_the_layout_with_the_same_boxes(tmp_path, class_map):
    import supervision as sv
    layout = Layout(tmp_path)
    index = class_index(class_map)
    records = [record(1, "train", class_map)[0], record(2, "train", class_map, flip=True)[0]]
    for rec in records:
        image = layout.path(Layout.rgb_png("train", rec["name"]))
        image.parent.mkdir(parents=True, exist_ok=True)
        write_color_png(image, np.zeros((H, W, 3), np.uint8))
        label = layout.path(Layout.yolo_label("train", rec["name"]))
        label.parent.mkdir(parents=True, exist_ok=True)
        label.write_text(yolo_lines(rec["instances"], W, H, index))
    (tmp_path / Layout.DATA_YAML).write_text(data_yaml(class_map))
    ds = sv.DetectionDataset.from_yolo(images_directory_path=str(tmp_path / "images/train"),
                                       annotations_directory_path=str(tmp_path / "labels/train"),
                                       data_yaml_path=str(tmp_path / Layout.DATA_YAML))
    names = [class_map.by_id(cid).name for cid in index]
    assert ds.classes == names
    for rec in records:
        path = str(layout.path(Layout.rgb_png("train", rec["name"])))
        dets = ds.annotations[path]
        things = [i for i in rec["instances"] if i["category_id"] in index]
        assert len(dets) == len(things) and len(things) > 5
        expected = np.array([[b[0], b[1], b[0] + b[2], b[1] + b[3]] for b in (i["bbox"] for i in things)], float)
        # supervision parses coordinates as float32 and scales them by the image size in float32: the boxes
        # are exact up to float32 rounding (about 1e-7 relative), so 1e-3 pixels.
        assert np.abs(dets.xyxy - expected).max() < 1e-3
        assert [names[k] for k in dets.class_id] == [class_map.by_id(i["category_id"]).name for i in things]


def test_data_yaml_lists_splits_and_names():
    from synthua_usd.taxonomy import ClassMap

    text = data_yaml(ClassMap.default())
    assert "train: images/train\n" in text and "test: images/test\n" in text and "path:" not in text
    assert '  0: "curb_ramp"\n' in text
    assert "path: \"/data/x\"" in data_yaml(ClassMap.default(), path="/data/x")
