"""``synthua generate`` end to end on the demo street: reproducible bytes (reruns, more workers), ``verify``
catching damage, quotas, QA lists, resampling, replay, and hostile configs and folders (resumption:
``test_generate_resume.py``; Ray: ``test_generate_ray.py``). The formats themselves are read by the real tools in
``test_generate_readers.py``."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from conftest import SCENARIO, TINY_CONFIG, generate_dataset
from dataset_runs import records, tree_bytes
from hostile import assert_refused, run_synthua, tree_state
from synthua_usd.core.images import read_image
from synthua_usd.dataset.layout import Layout
from synthua_usd.pipeline.verify import verify


# --- what a run writes -----------------------------------------------------------------------------------

def test_dataset_is_complete_and_verifies(generated):
    result = verify(generated)
    assert result.ok, result.problems
    plan = json.loads((generated / "generate.json").read_text())["plan"]
    kept = [r for r in records(generated) if r["qa"]["verdict"] != "rejected"]
    assert len(records(generated)) == len(plan) and len(kept) == 6
    manifest = json.loads((generated / "manifest.json").read_text())
    assert manifest["provenance"]["mitsuba_variant"] and manifest["provenance"]["usd-core"]
    assert {img["layer_stack"] for img in manifest["images"]} == {manifest["provenance"]["layer_stack"]["digest"]}


def test_splits_never_share_a_camera(generated):
    cameras = {}
    for r in records(generated):
        cameras.setdefault(r["camera"]["prim_path"], set()).add(r["split"])
    assert all(len(splits) == 1 for splits in cameras.values()), cameras


def test_an_empty_split_is_warned_about_and_the_achieved_split_printed(tmp_path, run_cli):
    """Two cameras cannot fill train, val and test: the split is by camera. The summary says what came out, and
    one warning line names the empty split, why, and the fix."""
    config = _config(tmp_path, cameras=["/World/Cameras/CCTV", "/World/Cameras/PedestrianEye"], images=2,
                     time_codes=[24], conditions=["clear_day"], seeds=[0], quotas={},
                     render={"width": 32, "height": 24, "spp": 1, "denoise": False}, qa={"reject": []},
                     split={"train": 0.5, "val": 0.25, "test": 0.25, "seed": 0})
    code, out, err = run_cli("generate", SCENARIO, "--config", config, "--out", tmp_path / "ds")
    assert code == 0, err
    kept = [r for r in records(tmp_path / "ds") if r["qa"]["verdict"] != "rejected"]
    achieved = {s: sum(r["split"] == s for r in kept) for s in ("train", "val", "test")}
    empty = [s for s, n in achieved.items() if n == 0]
    assert len(empty) == 1, achieved
    line = next(x for x in out.splitlines() if x.startswith("split by camera:"))
    assert all(f"{s} {n} images" in line for s, n in achieved.items()) and "(asked 0.5/0.25/0.25)" in line
    warnings = [x for x in err.splitlines() if x.startswith("synthua: warning: split ")]
    assert len(warnings) == 1 and f"split {empty[0]}: no image" in warnings[0], err
    assert "add cameras" in warnings[0] and f"split.{empty[0]} to 0" in warnings[0]


def test_quotas_met_and_reported(generated):
    coverage = json.loads((generated / "coverage.json").read_text())
    quotas = {(q["quota"], q["key"]): q for q in coverage["quotas"]}
    assert coverage["shortfalls"] == [] and all(q["met"] for q in quotas.values()), coverage
    assert quotas[("images", None)]["achieved"] == 6  # the image QA rejected was replaced
    # counted independently from the records: at least half the images show an aid user of >= 5 px
    with_aid = 0
    for r in records(generated):
        by_path = {i["prim_path"]: i for i in r["instances"]}
        for person in r["instances"]:
            device = by_path.get(person["relations"].get("uses", ""))
            if person["class_name"] == "person" and device and person["area"] + device["area"] >= 5:
                with_aid += 1
                break
    assert with_aid >= 3


def test_rejected_images_are_listed_not_dropped(generated):
    rejected = [r for r in records(generated) if r["qa"]["verdict"] == "rejected"]
    assert rejected, "tests/data/configs/tiny.json rejects images with > 5 % clipped highlights (its night frames of the wheelchair eye)"
    listed = (generated / "rejected.csv").read_text().splitlines()[1:]
    for r in rejected:
        assert any(line.startswith(f"{r['id']},{r['name']},rejected,highlights") for line in listed)
        assert "images/" not in json.dumps(r["files"]), "a rejected image stays out of the training formats"
        coco = json.loads((generated / f"annotations/instances_{r['split']}.json").read_text())
        assert r["id"] not in {img["id"] for img in coco["images"]}


def test_amodal_masks_contain_the_visible_ones(generated):
    from pycocotools import mask as mask_utils

    checked = 0
    for r in records(generated):
        instance = read_image(generated / r["files"]["instance"])[0][..., 0]
        for inst in r["instances"]:
            visible = instance == inst["id"]
            amodal = mask_utils.decode(inst["amodal_segmentation"]).astype(bool)
            assert np.array_equal(mask_utils.decode(inst["segmentation"]).astype(bool), visible)
            assert not (visible & ~amodal).any()
            assert inst["amodal_area"] == int(amodal.sum())
            assert inst["occlusion"] == pytest.approx(1.0 - inst["area"] / inst["amodal_area"])
            checked += inst["amodal_area"] > inst["area"]
    assert checked, "some instance of the demo street is partly occluded"


def test_instance_preview_is_colourful(generated):
    r = records(generated)[0]
    preview = read_image(generated / r["files"]["instance_preview"])[0]
    ids = read_image(generated / r["files"]["instance"])[0][..., 0]
    assert preview.shape[-1] == 3 and preview.dtype == np.uint8
    for i in np.unique(ids)[1:]:
        colours = np.unique(preview[ids == i].reshape(-1, 3), axis=0)
        assert len(colours) == 1 and colours[0].max() >= 64  # one visible colour per instance


# --- reproducibility --------------------------------------------------------------------------------------

def test_rerun_with_two_workers_is_byte_identical(generated, tmp_path):
    out = tmp_path / "again"
    generate_dataset(out, workers=2)
    assert tree_bytes(out) == tree_bytes(generated)


def test_denoised_dataset_is_byte_identical_on_one_and_two_workers(tmp_path):
    """tests/data/configs/tiny.json renders without the denoiser (its QA expectations were made on noisy
    images); here the same job with the default quality, denoised: OIDN's output must not depend on the worker
    count or the run."""
    config = json.loads(TINY_CONFIG.read_text())
    config["render"]["denoise"] = True
    config["images"] = 4
    path = tmp_path / "denoised.json"
    path.write_text(json.dumps(config))
    generate_dataset(tmp_path / "one", config=path, workers=1)
    generate_dataset(tmp_path / "two", config=path, workers=2)
    assert tree_bytes(tmp_path / "one") == tree_bytes(tmp_path / "two")
    assert all(r["render"]["denoise"] for r in records(tmp_path / "one"))


def test_replay_is_byte_identical(generated, run_cli):
    code, out, err = run_cli("replay", generated, "2")
    assert code == 0, out + err
    assert "byte-identical" in out


# --- verify -------------------------------------------------------------------------------------------------

@pytest.fixture
def damaged(generated, tmp_path) -> Path:
    copy = tmp_path / "copy"
    shutil.copytree(generated, copy)
    return copy


def _some_file(root: Path, pattern: str) -> Path:
    return sorted(root.glob(pattern))[0]


@pytest.mark.parametrize("damage", ["delete", "truncate", "alter"])
def test_verify_catches_damage(damaged, damage, run_cli):
    target = _some_file(damaged, "frames/*/instance.png" if damage != "alter" else "annotations/instances_train.json")
    if damage == "delete":
        target.unlink()
    elif damage == "truncate":
        target.write_bytes(target.read_bytes()[:100])
    else:
        target.write_bytes(target.read_bytes().replace(b'"iscrowd": 0', b'"iscrowd": 1', 1))
    code, out, _ = run_cli("verify", damaged)
    assert code == 1
    rel = target.relative_to(damaged).as_posix()
    assert any(rel in line for line in out.splitlines() if line.startswith("problem:")), out


def _rewrite_with_checksum(root: Path, path: Path, content: bytes) -> None:
    """Replace a file and make the manifest agree with it: only the cross-file checks can notice."""
    path.write_bytes(content)
    manifest_path = root / "manifest.json"
    manifest = json.loads(manifest_path.read_text())
    rel = path.relative_to(root).as_posix()
    for entry in manifest["dataset_files"] + [e for img in manifest["images"] for e in img["files"]]:
        if entry["path"] == rel:
            entry["sha256"] = hashlib.sha256(content).hexdigest()
            entry["bytes"] = len(content)
    manifest_path.write_text(json.dumps(manifest))


def test_verify_checks_annotations_against_masks(damaged):
    """A COCO box changed and the manifest updated to match: the checksums pass, the cross-file check does not."""
    coco_path = damaged / "annotations" / "instances_train.json"
    coco = json.loads(coco_path.read_text())
    coco["annotations"][0]["bbox"][2] += 1
    _rewrite_with_checksum(damaged, coco_path, json.dumps(coco).encode())
    result = verify(damaged)
    assert [p for p in result.problems if "bbox" in p], result.problems


def test_verify_checks_visible_keypoints_against_their_instance(damaged):
    """A visible keypoint moved to a pixel whose neighbourhood does not show its instance, the manifest
    updated to match: verify reports it."""
    from synthua_usd.dataset.keypoints import WINDOW_PX

    coco_path = damaged / "annotations" / "instances_train.json"
    coco = json.loads(coco_path.read_text())
    names = {img["id"]: img["file_name"][:-4] for img in coco["images"]}
    ann = next(a for a in coco["annotations"] if 2 in a.get("keypoints", [])[2::3])
    ids = read_image(damaged / Layout.frame_file(names[ann["image_id"]], "instance"))[0][..., 0]
    away = np.ones_like(ids, bool)
    for y, x in zip(*np.nonzero(ids == ann["instance_id"])):
        away[max(0, y - WINDOW_PX):y + WINDOW_PX + 1, max(0, x - WINDOW_PX):x + WINDOW_PX + 1] = False
    y, x = np.argwhere(away)[0]
    k = ann["keypoints"][2::3].index(2)
    ann["keypoints"][3 * k:3 * k + 2] = [float(x) + 0.5, float(y) + 0.5]
    _rewrite_with_checksum(damaged, coco_path, json.dumps(coco).encode())
    result = verify(damaged)
    assert [p for p in result.problems if f"keypoint {k} " in p], result.problems


def test_verify_counts_yolo_lines_against_the_instances(damaged):
    label = next(p for p in sorted(damaged.glob("labels/*/*.txt")) if p.read_text().count("\n") >= 2)
    lines = label.read_text().splitlines(keepends=True)
    _rewrite_with_checksum(damaged, label, "".join(lines[1:]).encode())
    result = verify(damaged)
    assert [p for p in result.problems if "YOLO" in p and label.name in p], result.problems


# --- render settings -----------------------------------------------------------------------------------------

def test_the_stage_spp_is_taken_when_the_config_sets_none(tmp_path):
    """The order of docs/rendering.md, "Where the render settings come from": a config's render block without
    spp renders at the stage's synthua:spp (3 here), not at RenderConfig's default."""
    import re

    stages = tmp_path / "stages"
    shutil.copytree(SCENARIO.parent, stages, ignore=shutil.ignore_patterns("district"))
    settings = stages / "render.usda"
    text, edits = re.subn(r"custom int synthua:spp = \d+", "custom int synthua:spp = 3", settings.read_text())
    assert edits == 1
    settings.write_text(text)
    config = _config(tmp_path, images=2, render={"width": 64, "height": 48, "max_depth": 4, "denoise": False})
    out = tmp_path / "out"
    generate_dataset(out, config=config, scenario=stages / SCENARIO.name)
    assert json.loads((out / "generate.json").read_text())["render"]["spp"] == 3
    assert records(out) and all(r["render"]["spp"] == 3 for r in records(out))
    assert verify(out).ok


# --- resampling ---------------------------------------------------------------------------------------------

def test_resampled_dataset_has_no_invented_labels(generated, tmp_path):
    """Written at half size (with the optional EXR and one-hot outputs): labels copy source pixels, so no
    (class, instance) pair appears that the full-size labels lack."""
    config = json.loads(TINY_CONFIG.read_text())
    config["resample"] = {"width": 32, "height": 24}
    config["outputs"] = {"rgb_exr": True, "depth": True, "onehot": True}
    path = tmp_path / "half.json"
    path.write_text(json.dumps(config))
    out = tmp_path / "half"
    generate_dataset(out, config=path)
    assert verify(out).ok
    full = {r["id"]: r for r in records(generated)}
    compared = 0
    for r in records(out):
        assert (r["width"], r["height"]) == (32, 24)
        if r["id"] not in full:  # QA saw other images at this size and replaced another one
            continue
        compared += 1
        small_class = read_image(out / r["files"]["class"])[0][..., 0]
        small_inst = read_image(out / r["files"]["instance"])[0][..., 0]
        big = full[r["id"]]
        big_class = read_image(generated / big["files"]["class"])[0][..., 0]
        big_inst = read_image(generated / big["files"]["instance"])[0][..., 0]
        pairs = set(zip(small_class.ravel().tolist(), small_inst.ravel().tolist()))
        assert pairs <= set(zip(big_class.ravel().tolist(), big_inst.ravel().tolist()))
        rgb = read_image(out / r["files"]["rgb_png"])[0]
        assert rgb.shape == (24, 32, 3)
        if r["qa"]["verdict"] == "rejected":
            continue  # a rejected image keeps only what shows why
        assert read_image(out / r["files"]["rgb_exr"])[0].shape == (24, 32, 3)
        onehot = np.load(out / r["files"]["onehot"])["onehot"]
        assert onehot.dtype == bool and onehot.shape[1:] == (24, 32)
        assert np.array_equal(np.argmax(onehot, axis=0), small_class) and (onehot.sum(axis=0) == 1).all()
    assert compared >= 5


# --- hostile input ------------------------------------------------------------------------------------------

def _config(tmp_path: Path, **changes) -> Path:
    document = json.loads(TINY_CONFIG.read_text())
    document.update(changes)
    path = tmp_path / "config.json"
    path.write_text(json.dumps(document))
    return path


@pytest.mark.parametrize("changes, mentions", [
    ({"images": 0}, ("images",)),
    ({"cameras": ["/World/Cameras/Nope"]}, ("cameras", "/World/Cameras/Nope")),
    ({"conditions": ["monsoon"]}, ("conditions", "monsoon")),
    ({"time_codes": [500]}, ("time_codes", "500")),
    ({"render": {"width": 64, "height": 48, "spp": 2, "pixel_filter": "gaussian"}}, ("pixel_filter",)),
    ({"split": {"train": 0.9, "val": 0.9, "test": 0.1}}, ("split",)),
])
def test_bad_configs_are_refused(tmp_path, changes, mentions):
    out = tmp_path / "out"
    result = run_synthua("generate", SCENARIO, "--config", _config(tmp_path, **changes), "--out", out)
    assert_refused(result, "config.json", *mentions)
    assert not out.exists()


def test_malformed_config_is_refused(tmp_path):
    path = tmp_path / "config.json"
    path.write_text('{"name": "x", "images": ')
    assert_refused(run_synthua("generate", SCENARIO, "--config", path, "--out", tmp_path / "out"), "config.json")


def test_foreign_folder_is_left_alone(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "thesis.tex").write_text("mine")
    before = tree_state(out)
    assert_refused(run_synthua("generate", SCENARIO, "--config", TINY_CONFIG, "--out", out), str(out), "not empty")
    assert tree_state(out) == before


def test_other_job_in_the_folder_is_refused(generated, tmp_path):
    copy = tmp_path / "copy"
    shutil.copytree(generated, copy)
    before = tree_state(copy)
    other = _config(tmp_path, images=5)
    assert_refused(run_synthua("generate", SCENARIO, "--config", other, "--out", copy), "another")
    assert tree_state(copy) == before


def test_out_is_a_file(tmp_path):
    out = tmp_path / "file"
    out.write_text("x")
    assert_refused(run_synthua("generate", SCENARIO, "--config", TINY_CONFIG, "--out", out), str(out))


def test_hostile_config_name_is_refused(tmp_path):
    out = tmp_path / "inside" / "out"
    config = _config(tmp_path, name="../../escape/\n name")
    assert_refused(run_synthua("generate", SCENARIO, "--config", config, "--out", out), "config.json", "name")
    assert not (tmp_path / "inside").exists()


def test_scene_names_stay_inside(tmp_path):
    """A camera whose prim name is not ASCII (USD allows Unicode identifiers) and a scenario outside the
    output folder: every file of the dataset lies below --out with a safe name."""
    from pxr import Usd, UsdGeom

    root = tmp_path / "scenario.usda"
    stage = Usd.Stage.CreateNew(str(root))
    stage.GetRootLayer().subLayerPaths.append(str(SCENARIO))
    demo = Usd.Stage.Open(str(SCENARIO))
    source = demo.GetPrimAtPath("/World/Cameras/PedestrianEye")
    for key in ("startTimeCode", "endTimeCode", "timeCodesPerSecond", "upAxis", "metersPerUnit", "defaultPrim"):
        stage.SetMetadata(key, demo.GetMetadata(key))
    camera = UsdGeom.Camera.Define(stage, "/World/Cameras/Câmera_Ωmega")
    for attr in source.GetAttributes():
        if attr.HasAuthoredValue():
            camera.GetPrim().CreateAttribute(attr.GetName(), attr.GetTypeName()).Set(attr.Get())
    stage.GetRootLayer().Save()
    config = _config(tmp_path, cameras=["/World/Cameras/Câmera_Ωmega"], images=2, quotas={})
    out = tmp_path / "inside" / "out"
    generate_dataset(out, config=config, scenario=root, allow_external_assets=True)
    assert verify(out).ok
    assert sorted(p.name for p in (tmp_path / "inside").iterdir()) == ["out"]
    names = [p.name for p in (out / "images").rglob("*.png")]
    assert names and all(n.isascii() and "_C-mera-mega_" in n for n in names), names
    for path in out.rglob("*"):
        assert path.resolve().is_relative_to(out.resolve())


