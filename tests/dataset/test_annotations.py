"""Per-image annotations against independent computations: np.nonzero boxes, counted areas, and masks
decoded by pycocotools."""

from __future__ import annotations

import numpy as np
import pytest
from pycocotools import mask as mask_utils

from label_scenes import INSTANCES, H, W, crowded_scene, scene
from synthua_usd.core.errors import InputError
from synthua_usd.dataset.annotations import STUFF_ID_BASE, annotate, panoptic, relation_entries
from synthua_usd.model.scene import Instance


def box(mask):
    ys, xs = np.nonzero(mask)
    return [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1]


def test_instances_match_masks_decoded_by_pycocotools():
    cls, ins, amodal, trunc = scene()
    entries = annotate(cls, ins, INSTANCES, amodal, trunc)
    visible_ids = sorted(int(i) for i in np.unique(ins) if i)
    assert [e["id"] for e in entries] == [i.id for i in INSTANCES if i.id in visible_ids]  # 12 is hidden
    for e in entries:
        mask = ins == e["id"]
        assert e["area"] == mask.sum() and e["bbox"] == box(mask)
        assert np.array_equal(mask_utils.decode(e["segmentation"]).astype(bool), mask)
        assert list(mask_utils.toBbox(e["segmentation"])) == e["bbox"]
        full = mask.copy().reshape(-1)
        full[amodal.get(e["id"], [])] = True
        full = full.reshape(H, W)
        assert np.array_equal(mask_utils.decode(e["amodal_segmentation"]).astype(bool), full)
        assert e["amodal_area"] == full.sum() and e["amodal_bbox"] == box(full)
        assert e["occlusion"] == pytest.approx(1 - mask.sum() / full.sum())
        assert e["truncation"] == trunc.get(e["id"], 0.0)
        assert isinstance(e["segmentation"]["counts"], str)
    by_id = {e["id"]: e for e in entries}
    # each relation with its target's class, whether or not the target is in view
    assert by_id[3]["relations"] == {"uses": "/World/Agents/W1", "uses_class": "manual_wheelchair"}
    assert by_id[9]["relations"] == {"pushes": "/World/Agents/W1", "pushes_class": "manual_wheelchair"}
    assert by_id[11]["relations"] == {"accompanies": "/World/Agents/P1", "accompanies_class": "person"}
    assert by_id[5]["relations"] == {}
    assert relation_entries((("uses", "/Nowhere"),), {}) == {"uses": "/Nowhere"}
    assert by_id[7]["occlusion"] == pytest.approx(18 / 144)  # two pole columns over nine car rows
    assert by_id[9]["occlusion"] == 0.0
    assert by_id[1]["isthing"] is False


def test_without_amodal_input_amodal_is_visible():
    cls, ins, _, _ = scene()
    for e in annotate(cls, ins, INSTANCES, None, None):
        assert e["amodal_segmentation"] == e["segmentation"] and e["occlusion"] == 0.0 and e["truncation"] == 0.0


def test_panoptic_segments_match_the_png_exactly(class_map):
    cls, ins, _, _ = scene()
    rgb, segments = panoptic(cls, ins, INSTANCES, class_map)
    rgb = rgb.astype(np.int64)
    ids = rgb[..., 0] + 256 * rgb[..., 1] + 65536 * rgb[..., 2]
    assert sorted(int(i) for i in np.unique(ids) if i) == [s["id"] for s in segments]
    for s in segments:
        mask = ids == s["id"]
        assert s["area"] == mask.sum() and s["bbox"] == box(mask) and s["iscrowd"] == 0
        assert np.all(cls[mask] == s["category_id"])
    stuff = {s["category_id"]: s for s in segments if s["id"] >= STUFF_ID_BASE}
    assert set(stuff) == {1, 3, 16}                                  # road with its instance merged into stuff
    assert stuff[1]["area"] == np.sum(cls == 1)
    assert np.all(ids[cls == 0] == 0)                                  # void
    things = {s["id"] for s in segments if s["id"] < STUFF_ID_BASE}
    assert things == {2, 3, 5, 7, 8, 9, 11, 13}


def test_bad_inputs_name_what_they_found():
    cls, ins, _, _ = scene()
    with pytest.raises(InputError, match="ids \\[13\\] have no instance"):
        annotate(cls, ins, INSTANCES[:-1])
    with pytest.raises(InputError, match="expected flat indices"):
        annotate(cls, ins, INSTANCES, {3: np.array([H * W])})
    wrong = tuple(Instance(i.id, i.prim_path, 19, "car", True) if i.id == 3 else i for i in INSTANCES)
    with pytest.raises(InputError, match="expected only its class 19"):
        annotate(cls, ins, wrong)
    with pytest.raises(InputError, match="expected \\(H, W\\) uint16"):
        annotate(cls, ins.astype(np.int32), INSTANCES)


def coco_rle(mask):
    """pycocotools' own encoding of a full-size mask, the straightforward way."""
    rle = mask_utils.encode(np.asfortranarray(mask.astype(np.uint8)))
    return {"size": [int(v) for v in rle["size"]], "counts": rle["counts"].decode("ascii")}


@pytest.mark.parametrize("seed", range(4))
def test_crowded_scene_equals_one_full_mask_per_instance(seed, class_map):
    """annotate and panoptic read the maps a few times in all; each entry must equal what one full-size mask
    per instance and pycocotools' encode give, byte for byte."""
    cls, ins, instances, amodal, trunc = crowded_scene(seed)
    height, width = ins.shape
    entries = annotate(cls, ins, instances, amodal, trunc)
    expected_ids = [i.id for i in instances if np.any(ins == i.id)]
    assert [e["id"] for e in entries] == expected_ids and 7 not in expected_ids
    for e in entries:
        mask = ins == e["id"]
        full = mask.copy().reshape(-1)
        full[np.asarray(amodal.get(e["id"], []), np.int64)] = True
        full = full.reshape(height, width)
        assert e["segmentation"] == coco_rle(mask) and e["amodal_segmentation"] == coco_rle(full)
        assert e["area"] == mask.sum() and e["bbox"] == box(mask)
        assert e["amodal_area"] == full.sum() and e["amodal_bbox"] == box(full)
        assert e["occlusion"] == 1.0 - mask.sum() / full.sum() and e["truncation"] == trunc[e["id"]]
    rgb, segments = panoptic(cls, ins, instances, class_map)
    rgb = rgb.astype(np.int64)
    ids = rgb[..., 0] + 256 * rgb[..., 1] + 65536 * rgb[..., 2]
    assert [s["id"] for s in segments] == sorted(int(i) for i in np.unique(ids) if i)
    for s in segments:
        mask = ids == s["id"]
        assert s["area"] == mask.sum() and s["bbox"] == box(mask) and np.all(cls[mask] == s["category_id"])


def test_a_mixed_class_instance_is_named_in_instance_order(class_map):
    cls, ins, instances, _, _ = crowded_scene(0)
    things = [i for i in instances if np.any(ins == i.id) and i.isthing]
    first, later = things[3], things[10]
    for inst in (later, first):  # another thing class under one pixel of each
        y, x = np.argwhere(ins == inst.id)[0]
        cls[y, x] = 22 if inst.class_id != 22 else 19
    # annotate names the first in instance order, panoptic the smallest segment id
    with pytest.raises(InputError, match=f"instance {first.id} .*expected only its class {first.class_id}"):
        annotate(cls, ins, instances)
    low = min(first, later, key=lambda i: i.id)
    with pytest.raises(InputError, match=f"instance {low.id} .*expected only its class {low.class_id}"):
        panoptic(cls, ins, instances, class_map)


def test_rle_problem_accepts_every_mask_pycocotools_encodes_and_refuses_garbage():
    from pycocotools import mask as mask_utils

    from synthua_usd.dataset.annotations import rle_problem

    rng = np.random.default_rng(5)
    for _ in range(50):
        h, w = (int(v) for v in rng.integers(1, 40, 2))
        mask = (rng.random((h, w)) < rng.random()).astype(np.uint8)
        rle = mask_utils.encode(np.asfortranarray(mask))
        assert rle_problem({"size": [h, w], "counts": rle["counts"].decode("ascii")}, (h, w)) is None
    assert "size" in rle_problem({"size": [3, 3], "counts": "9"}, (4, 5))
    assert "string" in rle_problem({"size": [4, 5], "counts": [20]}, (4, 5))
    assert "20" in rle_problem({"size": [4, 5], "counts": "6"}, (4, 5))
