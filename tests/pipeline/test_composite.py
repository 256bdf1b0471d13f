"""``synthua composite`` end to end on tiny drawn banks and photos: the dataset has generate's layout and verifies,
the same inputs give the same bytes on one and two workers, replay is byte-identical, stats reads it; and every
label claim checked against its own computation: instance and class maps against the cut-outs' ids resampled here,
COCO masks and boxes against the instance map, keypoint visibility against the occluding pastes, YOLO boxes
against the box convention, a labelled photo's dropped boxes against the share the pastes cover."""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image
from scipy import ndimage

from bank_maker import banded_aid_user, write_band_photos, write_bank, write_photos
from synthua_usd.backends.compositing import POISSON_MARGIN_PX
from synthua_usd.cli.main import main
from synthua_usd.dataset.cutout_bank import read_bank

WIDTH, HEIGHT = 64, 48
CONFIG = {"output": {"width": WIDTH, "height": HEIGHT}, "images_per_background": 2, "seed": 3,
          "pastes": {"per_image": [2, 3], "height_share": [0.3, 0.7], "max_overlap": 1.0, "placement_tries": 1},
          "effects": {"enabled": True, "defocus_probability": 0.5, "noise_probability": 0.5},
          "background_labels": {"classes": {"wheelchair": "manual_wheelchair"}, "drop_covered_share": 0.3},
          "convention": "wheelchair-sets", "min_instance_px": 4}


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("composite_inputs")
    write_bank(root / "bank")
    write_photos(root / "photos", 3, (96, 72))
    write_photos(root / "photos" / "more", 1, (64, 48), suffix=".jpg", seed=1)
    labelled = root / "labelled"
    for k, path in enumerate(write_photos(labelled / "images" / "train", 3, (96, 48), seed=2)):
        label = labelled / "labels" / "train" / f"{path.stem}.txt"
        label.parent.mkdir(parents=True, exist_ok=True)
        # the cut to 64x48 keeps columns 16..80: a person cut a little, a wheelchair user in the middle, a person
        # the cut leaves out
        label.write_text(f"0 0.2 0.6 0.15 0.5\n1 0.{4 + k} 0.6 0.2 0.6\n0 0.05 0.5 0.08 0.3\n")
    (labelled / "data.yaml").write_text("path: .\ntrain: images/train\nnames:\n  0: person\n  1: wheelchair\n")
    (root / "config.json").write_text(json.dumps(CONFIG))
    return root


def _composite(inputs: Path, backgrounds: str, out: str, workers: int) -> Path:
    """``synthua composite`` of ``inputs / backgrounds`` with the bank and config of ``inputs``."""
    assert main([str(a) for a in ("composite", inputs / backgrounds, "--bank", inputs / "bank", "--config",
                                  inputs / "config.json", "--out", inputs / out, "--workers", workers)]) == 0
    return inputs / out


@pytest.fixture(scope="module")
def unlabelled(inputs) -> Path:
    return _composite(inputs, "photos", "out_unlabelled", 2)


@pytest.fixture(scope="module")
def labelled(inputs) -> Path:
    return _composite(inputs, "labelled", "out_labelled", 1)


def _records(root: Path) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted((root / "records").glob("*.json"))]


def _png(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path))


def _tree(root: Path) -> dict[str, str]:
    return {p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def test_the_dataset_has_generates_layout_and_verifies(unlabelled, run_cli):
    for relative in ("data.yaml", "manifest.json", "generate.json", "metadata.csv", "metadata.parquet",
                     "coverage.json", "class_map.json", "annotations/instances_train.json",
                     "annotations/person_keypoints_train.json", "annotations/panoptic_train.json"):
        assert (unlabelled / relative).is_file(), relative
    records = _records(unlabelled)
    assert len(records) == 8 and {r["seed"] for r in records} == {0, 1}
    for r in records:
        assert set(r["files"]) >= {"rgb_png", "class", "semantic", "instance", "instance_preview", "panoptic",
                                   "cs_labelIds", "yolo_label"}
        assert (unlabelled / r["files"]["rgb_png"]).is_file()
    code, out, _ = run_cli("verify", unlabelled)
    assert code == 0 and out.strip().endswith("ok"), out
    job = json.loads((unlabelled / "generate.json").read_text())
    assert job["command"] == "composite" and len(job["plan"]) == 8


def test_one_and_two_workers_give_the_same_bytes_and_replay_is_byte_identical(inputs, unlabelled, run_cli):
    again = _composite(inputs, "photos", "out_one_worker", 1)
    assert _tree(again) == _tree(unlabelled)
    code, out, _ = run_cli("replay", again, "3")
    assert code == 0 and "byte-identical" in out, out
    name = _records(again)[2]["name"]
    (again / "frames" / name / "class.png").write_bytes((again / "frames" / _records(again)[0]["name"] /
                                                         "class.png").read_bytes())
    code, out, _ = run_cli("replay", again, name)
    assert code == 1 and f"differs: frames/{name}/class.png" in out, out


def _expected_maps(record: dict, bank) -> tuple[np.ndarray, np.ndarray]:
    """Instance and class maps of a composite from its bank's cut-outs, each placed by its record's anchor and scale
    (the cut-out pixel under each pixel centre), far to near."""
    from synthua_usd.model.taxonomy import ClassMap

    class_map = ClassMap.default()
    instances = np.zeros((HEIGHT, WIDTH), np.int64)
    classes = np.zeros((HEIGHT, WIDTH), np.int64)
    for paste in sorted(record["composite"]["pastes"], key=lambda p: p["order"]):
        entry = bank.entry(paste["cutout"]["entry"])
        ids = _png(bank.root / entry.files["ids"])
        (ax, ay), s = entry.anchor, paste["scale"]
        for row in range(HEIGHT):
            for col in range(WIDTH):
                u = ax + (col + 0.5 - paste["anchor_px"][0]) / s
                v = ay + (row + 0.5 - paste["anchor_px"][1]) / s
                if 0 <= u < ids.shape[1] and 0 <= v < ids.shape[0] and ids[int(math.floor(v)), int(math.floor(u))]:
                    index = int(ids[int(math.floor(v)), int(math.floor(u))])
                    instances[row, col] = paste["instance_ids"][index - 1]
                    name = next(i.class_name for i in entry.instances if i.index == index)
                    classes[row, col] = class_map.resolve(name).id
    return instances, classes


def test_label_maps_are_the_cutouts_resampled_far_to_near(inputs, unlabelled):
    bank = read_bank(inputs / "bank")
    for record in _records(unlabelled):
        instances, classes = _expected_maps(record, bank)
        np.testing.assert_array_equal(_png(unlabelled / record["files"]["instance"]), instances, record["name"])
        np.testing.assert_array_equal(_png(unlabelled / record["files"]["class"]), classes, record["name"])
        # an unlabelled photo: marked so, and its own pixels void
        assert record["composite"]["background"]["labelled"] is False
        assert record["composite"]["background_boxes"] == []
        sha = hashlib.sha256((inputs / "photos" / record["composite"]["background"]["path"]).read_bytes()).hexdigest()
        assert record["composite"]["background"]["sha256"] == sha


def test_coco_masks_and_boxes_are_the_instance_maps(unlabelled):
    from pycocotools import mask as mask_utils
    from pycocotools.coco import COCO

    coco = COCO(str(unlabelled / "annotations" / "instances_train.json"))
    by_id = {r["id"]: r for r in _records(unlabelled)}
    assert coco.getAnnIds()
    for ann in coco.loadAnns(coco.getAnnIds()):
        record = by_id[ann["image_id"]]
        truth = _png(unlabelled / record["files"]["instance"]) == ann["instance_id"]
        np.testing.assert_array_equal(mask_utils.decode(ann["segmentation"]).astype(bool), truth)
        ys, xs = np.nonzero(truth)
        assert ann["bbox"] == [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1]
        amodal = mask_utils.decode(ann["amodal_segmentation"]).astype(bool)
        assert (amodal | truth).sum() == amodal.sum()          # the amodal mask holds the visible one
        assert ann["occlusion"] == pytest.approx(1 - truth.sum() / amodal.sum())


def test_keypoint_visibility_follows_the_occluding_pastes(inputs, unlabelled):
    from synthua_usd.dataset.keypoints import WINDOW_PX

    bank = read_bank(inputs / "bank")
    downgraded = 0
    for record in _records(unlabelled):
        ids = _png(unlabelled / record["files"]["instance"])
        by_id = {i["id"]: i for i in record["instances"]}
        for paste in record["composite"]["pastes"]:
            entry = bank.entry(paste["cutout"]["entry"])
            for inst, gid in zip(entry.instances, paste["instance_ids"]):
                if gid not in by_id or inst.keypoints is None:
                    continue
                flat = by_id[gid]["keypoints"]["keypoints"]
                for k, (u, v, flag) in enumerate(inst.keypoints):
                    x = paste["anchor_px"][0] + paste["scale"] * (u - entry.anchor[0])
                    y = paste["anchor_px"][1] + paste["scale"] * (v - entry.anchor[1])
                    if flag == 0 or not (0 <= x < WIDTH and 0 <= y < HEIGHT):
                        assert flat[3 * k: 3 * k + 3] == [0.0, 0.0, 0]
                        continue
                    col, row = int(round(x, 2)), int(round(y, 2))  # the pixel of the coordinates as written
                    window = ids[max(0, row - WINDOW_PX):row + WINDOW_PX + 1, max(0, col - WINDOW_PX):col + WINDOW_PX + 1]
                    expected = 2 if flag == 2 and (window == gid).any() else 1
                    assert flat[3 * k + 2] == expected
                    assert flat[3 * k] == pytest.approx(x, abs=0.006) and flat[3 * k + 1] == pytest.approx(y, abs=0.006)
                    if flag == 2 and expected == 1:
                        downgraded += 1
                        # what hides it there is another paste (a nearer one), or its own device
                        others = set(np.unique(window).tolist()) - {0, gid}
                        assert others, (record["name"], gid, k)
    assert downgraded, "some visible keypoint of a cut-out is covered in a composite"


def test_a_labelled_photo_keeps_its_boxes_except_those_the_pastes_cover(inputs, labelled, run_cli):
    code, out, _ = run_cli("verify", labelled)
    assert code == 0, out
    reasons = set()
    for record in _records(labelled):
        composite = record["composite"]
        assert composite["background"]["labelled"] is True and composite["background"]["layout"] == "yolo"
        ids = _png(labelled / record["files"]["instance"])
        for box in composite["background_boxes"]:
            reasons.add(box["reason"])
            assert box["class_name"] == {"person": "person", "wheelchair": "manual_wheelchair"}[box["label"]]
            if box["reason"] == "cropped":
                continue
            x, y, w, h = box["bbox"]
            cols = [c for c in range(WIDTH) if x <= c + 0.5 < x + w]
            rows = [r for r in range(HEIGHT) if y <= r + 0.5 < y + h]
            covered = float((ids[np.ix_(rows, cols)] > 0).mean()) if rows and cols else 0.0
            assert box["covered_share"] == pytest.approx(covered)
            assert box["kept"] == (covered <= 0.3) and (box["reason"] == "covered") == (covered > 0.3)
    assert {None, "cropped"} <= reasons
    # the YOLO labels: the convention's boxes of the pastes, then the kept boxes of the photo
    names = {name: k for k, name in yaml.safe_load((labelled / "data.yaml").read_text())["names"].items()}
    for record in _records(labelled):
        lines = (labelled / record["files"]["yolo_label"]).read_text().splitlines()
        expected = []
        index = {18: names["person"], 29: names["manual_wheelchair"]}
        things = [i for i in record["instances"] if not i["ignore"]]
        by_path = {i["prim_path"]: i for i in things}
        for inst in things:
            x, y, w, h = inst["bbox"]
            if inst["class_name"] == "person" and "uses" in inst["relations"]:
                continue  # wheelchair-sets: a seated user has no person box
            if inst["class_name"] == "manual_wheelchair":
                users = [p for p in things if p["relations"].get("uses") == inst["prim_path"]]
                for u in users:
                    x0, y0 = min(x, u["bbox"][0]), min(y, u["bbox"][1])
                    x1, y1 = max(x + w, u["bbox"][0] + u["bbox"][2]), max(y + h, u["bbox"][1] + u["bbox"][3])
                    x, y, w, h = x0, y0, x1 - x0, y1 - y0
            expected.append((index[inst["category_id"]], x, y, w, h))
        assert by_path is not None
        for box in record["composite"]["background_boxes"]:
            if box["kept"]:
                expected.append((names[box["class_name"]], *box["bbox"]))
        expected = [e for e in expected if e[4] >= 8]  # boxes lower than 8 px are ignored (no YOLO line)
        assert len(lines) == len(expected), record["name"]
        for line, (k, x, y, w, h) in zip(lines, expected):
            values = [float(v) for v in line.split()]
            assert int(values[0]) == k
            np.testing.assert_allclose(values[1:], [(x + w / 2) / WIDTH, (y + h / 2) / HEIGHT, w / WIDTH, h / HEIGHT],
                                       atol=1e-8)


def test_training_targets_take_the_kept_boxes_of_the_photo(labelled):
    from synthua_usd.analytics.detection_targets import read_generated, targets_for

    dataset = read_generated(labelled, None, targets_for("wheelchair-sets"))
    by_name = {r["name"]: r for r in _records(labelled)}
    for image in dataset.images:
        record = by_name[Path(image.path).stem]
        kept = [b for b in record["composite"]["background_boxes"] if b["kept"]]
        photo_boxes = [b for b in image.boxes if [b.x, b.y, b.w, b.h] in [k["bbox"] for k in kept]]
        assert len(photo_boxes) == len(kept)


def test_scored_boxes_keep_one_group_and_make_the_other_regions(labelled):
    """``--boxes pasted`` / ``photo`` of `synthua evaluate-real`: the scored boxes are those of ``all`` in the group
    asked for (the photo's kept boxes told by the records' own bboxes), and the other group's are regions ignored
    for every class: the photo's kept and covered, cropped or crowd boxes; the pasted instances' boxes."""
    from synthua_usd.analytics.detection_targets import read_generated, targets_for

    targets = targets_for("wheelchair-sets")
    every = read_generated(labelled, None, targets)
    pasted, photo = (read_generated(labelled, None, targets, scored) for scored in ("pasted", "photo"))
    by_name = {r["name"]: r for r in _records(labelled)}
    seen = {"pasted": 0, "photo": 0, "dropped": 0}
    for a, p, q in zip(every.images, pasted.images, photo.images):
        record = by_name[Path(a.path).stem]
        shown = [b["bbox"] for b in record["composite"]["background_boxes"]
                 if (b["kept"] or b["reason"] in ("covered", "cropped", "crowd")) and min(b["bbox"][2:]) > 0]
        own = [b for b in a.boxes if [b.x, b.y, b.w, b.h] in shown]
        others = [b for b in a.boxes if [b.x, b.y, b.w, b.h] not in shown]
        assert a.regions == () and p.boxes == tuple(others) and q.boxes == tuple(own)
        assert sorted([r.x, r.y, r.w, r.h] for r in p.regions) == sorted(shown)
        assert all(r.ignore for r in p.regions + q.regions)
        q_regions = [[r.x, r.y, r.w, r.h] for r in q.regions]
        assert all([b.x, b.y, b.w, b.h] in q_regions for b in others)         # every pasted box ignored there
        assert all(box in q_regions for box in shown if box not in [[b.x, b.y, b.w, b.h] for b in own])
        seen["pasted"] += len(others)
        seen["photo"] += len(own)
        seen["dropped"] += len(shown) - len(own)
    assert seen["pasted"] > 0 and seen["photo"] > 0 and seen["dropped"] > 0   # every kind is there to tell apart
    for name in every.names:
        assert every.counts()[name] == pasted.counts()[name] + photo.counts()[name]


def test_evaluate_real_refuses_boxes_a_test_set_has_not(labelled, unlabelled, generated_random, tmp_path, run_cli):
    """Refused in one line before any detector runs: a rendered dataset has no pastes to tell apart, a YOLO reading
    of a composite does not say which boxes were pasted, and an unlabelled photo's composite has no photo boxes of
    the classes scored."""
    run = tmp_path / "run"
    run.mkdir()
    (run / "weights.pt").write_bytes(b"not read before the test set is")
    (run / "train.json").write_text(json.dumps({"classes": ["person", "wheelchair"], "budget": {"imgsz": 64}}))
    split = _records(unlabelled)[0]["split"]
    cases = [((generated_random, "--boxes", "pasted", "--split", "val"), "is a rendered image's record"),
             ((labelled, "--boxes", "pasted", "--format", "yolo"),
              "is read as a yolo set, which does not record which boxes were pasted"),
             ((unlabelled, "--boxes", "photo", "--split", split, "--convention", "wheelchair-sets"),
              "has no photo boxes")]
    for args, found in cases:
        code, out, err = run_cli("evaluate-real", run, *args, "--out", tmp_path / "eval")
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1, err
        assert lines[0].startswith("synthua: error: --boxes") and found in lines[0], err
        assert not (tmp_path / "eval").exists()


def test_stats_and_the_metadata_table_read_a_composite_dataset(unlabelled, tmp_path, run_cli):
    import pyarrow.parquet as pq

    code, out, err = run_cli("stats", unlabelled, "--out", tmp_path / "stats")
    assert code == 0, out + err
    assert (tmp_path / "stats" / "statistics.json").is_file()
    table = pq.read_table(unlabelled / "metadata.parquet").to_pydict()
    records = _records(unlabelled)
    assert table["pastes"] == [len(r["composite"]["pastes"]) for r in sorted(records, key=lambda r: r["id"])]
    assert table["fx"] == [r["camera"]["focal_px"] for r in sorted(records, key=lambda r: r["id"])]


def test_help_teaches_with_examples(run_cli):
    code, out, _ = run_cli("composite", "--help")
    assert code == 0 and "synthua composite photos/ --bank bank/ --config configs/composite.json" in out
    assert "BACKGROUNDS is a folder of photos without labels" in out and "box" in out
    code, out, _ = run_cli("replay", "--help")
    assert code == 0 and "synthua composite" in out


def test_a_coco_set_is_a_labelled_background_too(inputs, tmp_path):
    photos = sorted((inputs / "photos").glob("*.png"))
    coco = {"images": [{"id": k + 1, "file_name": p.name, "width": 96, "height": 72} for k, p in enumerate(photos)],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 7, "bbox": [20.0, 30.0, 12.0, 30.0],
                             "iscrowd": 0}],
            "categories": [{"id": 7, "name": "person"}]}
    (inputs / "photos" / "coco.json").write_text(json.dumps(coco))
    try:
        out = _composite(inputs, "photos/coco.json", "out_coco", 1)
    finally:
        (inputs / "photos" / "coco.json").unlink()
    records = _records(out)
    assert {r["composite"]["background"]["layout"] for r in records} == {"coco"}
    boxed = [r for r in records if r["composite"]["background"]["path"] == photos[0].name]
    assert boxed and all(len(r["composite"]["background_boxes"]) == 1 for r in boxed)
    box = boxed[0]["composite"]["background_boxes"][0]
    # the 96x72 photo covers 64x48 at scale 2/3: x (20 - 0) * 2/3, y 30 * 2/3 - 0 (no cut), sizes * 2/3
    assert box["label"] == "person" and box["bbox"] == pytest.approx([13.3333, 20.0, 8.0, 20.0], abs=1e-4)


def test_sharpness_matching_is_recorded_per_paste_verifies_and_replays(unlabelled, tmp_path, run_cli):
    """Banded cut-outs over soft banded photos: pastes are softened, recorded, verified and replayed."""
    write_bank(tmp_path / "bank", [banded_aid_user("c000000"), banded_aid_user("c000001")])
    write_band_photos(tmp_path / "photos", 2, (256, 192), 2.5)
    config = tmp_path / "sharp.json"
    config.write_text(json.dumps({**CONFIG, "output": {"width": 192, "height": 144}, "match": {"sharpness_strength": 1.0},
                                  "pastes": {**CONFIG["pastes"], "per_image": [1, 1], "height_share": [0.7, 0.9]}}))
    out = tmp_path / "sharp"
    assert main([str(a) for a in ("composite", tmp_path / "photos", "--bank", tmp_path / "bank", "--config", config,
                                  "--out", out, "--workers", 1)]) == 0
    pastes = [p for r in _records(out) for p in r["composite"]["pastes"]]
    assert pastes and all(p["sharpness_sigma_px"] >= 0.0 for p in pastes)
    assert any(p["sharpness_sigma_px"] > 0.5 for p in pastes), [p["sharpness_sigma_px"] for p in pastes]
    job = json.loads((out / "generate.json").read_text())
    assert job["job_key"]["config"]["match"]["sharpness_strength"] == 1.0
    code, text, _ = run_cli("verify", out)
    assert code == 0 and text.strip().endswith("ok"), text
    softened = next(r["id"] for r in _records(out) if any(p["sharpness_sigma_px"] > 0.5 for p in r["composite"]["pastes"]))
    code, text, _ = run_cli("replay", out, str(softened))
    assert code == 0 and "byte-identical" in text, text
    off = [p for r in _records(unlabelled) for p in r["composite"]["pastes"]]
    assert off and all("sharpness_sigma_px" not in p for p in off)


def test_tone_matching_is_recorded_per_paste_verifies_and_replays(inputs, unlabelled, tmp_path, run_cli):
    config = tmp_path / "tone.json"
    config.write_text(json.dumps({**CONFIG, "match": {"contrast_strength": 1.0, "saturation_strength": 0.5}}))
    out = tmp_path / "tone"
    assert main([str(a) for a in ("composite", inputs / "photos", "--bank", inputs / "bank", "--config", config,
                                  "--out", out, "--workers", 1)]) == 0
    pastes = [p for r in _records(out) for p in r["composite"]["pastes"]]
    assert pastes and all(0.67 <= p["contrast_gain"] <= 1.5 and 0.5 <= p["saturation_gain"] <= 1.5 for p in pastes)
    assert any(p["saturation_gain"] != 1.0 for p in pastes)
    match = json.loads((out / "generate.json").read_text())["job_key"]["config"]["match"]
    assert (match["contrast_strength"], match["saturation_strength"]) == (1.0, 0.5)
    assert "sharpness_strength" not in match
    code, text, _ = run_cli("verify", out)
    assert code == 0 and text.strip().endswith("ok"), text
    toned = next(r for r in _records(out) if any(p["saturation_gain"] != 1.0 for p in r["composite"]["pastes"]))
    code, text, _ = run_cli("replay", out, str(toned["id"]))
    assert code == 0 and "byte-identical" in text, text
    # the same draws as without tone matching (placements, blends, effects): only the pastes' pixels differ
    plain = next(r for r in _records(unlabelled) if r["id"] == toned["id"])
    assert [p["box"] for p in plain["composite"]["pastes"]] == [p["box"] for p in toned["composite"]["pastes"]]
    assert all("contrast_gain" not in p for r in _records(unlabelled) for p in r["composite"]["pastes"])


def test_a_coco_set_with_its_photos_elsewhere_keeps_pastes_off_its_crowd_regions(inputs, tmp_path, run_cli):
    """COCO's own layout (annotations/instances_*.json, the photos in a folder beside it: --images) read in place;
    a crowd region (iscrowd 1: no one object) is no box to train on, recorded as dropped (crowd), and pastes keep
    off it as off the kept boxes when the config says so; replay finds the photos where the job did."""
    photos = sorted((inputs / "photos").glob("*.png"))
    coco = {"images": [{"id": k + 1, "file_name": p.name, "width": 96, "height": 72} for k, p in enumerate(photos)],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 7, "bbox": [0.0, 0.0, 40.0, 72.0], "iscrowd": 1},
                            {"id": 2, "image_id": 1, "category_id": 7, "bbox": [60.0, 30.0, 12.0, 30.0],
                             "iscrowd": 0},
                            {"id": 3, "image_id": 1, "category_id": 7, "bbox": [80.0, 10.0, 0.0, 20.0],
                             "iscrowd": 0}],        # a stray click of a label tool: no width
            "categories": [{"id": 7, "name": "person"}]}
    (tmp_path / "annotations").mkdir()
    (tmp_path / "annotations" / "instances_train.json").write_text(json.dumps(coco))
    config = {**CONFIG, "pastes": {**CONFIG["pastes"], "max_background_cover": 0.0, "when_no_room": "skip",
                                   "placement_tries": 40}}
    (tmp_path / "config.json").write_text(json.dumps(config))
    out = tmp_path / "out"
    code, said, err = run_cli("composite", tmp_path / "annotations" / "instances_train.json", "--images",
                              inputs / "photos", "--bank", inputs / "bank", "--config", tmp_path / "config.json",
                              "--out", out, "--workers", "1")
    assert code == 0, said + err
    boxed = [r for r in _records(out) if r["composite"]["background"]["path"] == photos[0].name]
    assert len(boxed) == 2
    pasted = 0
    for record in boxed:
        crowd, person, empty = record["composite"]["background_boxes"]
        assert (crowd["reason"], crowd["kept"], person["kept"]) == ("crowd", False, True)
        assert (empty["reason"], empty["kept"]) == ("empty", False)
        # the 96x72 photo at scale 2/3: the crowd region covers x < 26.67 of the 64x48 image
        assert crowd["bbox"] == pytest.approx([0.0, 0.0, 26.6667, 48.0], abs=1e-4)
        for instance in record["instances"]:
            pasted += 1
            assert instance["bbox"][0] >= 26.6667 - 1e-6, instance["bbox"]       # off the crowd region
        lines = (out / record["files"]["yolo_label"]).read_text().splitlines()
        # the person at [60, 30, 12, 30] in the photo: [40, 20, 8, 20] in the image
        rows = [[float(v) for v in line.split()[1:]] for line in lines]
        assert sum(row == pytest.approx([0.6875, 0.625, 0.125, 0.416667], abs=1e-6) for row in rows) == 1
        assert all(cx - w / 2 >= 26.6667 / 64 - 1e-6 for cx, _, w, _ in rows)
    assert pasted
    code, said, err = run_cli("replay", out, str(boxed[0]["id"]))
    assert code == 0 and "byte-identical" in said + err, said + err


def test_pastes_cut_by_the_frames_side_edges_are_labelled_as_far_as_they_are_seen(inputs, tmp_path, run_cli):
    """pastes.edge_cut lets a paste stand partly beyond the left or right edge: its label maps are its cut-out
    resampled where the frame holds it (computed here again), its COCO box the extent of what is in view, its
    truncation above 0 (0 for pastes within the frame); the dataset verifies and replays byte for byte, and a job made
    before blurred and Poisson pastes went on beyond the cut replays as it was made (differently)."""
    from pycocotools.coco import COCO

    config = {**CONFIG, "images_per_background": 4, "pastes": {**CONFIG["pastes"], "edge_cut": 0.6}}
    (tmp_path / "config.json").write_text(json.dumps(config))
    out = tmp_path / "out"
    code, said, err = run_cli("composite", inputs / "photos", "--bank", inputs / "bank", "--config",
                              tmp_path / "config.json", "--out", out, "--workers", "1")
    assert code == 0, said + err
    bank = read_bank(inputs / "bank")
    coco = COCO(str(out / "annotations" / "instances_train.json"))
    cut = whole = 0
    cut_records = []
    for record in _records(out):
        instances, classes = _expected_maps(record, bank)
        np.testing.assert_array_equal(_png(out / record["files"]["instance"]), instances, record["name"])
        np.testing.assert_array_equal(_png(out / record["files"]["class"]), classes, record["name"])
        truncation = {i["id"]: i["truncation"] for i in record["instances"]}
        for paste in record["composite"]["pastes"]:
            x0, _, x1, _ = paste["box"]
            assert max(-x0, x1 - WIDTH) <= 0.6 * (x1 - x0) + 1e-6          # each side on its own
            outside = max(0.0, -x0) + max(0.0, x1 - WIDTH)
            seen = [i for i in paste["instance_ids"] if i in truncation]
            if outside > 1.0:
                cut += 1
                cut_records.append((paste["blend"]["mode"] in ("blur", "poisson"), record["id"]))
                assert any(truncation[i] > 0 for i in seen), paste
            elif x0 >= 0 and x1 <= WIDTH and paste["box"][1] >= 0 and paste["box"][3] <= HEIGHT:
                whole += 1
                assert all(truncation[i] == 0 for i in seen), paste
        for ann in coco.loadAnns(coco.getAnnIds(imgIds=[record["id"]])):
            ys, xs = np.nonzero(instances == ann["instance_id"])
            assert ann["bbox"] == [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1]
    assert cut and whole, (cut, whole)
    code, said, err = run_cli("verify", out)
    assert code == 0, said + err
    soft = max(cut_records)[1]          # a composite with a cut paste, blurred or Poisson-blended where there is one
    assert max(cut_records)[0], cut_records
    code, said, err = run_cli("replay", out, str(soft))
    assert code == 0 and "byte-identical" in said + err, said + err
    # a job made before such pastes went on beyond the cut has no job_key.open_cuts: replay fades them as it did
    job = json.loads((out / "generate.json").read_text())
    assert job["job_key"].pop("open_cuts") is True
    (out / "generate.json").write_text(json.dumps(job))
    code, said, err = run_cli("replay", out, str(soft))
    assert code != 0 and "differs: images/" in said + err, said + err


def test_replay_plans_and_blends_as_its_job_key_names(unlabelled, tmp_path, monkeypatch):
    """``job_key.visible_overlap`` and ``overlap_by_depth`` reach the planner, ``open_cuts`` and ``seamless_poisson``
    the painter, when a composite is made again; a job key without one (a job made before it) makes it as that job
    did: without ``overlap_by_depth``, by the share of the earlier-planned paste covered, and without
    ``visible_overlap`` too, by the earlier pastes' whole boxes; without ``seamless_poisson``, Poisson from the hard
    composite's gradients, and without ``open_cuts`` too, blends fading at a cut."""
    import synthua_usd.pipeline.composite_worker as worker
    from synthua_usd.pipeline.composite import remake

    asked = []
    planner, painter = worker.plan_pastes, worker.compose

    def plan(*args, **kwargs):
        asked.append(("plan",) + args[5:7])
        return planner(*args, **kwargs)

    def paint(*args, **kwargs):
        asked.append(("paint",) + args[4:6])
        return painter(*args, **kwargs)

    monkeypatch.setattr(worker, "plan_pastes", plan)
    monkeypatch.setattr(worker, "compose", paint)
    job = json.loads((unlabelled / "generate.json").read_text())
    for n, missing in enumerate(((), ("overlap_by_depth",), ("overlap_by_depth", "visible_overlap"),
                                 ("seamless_poisson",), ("seamless_poisson", "open_cuts"))):
        key = {k: v for k, v in job["job_key"].items() if k not in missing}
        (tmp_path / str(n)).mkdir()
        remake({**job, "job_key": key}, job["plan"][0], tmp_path / str(n))
    assert asked == [("plan", True, True), ("paint", True, True), ("plan", True, False), ("paint", True, True),
                     ("plan", False, False), ("paint", True, True), ("plan", True, True), ("paint", True, False),
                     ("plan", True, True), ("paint", False, False)]


def test_the_summary_counts_composites_and_photos_without_a_paste(inputs, tmp_path, run_cli):
    """A photo whose labelled person fills it leaves no room under ``max_background_cover`` 0 and ``skip``: its
    composites are the photo alone, and the summary says how many composites and photos hold no paste (counted
    here from the records)."""
    photos = sorted((inputs / "photos").glob("*.png"))
    coco = {"images": [{"id": k + 1, "file_name": p.name, "width": 96, "height": 72} for k, p in enumerate(photos)],
            "annotations": [{"id": 1, "image_id": 1, "category_id": 7, "bbox": [0.0, 0.0, 96.0, 72.0],
                             "iscrowd": 0}],
            "categories": [{"id": 7, "name": "person"}]}
    (tmp_path / "coco.json").write_text(json.dumps(coco))
    config = {**CONFIG, "pastes": {**CONFIG["pastes"], "max_background_cover": 0.0, "when_no_room": "skip",
                                   "placement_tries": 40}}
    (tmp_path / "config.json").write_text(json.dumps(config))
    out = tmp_path / "out"
    code, said, err = run_cli("composite", tmp_path / "coco.json", "--images", inputs / "photos", "--bank",
                              inputs / "bank", "--config", tmp_path / "config.json", "--out", out, "--workers", "1")
    assert code == 0, said + err
    records = _records(out)
    empty = [r for r in records if not r["composite"]["pastes"]]
    by_photo: dict[str, int] = {}
    for r in records:
        path = r["composite"]["background"]["path"]
        by_photo[path] = by_photo.get(path, 0) + len(r["composite"]["pastes"])
    assert by_photo[photos[0].name] == 0 and len(empty) < len(records)
    photos_without = sum(n == 0 for n in by_photo.values())
    assert (f"{len(empty)} of {len(records)} composites hold no paste ({photos_without} photo"
            f"{'s' * (photos_without != 1)} none in any)") in said + err, said + err


def test_a_grey_photos_composites_are_grey_recorded_verified_and_replayed(inputs, unlabelled, tmp_path, run_cli):
    """Colour pastes in a grey photo (a night CCTV frame) give themselves away: the composite is made grey after its
    camera effects (white balance and noise among them), and the record and metadata table say so."""
    import pyarrow.parquet as pq

    for path in write_photos(tmp_path / "grey", 2, (96, 72), seed=4):
        Image.open(path).convert("L").save(path)
    out = tmp_path / "grey_out"
    code, said, err = run_cli("composite", tmp_path / "grey", "--bank", inputs / "bank", "--config",
                              inputs / "config.json", "--out", out, "--workers", 1)
    assert code == 0, said + err
    records = _records(out)
    assert f"{len(records)} composites made grey: their photos are grey" in said
    assert sum(len(r["composite"]["pastes"]) for r in records) >= 2
    for record in records:
        assert record["composite"]["background"]["monochrome"] is True
        image = _png(out / record["files"]["rgb_png"]).astype(int)
        assert image.ndim == 3 and (image[..., 0] == image[..., 1]).all() and (image[..., 1] == image[..., 2]).all()
    assert pq.read_table(out / "metadata.parquet").to_pydict()["background_monochrome"] == [True] * len(records)
    code, text, _ = run_cli("verify", out)
    assert code == 0 and text.strip().endswith("ok"), text
    code, text, _ = run_cli("replay", out, str(records[0]["id"]))
    assert code == 0 and "byte-identical" in text, text
    # a job made before grey photos stayed grey has no job_key.grey_photos: replay makes its composites in colour
    job = json.loads((out / "generate.json").read_text())
    assert job["job_key"].pop("grey_photos") is True
    (out / "generate.json").write_text(json.dumps(job))
    code, text, _ = run_cli("replay", out, str(records[0]["id"]))
    assert code != 0 and "differs: images/" in text and "differs: records/" in text, text
    # the colour photos' composites stay colour, their pastes too
    for record in _records(unlabelled):        # written only where true: records of colour photos are as before
        assert "monochrome" not in record["composite"]["background"]
        image = _png(unlabelled / record["files"]["rgb_png"]).astype(int)
        assert (image[..., 0] != image[..., 2]).any()


def test_a_labelled_photos_people_place_its_horizon_where_asked(inputs, labelled, tmp_path, run_cli):
    """``camera.person_height_m``: the horizon of each composite of a labelled photo is the median of y_b - h H / 1.7
    over its person boxes whole in the photo (recomputed here from the record's boxes: the cut to the output keeps
    every row of these photos), said as ``people:N``; the pastes stand on that ground; without it, the config's
    range, as before. Its job key says ``people_in_photo``, and a config without the heights leaves it out."""
    config = tmp_path / "people.json"
    config.write_text(json.dumps({**CONFIG, "camera": {"person_height_m": 1.7}}))
    out = tmp_path / "people"
    code, said, err = run_cli("composite", inputs / "labelled", "--bank", inputs / "bank", "--config", config,
                              "--out", out, "--workers", 1)
    assert code == 0, said + err
    records = _records(out)
    assert records and f"{len(records)} of {len(records)} composites with the horizon placed by their photo's" in said
    for record in records:
        camera = record["camera"]
        whole = [b["bbox"] for b in record["composite"]["background_boxes"]      # cropped: at a side, rows whole
                 if b["class_name"] == "person" and b["reason"] in (None, "covered", "cropped")
                 and b["bbox"][1] >= 0.48 and b["bbox"][1] + b["bbox"][3] <= HEIGHT - 0.48 and b["bbox"][3] >= 16.0]
        assert whole, "the fixture's first person box lies whole in the photo"
        expected = float(np.median([y + h - h * camera["height_m"] / 1.7 for _, y, _, h in whole]))
        assert camera["sources"]["horizon_row_px"] == f"people:{len(whole)}:config"
        assert camera["horizon_row_px"] == pytest.approx(expected, abs=1e-3)
        for paste in record["composite"]["pastes"]:
            assert paste["anchor_px"][1] > camera["horizon_row_px"]
            drop = paste["anchor_px"][1] - camera["horizon_row_px"]
            assert paste["distance_m"] == pytest.approx(camera["focal_px"] * camera["height_m"] / drop, rel=1e-6)
    job = json.loads((out / "generate.json").read_text())
    assert job["job_key"]["config"]["camera"]["person_height_m"] == 1.7 and job["job_key"]["people_in_photo"] is True
    assert "people_in_photo" not in json.loads((labelled / "generate.json").read_text())["job_key"]
    code, text, _ = run_cli("replay", out, str(records[0]["id"]))
    assert code == 0 and "byte-identical" in text, text
    plain = _records(labelled)
    assert plain and all(r["camera"]["sources"]["horizon_row_px"] == "config" for r in plain)


def test_wheelchair_users_and_people_the_cut_crops_place_the_horizon_too(inputs, tmp_path, run_cli):
    """``camera.wheelchair_height_m`` with ``person_height_m``: tall photos cut to the output keep rows 12..60, so
    a person whose head the cut crops counts in the whole extent the photo holds, and so does one the cut leaves
    less than half of (dropped from the labels as cropped); a wheelchair user (seated, 1.35 m) counts, a person the
    photo's own bottom edge cuts does not. Recomputed here from the label files and each record's cut: the median
    of y_b - p H / h; said as ``people:3``; pastes below it; replay byte-identical, and a job made before this rule
    (no ``job_key.people_in_photo``) replays by the frame's person boxes alone."""
    tall = tmp_path / "tall"
    lines = "0 0.2 0.45 0.15 0.6\n1 0.6 0.6 0.25 0.4\n0 0.85 0.8 0.1 0.4\n0 0.45 0.158333 0.1 0.294444\n"
    for path in write_photos(tall / "images" / "train", 2, (64, 72), seed=4):
        (tall / "labels" / "train").mkdir(parents=True, exist_ok=True)
        (tall / "labels" / "train" / f"{path.stem}.txt").write_text(lines)
    (tall / "data.yaml").write_text("path: .\ntrain: images/train\nnames:\n  0: person\n  1: wheelchair\n")
    config = tmp_path / "seated.json"
    config.write_text(json.dumps({**CONFIG, "camera": {"person_height_m": 1.7, "wheelchair_height_m": 1.35}}))
    out = tmp_path / "seated"
    code, said, err = run_cli("composite", tall, "--bank", inputs / "bank", "--config", config, "--out", out,
                              "--workers", 1)
    assert code == 0, said + err
    records = _records(out)
    assert len(records) == 4 and "4 of 4 composites with the horizon placed by their photo's people" in said
    boxes = [[float(v) for v in line.split()] for line in lines.splitlines()]
    for record in records:
        camera, background = record["camera"], record["composite"]["background"]
        assert background["region"] == [0.0, 12.0, 64.0, 60.0] and background["scale"] == 1.0
        rows = []
        for label, _, cy, _, h in boxes:
            top, bottom = (cy - h / 2) * 72, (cy + h / 2) * 72     # photo rows
            if top >= 0.72 and bottom <= 72 - 0.72:                # whole in the photo (1 % of its height)
                rows.append(bottom - 12 - (bottom - top) * camera["height_m"] / (1.7 if label == 0 else 1.35))
        assert len(rows) == 3 and (boxes[0][2] - boxes[0][4] / 2) * 72 < 12    # the first person's head is cut
        assert [b["reason"] for b in record["composite"]["background_boxes"]][3] == "cropped"
        assert camera["sources"]["horizon_row_px"] == "people:3:config"
        assert camera["horizon_row_px"] == pytest.approx(float(np.median(rows)), abs=1e-3)
        assert all(p["anchor_px"][1] > camera["horizon_row_px"] for p in record["composite"]["pastes"])
    job = json.loads((out / "generate.json").read_text())
    assert job["job_key"]["config"]["camera"]["wheelchair_height_m"] == 1.35
    code, text, _ = run_cli("replay", out, str(records[-1]["id"]))
    assert code == 0 and "byte-identical" in text, text
    assert job["job_key"].pop("people_in_photo") is True
    (out / "generate.json").write_text(json.dumps(job))
    code, text, _ = run_cli("replay", out, str(records[-1]["id"]))
    assert code != 0 and "differs: records/" in text, text


def test_sharpening_is_recorded_per_paste_keeps_labels_and_photo_pixels_verifies_and_replays(inputs, tmp_path, run_cli):
    """Half the pastes sharpened, camera effects off: each paste's record says whether and how; the labels and
    the photo's pixels are those of the same config without sharpening (but for the 2 px around the pastes of a
    composite with a Poisson paste: its domain reaches there, and its solution depends on every pixel it borders),
    and so is all of a composite none of whose pastes is sharpened (a nearer paste's soft edge may show a sharpened
    farther one's pixels through it)."""
    plain_config = {**CONFIG, "effects": {"enabled": False}}
    made = {}
    for name, extra in (("plain", {}), ("unsharp", {"sharpen": {"share": 0.5, "sigma_px": [1.0, 2.0]}})):
        config = tmp_path / f"{name}.json"
        config.write_text(json.dumps({**plain_config, **extra}))
        made[name] = tmp_path / name
        assert main([str(a) for a in ("composite", inputs / "photos", "--bank", inputs / "bank", "--config", config,
                                      "--out", made[name], "--workers", 1)]) == 0
    records = _records(made["unsharp"])
    pastes = [p for r in records for p in r["composite"]["pastes"]]
    drawn = [p["sharpen"] for p in pastes if p["sharpen"] is not None]
    assert 0 < len(drawn) < len(pastes)
    assert all(2.0 <= s["amount"] <= 3.0 and 1.0 <= s["sigma_px"] <= 2.0 for s in drawn)
    assert all("sharpen" not in p for r in _records(made["plain"]) for p in r["composite"]["pastes"])
    assert json.loads((made["unsharp"] / "generate.json").read_text())["job_key"]["config"]["sharpen"]["share"] == 0.5
    changed = 0
    for record, plain in zip(records, _records(made["plain"])):
        assert [p["box"] for p in plain["composite"]["pastes"]] == [p["box"] for p in record["composite"]["pastes"]]
        instance = _png(made["unsharp"] / record["files"]["instance"])
        np.testing.assert_array_equal(instance, _png(made["plain"] / plain["files"]["instance"]))
        rgb = _png(made["unsharp"] / record["files"]["rgb_png"])
        rgb_plain = _png(made["plain"] / plain["files"]["rgb_png"])
        photo = instance == 0
        if any(p["blend"]["mode"] == "poisson" for p in record["composite"]["pastes"]):
            photo &= ~ndimage.binary_dilation(instance > 0, iterations=POISSON_MARGIN_PX)
        np.testing.assert_array_equal(rgb[photo], rgb_plain[photo])   # the photo's pixels
        if not any(p["sharpen"] for p in record["composite"]["pastes"]):
            np.testing.assert_array_equal(rgb, rgb_plain)
            continue
        sharpened = np.zeros(instance.shape, bool)
        for paste in record["composite"]["pastes"]:
            if paste["sharpen"] is not None:
                sharpened |= np.isin(instance, paste["instance_ids"])
        changed += int((rgb[sharpened] != rgb_plain[sharpened]).any())
    assert changed > 0
    code, text, _ = run_cli("verify", made["unsharp"])
    assert code == 0 and text.strip().endswith("ok"), text
    one = next(r for r in records if any(p["sharpen"] for p in r["composite"]["pastes"]))
    code, text, _ = run_cli("replay", made["unsharp"], str(one["id"]))
    assert code == 0 and "byte-identical" in text, text
