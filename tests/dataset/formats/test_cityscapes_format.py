"""Cityscapes gtFine files read by cityscapesScripts, with synthua's label table patched in."""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest

from format_readers import cityscapes_evaluation
from label_scenes import INSTANCES, crowded_scene, scene
from synthua_usd.core.images import write_color_png, write_id_png
from synthua_usd.core.errors import OutputError
from synthua_usd.dataset.formats.cityscapes import cityscapes_arrays
from synthua_usd.dataset.layout import CityscapesName, Layout, cityscapes_city
from synthua_usd.model.scene import Instance


def test_instance_ids_follow_the_cityscapes_convention(class_map):
    cls, ins, _, _ = scene()
    label_ids, cs_ids, color = cityscapes_arrays(cls, ins, INSTANCES, class_map)
    assert np.array_equal(label_ids, cls) and cs_ids.dtype == np.uint16
    assert np.array_equal(color, class_map.palette()[cls])
    # persons 3, 9, 11 are 18000, 18001, 18002; the road instance (stuff) stays its class id
    assert np.array_equal(cs_ids == 18000, ins == 3) and np.array_equal(cs_ids == 18002, ins == 11)
    assert np.array_equal(cs_ids == 19000, ins == 7)
    assert np.all(cs_ids[cls == 1] == 1) and np.all(cs_ids[cls == 0] == 0)
    assert np.array_equal(cs_ids // 1000 * (cs_ids >= 1000) + cs_ids * (cs_ids < 1000), cls)


def test_more_than_1000_instances_of_a_class_is_refused(class_map):
    ids = np.arange(1, 1002, dtype=np.uint16).reshape(1, -1)
    cls = np.full(ids.shape, 18, np.uint8)
    many = [Instance(int(i), f"/World/P{i}", 18, "person", True) for i in ids.ravel()]
    with pytest.raises(OutputError, match="number 1000 of class 18"):
        cityscapes_arrays(cls, ids, many, class_map)


def test_cityscapes_scripts_pixel_evaluation_of_gt_against_itself_is_iou_one(tmp_path, class_map, monkeypatch):
    from cityscapesscripts.helpers import csHelpers

    ev, labels = cityscapes_evaluation(monkeypatch, class_map)

    layout = Layout(tmp_path)
    city = cityscapes_city("Largo da Ordem, Curitiba")
    gts = []
    for frame, flip in ((1, False), (2, True)):
        cls, ins, _, _ = scene()
        if flip:
            cls, ins = np.ascontiguousarray(cls[:, ::-1]), np.ascontiguousarray(ins[:, ::-1])
        name = CityscapesName(city, 3, frame)
        label_ids, cs_ids, color = cityscapes_arrays(cls, ins, INSTANCES, class_map)
        for kind, pixels, writer in (("labelIds", label_ids, write_id_png), ("instanceIds", cs_ids, write_id_png),
                                     ("color", color, write_color_png)):
            path = layout.path(Layout.cityscapes("val", name, kind))
            path.parent.mkdir(parents=True, exist_ok=True)
            writer(path, pixels)
        gts.append(str(layout.path(Layout.cityscapes("val", name, "labelIds"))))
        info = csHelpers.getCsFileInfo(gts[-1])
        assert (info.city, info.sequenceNb, info.frameNb, info.type, info.type2) == (
            city, "000003", f"{frame:06d}", "gtFine", "labelIds")
    with contextlib.redirect_stdout(io.StringIO()):
        result = ev.evaluateImgLists(gts, gts, ev.args)
    present = {class_map.by_id(int(c)).name for c in np.unique(scene()[0]) if c}
    for name, iou in result["classScores"].items():
        if name in present:
            assert iou == pytest.approx(1.0), name
    for name in present & {l.name for l in labels if l.hasInstances}:
        assert result["classInstScores"][name] == pytest.approx(1.0), name
    assert result["averageScoreClasses"] == pytest.approx(1.0)


@pytest.mark.parametrize("seed", range(3))
def test_instance_ids_of_a_crowded_scene_equal_one_mask_per_instance(seed, class_map):
    cls, ins, instances, _, _ = crowded_scene(seed)
    _, cs_ids, _ = cityscapes_arrays(cls, ins, instances, class_map)
    expected = cls.astype(np.uint16)
    by_id = {i.id: i for i in instances}
    numbered: dict[int, int] = {}
    for inst_id in sorted(int(i) for i in np.unique(ins) if i):
        inst = by_id[inst_id]
        if class_map.by_id(inst.class_id).isthing:
            k = numbered[inst.class_id] = numbered.get(inst.class_id, -1) + 1
            expected[(ins == inst_id) & (cls == inst.class_id)] = inst.class_id * 1000 + k
    assert np.array_equal(cs_ids, expected) and len(numbered) >= 3
