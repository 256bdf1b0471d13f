"""``synthua_usd.analytics.statistics`` on the hand-made dataset of tiny_dataset.py: every figure below is
worked out from the pictures in that module's docstring, not by the code under test."""

from __future__ import annotations

import math

import numpy as np
import pytest

from synthua_usd.analytics.dataset_index import load_index
from synthua_usd.analytics.statistics import compute, mobility_aid_classes
from synthua_usd.core.errors import InputError

from analytics import tiny_dataset


@pytest.fixture()
def tiny_stats(tmp_path):
    root = tiny_dataset.write(tmp_path / "ds")
    return compute(load_index(root))


def test_rejected_images_are_left_out(tiny_stats):
    s = tiny_stats.summary
    assert s["images"] == 2 and s["rejected_images_left_out"] == 1
    assert s["images_per_split"] == {"train": 1, "val": 1}
    assert s["images_per_condition"] == {"clear_day": 1, "day_fog": 1}
    assert s["images_per_rig_type"] == {"cctv": 1, "pedestrian_eye": 1}


def test_objects_shares_ratios_and_areas(tiny_stats):
    rows = {c.name: c for c in tiny_stats.classes}
    assert len(rows) == 36 and "unlabelled" not in rows
    # objects: road 2 regions (one per image), building 3 instances, person, wheelchair, walker 1 each
    assert {n: r.instances for n, r in rows.items() if r.instances} == {
        "road": 2, "building": 3, "person": 1, "manual_wheelchair": 1, "walker": 1}
    assert rows["building"].instance_share == pytest.approx(3 / 8)
    assert rows["building"].imbalance_ratio == 1.0
    assert rows["road"].imbalance_ratio == pytest.approx(1.5)
    assert rows["walker"].imbalance_ratio == pytest.approx(3.0)
    assert rows["car"].imbalance_ratio is None and rows["car"].area.count == 0
    road, building = rows["road"].area, rows["building"].area
    assert (road.mean, road.median, road.std, road.max, road.iqr) == (12.0, 12.0, 4.0, 16.0, 4.0)
    # building areas 12, 6, 4: mean 22/3, median 6, population std sqrt(104/9), quartiles 5 and 9
    assert building.mean == pytest.approx(22 / 3) and building.median == 6.0
    assert building.std == pytest.approx(math.sqrt(104 / 9)) and building.iqr == pytest.approx(4.0)
    assert tiny_stats.areas["building"] == [12, 6, 4]
    assert {n: r.pixels for n, r in rows.items() if r.pixels} == {
        "road": 24, "building": 22, "person": 2, "manual_wheelchair": 3, "walker": 2}
    assert rows["road"].pixel_share == pytest.approx(24 / 53)
    assert rows["road"].images == 2 and rows["person"].images == 1


def test_balance_measures(tiny_stats):
    s = tiny_stats.summary
    assert s["labelled_pixels"] == 53 and s["pixels"] == 96
    assert s["unlabelled_share"] == pytest.approx(43 / 96)
    p = [24 / 53, 22 / 53, 2 / 53, 3 / 53, 2 / 53]
    h = -sum(q * math.log2(q) for q in p)
    assert s["shannon_entropy_bits"] == pytest.approx(h)
    assert s["normalised_entropy"] == pytest.approx(h / math.log2(36))
    # 31 zeros then 2, 2, 3, 22, 24 at ranks 32..36: sum i x = 1866; G = 2*1866/(36*53) - 37/36
    assert s["gini_pixel_area"] == pytest.approx(2 * 1866 / (36 * 53) - 37 / 36)
    assert s["classes_for_coverage"] == 2                     # 24 + 22 = 46 of 53 = 86.8 %
    assert s["coverage_curve"][:2] == pytest.approx([24 / 53, 46 / 53])


def test_per_image_and_cooccurrence(tiny_stats):
    s = tiny_stats.summary
    assert tiny_stats.instances_per_image == [4, 4]
    assert (s["instances_per_image"]["mean"], s["instances_per_image"]["median"], s["instances_per_image"]["max"]) \
        == (4.0, 4.0, 4.0)
    assert s["instances_per_image"]["density_buckets"] == {"<=100": 2, "101-500": 0, ">500": 0}
    # one bin per count 0..4, centred on the integers: both images have 4 objects
    assert s["instances_per_image"]["histogram"] == {"edges": [-0.5, 0.5, 1.5, 2.5, 3.5, 4.5],
                                                     "counts": [0, 0, 0, 0, 2]}
    names = [c.name for c in tiny_stats.classes]
    co = tiny_stats.cooccurrence
    pair = lambda a, b: co[names.index(a), names.index(b)]  # noqa: E731
    assert pair("road", "building") == 2 and pair("road", "road") == 2
    assert pair("person", "manual_wheelchair") == 1 and pair("person", "walker") == 0
    assert pair("walker", "road") == 1
    assert np.array_equal(co, co.T)


def test_mobility_aid_figures(tiny_stats, class_map):
    from conftest import MOBILITY_AIDS

    assert {c.name for c in mobility_aid_classes(class_map.classes)} == MOBILITY_AIDS
    s = tiny_stats.summary
    assert s["images_with_aid_user"] == 1 and s["share_images_with_aid_user"] == 0.5
    assert s["images_with_aid_class"] == 2            # the walker stands alone: a class, not a user
    assert s["aid_area"]["manual_wheelchair"] == {"pixels": 3, "share": pytest.approx(0.6)}
    assert s["aid_area"]["walker"]["share"] == pytest.approx(0.4)
    users = s["aid_users"]
    assert users["count"] == 1 and users["per_aid_type"] == {"manual_wheelchair": 1}
    # person 2 + wheelchair 3 visible of 2 + 4 amodal pixels: occlusion 1/6
    assert users["occlusion"]["median"] == pytest.approx(1 / 6)
    assert users["occlusion"]["histogram"]["counts"] == [1, 0, 0, 0]
    assert users["visible_pixels"]["median"] == 5.0


def test_a_folder_without_manifest_is_refused(tmp_path):
    root = tiny_dataset.write(tmp_path / "ds")
    (root / "manifest.json").unlink()
    with pytest.raises(InputError, match="manifest.json: file not found; expected a complete dataset"):
        load_index(root)


def test_a_broken_record_is_one_error(tmp_path):
    root = tiny_dataset.write(tmp_path / "ds")
    (root / "records" / f"{tiny_dataset.NAMES[0]}.json").write_text('{"id": 1}')
    with pytest.raises(InputError, match=r"records/000001_CCTV_t0001_clear-day_s0\.json: not an image record: "
                                         r"\(document\): 'camera' is a required property; expected a document "
                                         r"matching \$defs/image of record\.schema\.json") as caught:
        load_index(root)
    assert "\n" not in str(caught.value)


def test_a_dataset_without_images_is_refused(tmp_path):
    import json

    root = tiny_dataset.write(tmp_path / "ds")
    manifest = json.loads((root / "manifest.json").read_text())
    for entry in manifest["images"]:
        entry["qa"] = "rejected"
    (root / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(InputError, match=r"no images \(3 rejected by QA, left out\); expected a dataset"):
        compute(load_index(root))
