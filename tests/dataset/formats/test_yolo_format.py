"""YOLO labels read by supervision's YOLO loader, and the pixel-edge outlines checked against the masks."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from label_scenes import W, H, crowded_scene, record, scene
from synthua_usd.core.images import write_color_png
from synthua_usd.dataset.annotations import annotate, mark_ignored
from synthua_usd.dataset.formats.yolo import (class_index, data_yaml, label_outlines, merge_parts, outer_outlines,
                                             yolo_lines)
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
    from synthua_usd.model.taxonomy import ClassMap

    text = data_yaml(ClassMap.default())
    assert "train: images/train\n" in text and "test: images/test\n" in text and "path:" not in text
    assert '  0: "curb_ramp"\n' in text
    assert "path: \"/data/x\"" in data_yaml(ClassMap.default(), path="/data/x")


def walked_outlines(mask: np.ndarray) -> list[np.ndarray]:
    """Outer outlines traced one edge at a time in Python (the tracer's first form), for comparison: from
    each unused edge in raster order of its start corner, follow the edge leaving the corner reached, the
    left turn where two leave it; keep clockwise loops, corners only."""
    m = np.pad(mask, 1)
    rows, cols = np.nonzero(m[1:-1, 1:-1])
    start, end = [], []
    for (dr, dc), (sx, sy), (ex, ey) in [((-1, 0), (0, 0), (1, 0)), ((0, 1), (1, 0), (1, 1)),
                                         ((1, 0), (1, 1), (0, 1)), ((0, -1), (0, 1), (0, 0))]:
        for r, c in zip(rows, cols):
            if not m[1 + r + dr, 1 + c + dc]:
                start.append((c + sx, r + sy))
                end.append((c + ex, r + ey))
    outgoing = {}
    for e, corner in enumerate(start):
        outgoing.setdefault(corner, []).append(e)
    used, loops = set(), []
    for first in sorted(range(len(start)), key=lambda e: (start[e][1], start[e][0], e)):
        if first in used:
            continue
        loop, e = [], first
        while e not in used:
            used.add(e)
            loop.append(start[e])
            options = [o for o in outgoing[end[e]] if o not in used]
            if not options:
                break
            dx, dy = end[e][0] - start[e][0], end[e][1] - start[e][1]
            lefts = [o for o in options if (end[o][0] - start[o][0], end[o][1] - start[o][1]) == (dy, -dx)]
            e = (lefts or options)[0]
        poly = np.array(loop, np.int64)
        nxt, prev = np.roll(poly, -1, axis=0), np.roll(poly, 1, axis=0)
        if np.sum(poly[:, 0] * nxt[:, 1] - nxt[:, 0] * poly[:, 1]) > 0:
            d_in, d_out = poly - prev, nxt - poly
            loops.append(poly[d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0] != 0])
    return loops


def test_outlines_equal_an_edge_by_edge_walk_on_random_masks():
    rng = np.random.default_rng(3)
    for _ in range(300):
        mask = rng.random(tuple(rng.integers(1, 16, 2))) < rng.uniform(0.2, 0.8)  # pinches, holes, parts
        got, expected = outer_outlines(mask), walked_outlines(mask)
        assert len(got) == len(expected) and all(np.array_equal(a, b) for a, b in zip(got, expected))


@pytest.mark.parametrize("seed", range(3))
def test_outlines_of_all_instances_at_once_and_lines_from_the_map_equal_those_of_each_mask(seed, class_map):
    cls, ins, instances, amodal, trunc = crowded_scene(seed)
    outlines = label_outlines(ins)
    assert sorted(outlines) == sorted(int(i) for i in np.unique(ins) if i)
    for inst_id, parts in outlines.items():
        expected = outer_outlines(ins == inst_id)
        assert len(parts) == len(expected) and all(np.array_equal(a, b) for a, b in zip(parts, expected))
    entries = annotate(cls, ins, instances, amodal, trunc)
    mark_ignored(entries, 0)  # as the worker does: every entry a record holds says whether it is ignored
    index = class_index(class_map)
    from_map = yolo_lines(entries, ins.shape[1], ins.shape[0], index, ins)
    assert from_map == yolo_lines(entries, ins.shape[1], ins.shape[0], index)  # masks decoded from the RLEs
    assert len(from_map.splitlines()) == sum(e["category_id"] in index for e in entries) > 10
