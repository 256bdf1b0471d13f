"""A dataset made by ``synthua generate`` read by the real tools, not by our own code: pycocotools (COCO,
COCOeval), panopticapi (pq_compute), cityscapesScripts (getCsFileInfo, pixel-level evaluation), supervision
(YOLO loader), pyarrow and csv (metadata), hashlib (manifest). The unit tests in tests/dataset/formats/ check
each writer on hand-made records; these check the files of one whole run and that they agree with each other.

The ``generated`` and ``generated_random`` datasets are shared by the session: tests that need a reader to write copy the dataset first.
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import json
import multiprocessing
import shutil
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from format_readers import cityscapes_evaluation, coco_keypoint_self_evaluation, coco_self_evaluation
from synthua_usd.dataset.layout import SPLITS, Layout
from synthua_usd.model.taxonomy import ClassMap


def read_json(root: Path, relative: str):
    return json.loads((root / relative).read_text(encoding="utf-8"))


def read_png(path: Path) -> np.ndarray:
    """Pixels as PIL (the reader of pycocotools' users, panopticapi and cityscapesScripts) decodes them."""
    with Image.open(path) as image:
        return np.array(image)


def manifest_images(root: Path) -> list[dict]:
    return read_json(root, Layout.MANIFEST)["images"]


def coco_split(root: Path, split: str) -> dict:
    return read_json(root, Layout.coco_instances(split))


def splits_with_images(root: Path) -> list[str]:
    splits = [s for s in SPLITS if coco_split(root, s)["images"]]
    assert splits, f"{root}: no split holds an image"
    return splits


def dataset_class_map(root: Path) -> ClassMap:
    return ClassMap.from_document(read_json(root, Layout.CLASS_MAP), source=Layout.CLASS_MAP)


@pytest.fixture(params=["generated", "generated_random"])
def dataset(request) -> Path:
    """Each test reads both the tiny dataset and the randomised one (every image a new scene)."""
    return request.getfixturevalue(request.param)


def quiet():
    """pycocotools, panopticapi and cityscapesScripts print their progress and tables."""
    return contextlib.redirect_stdout(io.StringIO())


# ---------------------------------------------------------------------------------------------------- COCO


def test_pycocotools_loads_every_split_and_cocoeval_of_gt_against_itself_is_one(dataset):
    from pycocotools.coco import COCO

    evaluated = 0
    for split in splits_with_images(dataset):
        with quiet():
            gt = COCO(str(dataset / Layout.coco_instances(split)))
        for image in gt.loadImgs(gt.getImgIds()):
            assert (dataset / "images" / split / image["file_name"]).is_file(), image
        anns = gt.loadAnns(gt.getAnnIds())
        if not anns:
            continue
        for kind, stats in coco_self_evaluation(gt, anns).items():
            assert stats[0] == pytest.approx(1.0), (split, kind, stats[:3])
            assert stats[1] == pytest.approx(1.0), (split, kind, stats[:3])
        evaluated += 1
    assert evaluated >= 1, "no split has COCO annotations"


def test_coco_keypoints_evaluate_to_one_and_their_flags_agree_with_the_written_instance_maps(dataset):
    """OKS AP of the keypoints against themselves is 1.0 for every category with labelled keypoints (people
    and the street's manual wheelchair); a visible keypoint (v = 2) has its instance's id in the written
    instance map within WINDOW_PX pixels, a labelled one lies inside the image, an unlabelled one is 0, 0."""
    from pycocotools.coco import COCO

    from synthua_usd.dataset.keypoints import WINDOW_PX

    names = {m["id"]: m["name"] for m in manifest_images(dataset)}
    evaluated, flags = set(), Counter()
    for split in splits_with_images(dataset):
        with quiet():
            gt = COCO(str(dataset / Layout.coco_instances(split)))
        for category, ap in coco_keypoint_self_evaluation(gt).items():
            assert ap == pytest.approx(1.0), (split, category)
            evaluated.add(category)
        for ann in gt.dataset["annotations"]:
            if "keypoints" not in ann:
                continue
            image = gt.imgs[ann["image_id"]]
            ids = read_png(dataset / Layout.frame_file(names[ann["image_id"]], "instance"))
            for x, y, v in np.array(ann["keypoints"], float).reshape(-1, 3):
                flags[int(v)] += 1
                if v == 0:
                    assert x == y == 0
                    continue
                assert 0 <= x < image["width"] and 0 <= y < image["height"]
                if v == 2:
                    col, row = int(x), int(y)
                    window = ids[max(0, row - WINDOW_PX):row + WINDOW_PX + 1, max(0, col - WINDOW_PX):col + WINDOW_PX + 1]
                    assert (window == ann["instance_id"]).any(), (ann["prim_path"], x, y)
    assert {"person", "manual_wheelchair"} <= evaluated
    assert flags[2] > 0


def _default_keypoint_cocoeval(gt, dets: list[dict]) -> list[float]:
    """COCOeval(gt, dt, "keypoints") exactly as its users call it: every category, the default sigmas."""
    from pycocotools.cocoeval import COCOeval

    with quiet():
        ev = COCOeval(gt, gt.loadRes(dets), "keypoints")
        ev.evaluate()
        ev.accumulate()
        ev.summarize()
    return [float(v) for v in ev.stats]


def test_cocoevals_default_keypoint_call_reads_instances_and_person_keypoints(dataset):
    """The default call reads ``num_keypoints`` of every annotation of every category: on instances_{split}.json
    (person detections) it runs, on COCO's person_keypoints_{split}.json (the person category only, COCO's
    sigmas) the person keypoints against themselves give AP 1.0."""
    from pycocotools.coco import COCO

    evaluated = 0
    for split in splits_with_images(dataset):
        with quiet():
            instances = COCO(str(dataset / Layout.coco_instances(split)))
            people = COCO(str(dataset / Layout.coco_person_keypoints(split)))
        person = [c["id"] for c in people.dataset["categories"]]
        assert [c["name"] for c in people.dataset["categories"]] == ["person"]
        assert all("num_keypoints" in a for a in instances.dataset["annotations"])
        dets = [{"image_id": a["image_id"], "category_id": a["category_id"], "keypoints": a["keypoints"], "score": 1.0}
                for a in people.dataset["annotations"] if a["num_keypoints"]]
        assert people.dataset["annotations"] == [a for a in instances.dataset["annotations"]
                                                 if a["category_id"] in person]
        if not dets:
            continue
        assert len(_default_keypoint_cocoeval(instances, dets)) == 10
        assert _default_keypoint_cocoeval(people, dets)[0] == pytest.approx(1.0), split
        evaluated += 1
    assert evaluated >= 1, "no split has labelled person keypoints"


def test_coco_ids_categories_and_images_agree_with_the_manifest_and_class_map(dataset):
    class_map = dataset_class_map(dataset)
    things = {c.id for c in class_map.classes if c.isthing and c.id >= 1}
    manifest = {m["id"]: m for m in manifest_images(dataset)}
    image_ids, ann_ids = [], []
    for split in SPLITS:
        doc = coco_split(dataset, split)
        assert {c["id"] for c in doc["categories"]} == things, split
        assert all(c["name"] == class_map.by_id(c["id"]).name for c in doc["categories"])
        for image in doc["images"]:
            assert manifest[image["id"]]["split"] == split and manifest[image["id"]]["qa"] != "rejected"
            assert image["file_name"] == f"{manifest[image['id']]['name']}.png"
        image_ids += [i["id"] for i in doc["images"]]
        ann_ids += [a["id"] for a in doc["annotations"]]
        assert all(a["category_id"] in things for a in doc["annotations"])
        assert {a["image_id"] for a in doc["annotations"]} <= {i["id"] for i in doc["images"]}
    assert min(image_ids) >= 1 and len(set(image_ids)) == len(image_ids)
    assert ann_ids and min(ann_ids) >= 1 and len(set(ann_ids)) == len(ann_ids)
    # every image QA did not reject is in COCO, in its split; the rejected ones are listed in the manifest only
    assert sorted(image_ids) == sorted(i for i, m in manifest.items() if m["qa"] != "rejected")


def test_coco_amodal_masks_contain_the_visible_ones_and_occlusion_is_their_ratio(dataset):
    from pycocotools import mask as mask_utils

    relations = occluded = 0
    for split in SPLITS:
        doc = coco_split(dataset, split)
        by_id = {a["id"]: a for a in doc["annotations"]}
        for a in doc["annotations"]:
            for key in ("amodal_segmentation", "amodal_area", "amodal_bbox", "occlusion", "truncation", "relations"):
                assert key in a, (split, a["id"], key)
            visible = mask_utils.decode(a["segmentation"]).astype(bool)
            amodal = mask_utils.decode(a["amodal_segmentation"]).astype(bool)
            assert visible.sum() == a["area"] == mask_utils.area(a["segmentation"]) > 0, (split, a["id"])
            assert amodal.sum() == a["amodal_area"], (split, a["id"])
            assert not np.any(visible & ~amodal), (split, a["id"], "visible pixels outside the amodal mask")
            assert a["occlusion"] == pytest.approx(1 - a["area"] / a["amodal_area"], abs=1e-9), (split, a["id"])
            assert 0.0 <= a["truncation"] <= 1.0
            occluded += a["amodal_area"] > a["area"]
            ys, xs = np.nonzero(visible)
            assert a["bbox"] == [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1], (split, a["id"])
            for name in ("uses", "pushes", "accompanies"):  # what a person uses, a companion pushes or accompanies
                if name not in a["relations"]:
                    continue
                target = a["relations"][name]
                if a["relations"].get(f"{name}_annotation_id") is not None:
                    other = by_id[a["relations"][f"{name}_annotation_id"]]
                    assert other["image_id"] == a["image_id"] and other["prim_path"] == target
                    relations += 1
                else:  # the target is not in the picture (hidden, out of frame)
                    assert not any(b["image_id"] == a["image_id"] and b.get("prim_path") == target
                                   for b in doc["annotations"]), (split, a["id"], name)
    assert occluded >= 1, "no annotation is occluded: the amodal checks above would be vacuous"
    assert relations >= 1, "the demo street has mobility-aid users: some annotation should carry a 'uses' relation"


def test_instances_below_min_instance_px_are_ignore_regions_in_every_format(dataset):
    """The rule, from the written instance maps alone: a thing instance with fewer pixels than the config's
    min_instance_px is COCO iscrowd 1, one crowd segment per class in panoptic (panopticapi keeps one per
    category), and no YOLO line; every other one is none of these. COCOeval ignoring the crowd ones is checked by
    the self-evaluations above, which pass them as detections too."""
    from panopticapi.utils import rgb2id

    min_px = read_json(dataset, Layout.MANIFEST)["provenance"]["config"]["min_instance_px"]
    assert min_px > 0
    ignored_seen = kept_seen = 0
    for split in splits_with_images(dataset):
        coco = coco_split(dataset, split)
        panoptic = {a["image_id"]: a for a in read_json(dataset, Layout.coco_panoptic(split))["annotations"]}
        names = {m["id"]: m["name"] for m in manifest_images(dataset)}
        for image in coco["images"]:
            frame = read_png(dataset / Layout.frame_file(names[image["id"]], "instance"))
            pixels = np.bincount(frame.ravel().astype(np.int64))
            anns = [a for a in coco["annotations"] if a["image_id"] == image["id"]]
            crowd_classes = set()
            for a in anns:
                small = pixels[a["instance_id"]] < min_px
                assert a["iscrowd"] == int(small), (split, image["file_name"], a["instance_id"], pixels[a["instance_id"]])
                ignored_seen += small
                kept_seen += not small
                if small:
                    crowd_classes.add(a["category_id"])
            segments = panoptic[image["id"]]["segments_info"]
            ids = rgb2id(read_png(dataset / "annotations" / f"panoptic_{split}" / panoptic[image["id"]]["file_name"]))
            crowds = [seg for seg in segments if seg["iscrowd"]]
            assert sorted(seg["category_id"] for seg in crowds) == sorted(crowd_classes)  # one per class
            for seg in crowds:
                members = [a["instance_id"] for a in anns if a["iscrowd"] and a["category_id"] == seg["category_id"]]
                assert np.array_equal(ids == seg["id"], np.isin(frame, members)), (split, image["file_name"], seg)
            lines = (dataset / "labels" / split / image["file_name"].replace(".png", ".txt")).read_text().splitlines()
            assert len(lines) == sum(not a["iscrowd"] for a in anns), (split, image["file_name"])
    assert ignored_seen and kept_seen, (ignored_seen, kept_seen)  # both kinds occur: the checks are not vacuous


# ------------------------------------------------------------------------------------------------ panoptic


def test_panopticapi_pq_of_gt_against_itself_is_100_for_every_split(dataset, tmp_path, monkeypatch):
    from panopticapi import evaluation

    # pq_compute writes nothing, but the dataset is shared: evaluate a copy all the same.
    root = tmp_path / "dataset"
    shutil.copytree(dataset / "annotations", root / "annotations")
    # One worker: panopticapi starts a pool of cpu_count() processes and never closes it.
    monkeypatch.setattr(multiprocessing, "cpu_count", lambda: 1)
    evaluated = 0
    for split in SPLITS:
        doc = read_json(root, Layout.coco_panoptic(split))
        if not doc["images"]:
            continue
        json_path = str(root / Layout.coco_panoptic(split))
        folder = str(root / "annotations" / f"panoptic_{split}")
        with quiet():
            result = evaluation.pq_compute(json_path, json_path, folder, folder)
        for group in ("All", "Things", "Stuff"):
            assert result[group]["pq"] == pytest.approx(1.0), (split, group, result[group])
            assert result[group]["sq"] == pytest.approx(1.0) and result[group]["rq"] == pytest.approx(1.0)
        assert result["Things"]["n"] > 0 and result["Stuff"]["n"] > 0, split
        evaluated += 1
    assert evaluated >= 1


def test_panoptic_segments_match_their_pngs_exactly(dataset):
    from panopticapi.utils import rgb2id

    class_map = dataset_class_map(dataset)
    checked = 0
    for split in splits_with_images(dataset):
        doc = read_json(dataset, Layout.coco_panoptic(split))
        categories = {c["id"]: c for c in doc["categories"]}
        for c in class_map.classes:
            if c.id >= 1:
                assert categories[c.id]["isthing"] == int(c.isthing), c.name
        assert sorted(a["image_id"] for a in doc["annotations"]) == sorted(i["id"] for i in doc["images"])
        for ann in doc["annotations"]:
            ids = rgb2id(read_png(dataset / "annotations" / f"panoptic_{split}" / ann["file_name"]))
            found, areas = np.unique(ids, return_counts=True)
            in_png = {int(i): int(n) for i, n in zip(found, areas) if i != 0}
            in_json = {s["id"]: s["area"] for s in ann["segments_info"]}
            assert in_png == in_json, (split, ann["file_name"])
            for s in ann["segments_info"]:
                assert s["category_id"] in categories
                ys, xs = np.nonzero(ids == s["id"])
                assert s["bbox"] == [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1], s
            checked += 1
    assert checked >= 1


# ---------------------------------------------------------------------------------------------- Cityscapes


def cityscapes_files(root: Path, folder: str) -> list[Path]:
    return sorted((root / folder).rglob("*.png"))


def test_cityscapes_scripts_parses_every_name_and_its_evaluation_of_gt_against_itself_is_iou_one(
        dataset, monkeypatch):
    from cityscapesscripts.helpers import csHelpers

    class_map = dataset_class_map(dataset)
    ev, labels = cityscapes_evaluation(monkeypatch, class_map)
    gt_files = cityscapes_files(dataset, "gtFine")
    assert gt_files
    for path in gt_files + cityscapes_files(dataset, "leftImg8bit"):
        info = csHelpers.getCsFileInfo(str(path))
        split, city = path.relative_to(dataset).parts[1:3]
        assert split in SPLITS and info.city == city, path
        assert path.name == f"{info.city}_{info.sequenceNb}_{info.frameNb}_{info.type}" + (
            f"_{info.type2}.png" if info.type == "gtFine" else ".png")
        assert info.type2 in ({"labelIds", "instanceIds", "color"} if info.type == "gtFine" else {""}), path
    evaluated = 0
    for split in SPLITS:
        gts = [str(p) for p in gt_files if p.parts[-3] == split and p.name.endswith("_gtFine_labelIds.png")]
        if not gts:
            continue
        present = set()
        for gt in gts:
            present |= {int(c) for c in np.unique(read_png(Path(gt)))}
        with quiet():
            result = ev.evaluateImgLists(gts, gts, ev.args)
        scored = {class_map.by_id(c).name for c in present if c != 0}
        assert scored
        for name in scored:
            assert result["classScores"][name] == pytest.approx(1.0), (split, name)
        with_instances = set()  # classes with an instance (not only group regions of ignored ones)
        for gt in gts:
            ids = read_png(Path(gt.replace("_labelIds.png", "_instanceIds.png")))
            with_instances |= {class_map.by_id(int(i) // 1000).name for i in np.unique(ids[ids >= 1000])}
        for name in scored & {l.name for l in labels if l.hasInstances} & with_instances:
            assert result["classInstScores"][name] == pytest.approx(1.0), (split, name)
        assert result["averageScoreClasses"] == pytest.approx(1.0), split
        evaluated += 1
    assert evaluated >= 1


def test_cityscapes_instance_ids_are_class_times_1000_plus_k_and_agree_with_coco(dataset):
    class_map = dataset_class_map(dataset)
    manifest_names = {m["id"]: m["name"] for m in manifest_images(dataset)}
    things = {c.id for c in class_map.classes if c.isthing}
    checked = 0
    for split in splits_with_images(dataset):
        coco = coco_split(dataset, split)
        for image in coco["images"]:
            stems = list((dataset / "gtFine" / split).rglob(f"*_{image['id']:06d}_gtFine_labelIds.png"))
            assert len(stems) == 1, (split, image["id"], stems)
            label_path = stems[0]
            label_ids = read_png(label_path)
            instance_ids = read_png(Path(str(label_path).replace("_labelIds.png", "_instanceIds.png")))
            assert label_ids.shape == instance_ids.shape == (image["height"], image["width"])
            assert instance_ids.max() < 2 ** 16
            big = instance_ids >= 1000
            assert np.array_equal(instance_ids[big] // 1000, label_ids[big]), label_path
            assert np.array_equal(instance_ids[~big], label_ids[~big]), label_path
            # every thing pixel has its instance, but those of an instance too small to annotate (COCO iscrowd 1),
            # which are a group region: the class id alone
            anns = [a for a in coco["annotations"] if a["image_id"] == image["id"]]
            frame = read_png(dataset / Layout.frame_file(manifest_names[image["id"]], "instance"))
            crowd = np.isin(frame, [a["instance_id"] for a in anns if a["iscrowd"]])
            assert np.all(big == (np.isin(label_ids, list(things)) & ~crowd)), label_path
            # each other COCO annotation is one Cityscapes instance of the same class and area
            cs = sorted((int(i) // 1000, int(n)) for i, n in zip(*np.unique(instance_ids[big], return_counts=True)))
            assert cs == sorted((a["category_id"], a["area"]) for a in anns if not a["iscrowd"]), label_path
            # leftImg8bit is the very RGB file of images/
            left = label_path.parents[3] / "leftImg8bit" / split / label_path.parent.name / label_path.name.replace(
                "_gtFine_labelIds.png", "_leftImg8bit.png")
            assert left.read_bytes() == (dataset / "images" / split / image["file_name"]).read_bytes(), left
            checked += 1
    assert checked >= 1
    assert len(cityscapes_files(dataset, "leftImg8bit")) == checked  # no Cityscapes image without COCO image


# ---------------------------------------------------------------------------------------------------- YOLO


def test_supervision_loads_every_split_with_the_coco_boxes(dataset):
    import supervision as sv

    class_map = dataset_class_map(dataset)
    compared = 0
    for split in splits_with_images(dataset):
        ds = sv.DetectionDataset.from_yolo(images_directory_path=str(dataset / "images" / split),
                                           annotations_directory_path=str(dataset / "labels" / split),
                                           data_yaml_path=str(dataset / Layout.DATA_YAML))
        names = list(ds.classes)
        assert names == [c.name for c in class_map.classes if c.isthing and c.id >= 1]  # COCO's categories
        ids = {c.name: c.id for c in class_map.classes}
        coco = coco_split(dataset, split)
        detections = {Path(path).name: dets for path, dets in ds.annotations.items()}
        assert sorted(detections) == sorted(i["file_name"] for i in coco["images"]), split
        for image in coco["images"]:
            dets = detections[image["file_name"]]
            found = [(ids[names[k]], box) for k, box in zip(dets.class_id, dets.xyxy)]
            expected = [(a["category_id"], np.array([a["bbox"][0], a["bbox"][1], a["bbox"][0] + a["bbox"][2],
                                                     a["bbox"][1] + a["bbox"][3]], float))
                        for a in coco["annotations"] if a["image_id"] == image["id"] and not a["iscrowd"]]
            assert len(found) == len(expected), (split, image["file_name"])  # no YOLO line for an ignore region
            # supervision scales float32 coordinates by the image size: exact up to float32 rounding
            for cid, box in expected:
                match = [j for j, (c, b) in enumerate(found) if c == cid and np.abs(b - box).max() < 1e-3]
                assert match, (split, image["file_name"], cid, box.tolist())
                found.pop(match[0])
            compared += len(expected)
    assert compared >= 1


# ------------------------------------------------------------------------------------------------ metadata


def test_metadata_tables_have_one_row_per_image_with_its_camera_condition_and_counts(dataset):
    import pyarrow.parquet as pq

    class_map = dataset_class_map(dataset)
    manifest = {m["id"]: m for m in manifest_images(dataset)}
    sweep = read_json(dataset, Layout.MANIFEST)["provenance"]["config"]  # the run's config, as it recorded it
    table = pq.read_table(dataset / Layout.METADATA_PARQUET).to_pylist()
    with open(dataset / Layout.METADATA_CSV, newline="", encoding="utf-8") as f:
        text_rows = list(csv.DictReader(f))
    assert sorted(r["image_id"] for r in table) == sorted(manifest)
    assert [int(r["image_id"]) for r in text_rows] == [r["image_id"] for r in table]
    assert list(text_rows[0]) == list(table[0])
    columns = set(table[0])
    wanted = {"camera_path", "rig_type", "fx", "fy", "cx", "cy", "condition", "seed", "time_code", "qa_verdict",
              "qa_reasons"}
    wanted |= {f"camera_to_world_{i}{j}" for i in range(4) for j in range(4)}
    wanted |= {f"{kind}.{c.name}" for kind in ("instances", "pixels") for c in class_map.classes}
    assert wanted <= columns, sorted(wanted - columns)
    annotations = Counter()
    for split in SPLITS:
        annotations.update((a["image_id"], a["category_id"]) for a in coco_split(dataset, split)["annotations"])
    for row, text in zip(table, text_rows):
        image = manifest[row["image_id"]]
        assert row["qa_verdict"] == text["qa_verdict"] == image["qa"] and row["name"] == image["name"]
        assert row["camera_path"].startswith("/") and row["camera_path"] == text["camera_path"]
        assert row["fx"] > 0 and row["fy"] > 0 and 0 < row["cx"] < row["width"] and 0 < row["cy"] < row["height"]
        assert float(text["fx"]) == row["fx"]
        assert row["condition"] in sweep["conditions"] and row["seed"] in sweep["seeds"]
        assert row["time_code"] in sweep["time_codes"]
        assert row["seed"] == image["seed"] and row["split"] == image["split"]
        if image["qa"] != "accepted":  # rejected and flagged images are listed with their reasons
            assert row["qa_reasons"] and text["qa_reasons"] == row["qa_reasons"], row["image_id"]
        # pixel counts add up to the image and match its class-id PNG
        classes = read_png(dataset / Layout.frame_file(image["name"], "class"))
        counts = np.bincount(classes.ravel(), minlength=len(class_map.classes))
        for c in class_map.classes:
            assert row[f"pixels.{c.name}"] == counts[c.id] == int(text[f"pixels.{c.name}"]), (row["image_id"], c.name)
            if c.isthing and c.id >= 1 and image["qa"] != "rejected":
                assert row[f"instances.{c.name}"] == annotations[(row["image_id"], c.id)], (row["image_id"], c.name)


# ------------------------------------------------------------------------------------------------ manifest


def test_manifest_lists_every_file_with_its_sha256_and_nothing_else(dataset):
    manifest = read_json(dataset, Layout.MANIFEST)
    entries = [f for image in manifest["images"] for f in image["files"]] + manifest["dataset_files"]
    paths = [e["path"] for e in entries]
    assert len(set(paths)) == len(paths), [p for p, n in Counter(paths).items() if n > 1]
    for entry in entries:
        data = (dataset / entry["path"]).read_bytes()
        assert hashlib.sha256(data).hexdigest() == entry["sha256"], entry["path"]
        assert len(data) == entry["bytes"], entry["path"]
    on_disk = {p.relative_to(dataset).as_posix() for p in dataset.rglob("*") if p.is_file()}
    listed = set(paths) | {Layout.MANIFEST}
    assert on_disk == listed, sorted(on_disk ^ listed)
    assert sorted(m["id"] for m in manifest["images"]) == sorted(
        read_json(dataset, Layout.record(m["name"]))["id"] for m in manifest["images"])
