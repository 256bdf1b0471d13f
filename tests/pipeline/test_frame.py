"""Render jobs (``run_frames``): frame.json against an independent ray caster, the folder layout of several
frames, and the stage's UsdRender vars choosing which files are written."""

import json
import shutil
import logging

import numpy as np
import pytest
from pxr import Sdf, UsdRender

from conftest import DATA, SCENARIO
from reference_raycast import reference_labels
from synthua_usd.composition.scenario import StageMetadata
from synthua_usd.core.outputs import FRAME_DOCUMENT, file_names, select_outputs
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.pipeline.frame import FrameRequest, run_frames
from synthua_usd.usd.compose import compose_layers
from synthua_usd.usd.scenario_layers import build_render_settings

CAMERAS = ("/World/Cameras/CCTV", "/World/Cameras/PedestrianEye", "/World/Cameras/WheelchairEye")
W, H = 160, 120


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    return tmp_path_factory.mktemp("frames") / "out"


@pytest.fixture(scope="module")
def run(out):
    return run_frames(FrameRequest(stage_path=SCENARIO, out_dir=out, camera_paths=CAMERAS, time_codes=(24,), keep_buffers=True,
                                   width=W, height=H, spp=1))


def test_several_frames_from_one_load_in_camera_folders(run, out):
    assert (run.loads, run.reloads) == (1, 0)
    assert [(f.camera.path, f.document["time_code"]) for f in run.frames] == [(c, 24) for c in CAMERAS]
    for frame in run.frames:
        assert frame.out_dir == out / frame.camera.path.rsplit("/", 1)[-1] / "0024"
        assert sorted(p.name for p in frame.out_dir.iterdir()) == sorted(file_names())
        assert json.loads((frame.out_dir / FRAME_DOCUMENT).read_text()) == json.loads(json.dumps(frame.document))


@pytest.mark.slow
@pytest.mark.parametrize("index", range(len(CAMERAS)))
def test_every_instance_visible_to_embree_is_in_frame_json(run, index):
    frame = run.frames[index]
    _, ref_inst = reference_labels(frame.snapshot, frame.camera, W, H)
    listed = {i["id"]: i for i in frame.document["instances"] if i["pixel_count"] > 0}
    by_path = {i["prim_path"]: i for i in frame.document["instances"]}
    for inst_id in set(np.unique(ref_inst)) - {0}:
        assert inst_id in listed, f"instance {inst_id} visible to Embree is missing from frame.json"
        assert frame.snapshot.instance(inst_id).prim_path in by_path


@pytest.mark.parametrize("index", range(len(CAMERAS)))
def test_pixel_counts_match_the_instance_map(run, index):
    frame = run.frames[index]
    counts = np.bincount(frame.rendered.instance_ids.ravel())
    assert sum(i["pixel_count"] for i in frame.document["instances"]) == counts[1:].sum()
    for inst in frame.document["instances"]:
        expected = counts[inst["id"]] if inst["id"] < len(counts) else 0
        assert inst["pixel_count"] == expected


@pytest.mark.parametrize("index", [0, 1])  # the wheelchair-eye camera does not see both
def test_person_and_wheelchair_are_two_instances_linked_in_frame_json(run, index):
    frame = run.frames[index]
    by_path = {i["prim_path"]: i for i in frame.document["instances"]}
    person = by_path["/World/Agents/Agent_0001/Person"]
    chair = by_path["/World/Agents/Agent_0001/ManualWheelchair"]
    assert person["pixel_count"] > 0 and chair["pixel_count"] > 0
    assert person["id"] != chair["id"]
    assert (person["class_name"], chair["class_name"]) == ("person", "manual_wheelchair")
    assert person["relations"] == {"uses": chair["prim_path"]}
    inst, cls = frame.rendered.instance_ids, frame.rendered.class_ids
    assert set(np.unique(cls[inst == person["id"]])) == {person["class_id"]}
    assert set(np.unique(cls[inst == chair["id"]])) == {chair["class_id"]}


# --- the render vars of the stage decide the files -----------------------------------------------------------

TINY_META = StageMetadata(start_time_code=1, end_time_code=2)


def tiny_with_vars(folder, var_names, extra_var=None):
    """tests/data/valid/tiny_scene.usda under a render layer whose product names only ``var_names`` (plus an
    ``extra_var`` that synthua does not write, authored by hand)."""
    stage = build_render_settings(TINY_META, "/World/Cam", RenderConfig(width=16, height=12, spp=1), var_names)
    if extra_var:
        var = UsdRender.Var.Define(stage, f"/Render/Vars/{extra_var}")
        UsdRender.Product(stage.GetPrimAtPath("/Render/Products/Frame")).GetOrderedVarsRel().AddTarget(var.GetPath())
    folder.mkdir()
    stage.GetRootLayer().Export(str(folder / "render.usda"))
    shutil.copy(DATA / "valid" / "tiny_scene.usda", folder / "tiny_scene.usda")  # inside the scenario's folder
    return compose_layers(folder / "scenario.usda", [folder / "render.usda", folder / "tiny_scene.usda"])


@pytest.mark.parametrize("var_names", [("class_id", "depth"), ("rgb",), ("instance_id",)])
def test_render_vars_choose_the_files(tmp_path, var_names):
    stage_path = tiny_with_vars(tmp_path / "scene", var_names)
    assert list(Sdf.Layer.FindOrOpen(str(tmp_path / "scene" / "render.usda")).GetPrimAtPath("/Render/Vars")
                .nameChildren.keys()) == list(var_names)
    run = run_frames(FrameRequest(stage_path=stage_path, out_dir=tmp_path / "out"))
    expected = file_names(select_outputs(var_names))
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(expected)
    doc = json.loads((tmp_path / "out" / FRAME_DOCUMENT).read_text())
    assert sorted(f["path"] for f in doc["files"].values()) == sorted(n for n in expected if n != FRAME_DOCUMENT)
    assert doc["image"] == {"width": 16, "height": 12}  # from the render settings too
    assert (run.frames[0].rendered.rgb is None) == ("rgb" not in var_names)


def test_unknown_render_vars_are_ignored_with_a_warning(tmp_path, caplog):
    stage_path = tiny_with_vars(tmp_path / "scene", ("class_id",), extra_var="normals")
    with caplog.at_level(logging.WARNING):
        run_frames(FrameRequest(stage_path=stage_path, out_dir=tmp_path / "out"))
    assert "render vars ['normals'] are not outputs synthua writes" in caplog.text
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(file_names(select_outputs(["class_id"])))


def test_a_distorted_camera_renders_with_its_lens_in_frame_json(tmp_path):
    """Distortion authored on the camera prim (synthua:distortion:*) reaches the labels, the RGB and frame.json."""
    from pxr import Usd

    from synthua_usd.core.schemas import validate_document
    from synthua_usd.model.distortion import BrownConrady
    from synthua_usd.usd.cameras import author_distortion

    stage_path = tmp_path / "tiny.usda"
    shutil.copy(DATA / "valid" / "tiny_scene.usda", stage_path)
    stage = Usd.Stage.Open(str(stage_path))
    lens = BrownConrady(k1=-0.3, k2=0.08, p2=0.002)
    author_distortion(stage.GetPrimAtPath("/World/Cam"), lens)
    stage.GetRootLayer().Save()
    runs = {}
    for name, path in (("lens", stage_path), ("pinhole", DATA / "valid" / "tiny_scene.usda")):
        runs[name] = run_frames(FrameRequest(stage_path=path, out_dir=tmp_path / name, camera_paths=("/World/Cam",),
                                             width=48, height=32, spp=4)).frames[0]
    doc = json.loads((tmp_path / "lens" / FRAME_DOCUMENT).read_text())
    validate_document(doc, "frame", "frame.json")
    assert doc["camera"]["distortion"] == lens.to_dict()
    assert "distortion" not in runs["pinhole"].document["camera"]
    lensed, plain = runs["lens"].rendered, runs["pinhole"].rendered
    assert (lensed.instance_ids != plain.instance_ids).any() and not np.array_equal(lensed.rgb, plain.rgb)
