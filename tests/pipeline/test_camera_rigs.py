"""Camera rigs placed in the demo street and checked independently of the placing code: every rig's pose
and field of view as USD holds them, the dashcam on the road at every time code (a ray cast straight down
with Embree), aimed cameras seeing their target in a fresh label pass, occlusion counts, rejection."""

import numpy as np
import pytest
import trimesh

from conftest import SCENARIO
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.composition.rigs import RigSpec
from synthua_usd.core.schemas import validate_document
from synthua_usd.geometry.roads import ROAD_CLASSES
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.pipeline.camera_rigs import RigRequest, author_rigs, default_time_codes
from synthua_usd.usd.cameras import camera_paths, read_camera
from synthua_usd.usd.compose import compose_layers
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_io import open_stage

W, H = 320, 240
TIME_CODES = (1.0, 24.0, 48.0)
MIN_PX = 200
RIGS = ("cctv:k1=-0.1,k2=0.02", "dashcam", "uav_nadir:height_m=25", "uav_oblique:aim=crossing,height_m=25",
        "pedestrian_eye:aim=curb_ramp", "wheelchair_eye:ride=auto,aim=crossing",
        "pedestrian_eye:ride=auto,name=Walker")  # the walker's companion is on the other sidewalk: rejected


@pytest.fixture(scope="module")
def placed(tmp_path_factory):
    """(result, stage of the scenario with the rigs layer composed in)."""
    folder = tmp_path_factory.mktemp("rigs")
    result = author_rigs(RigRequest(stage_path=SCENARIO, out_path=folder / "rigs.usda",
                                    rigs=tuple(RigSpec.parse(r) for r in RIGS), width=W, height=H,
                                    time_codes=TIME_CODES, min_target_px=MIN_PX))
    root = compose_layers(folder / "with_rigs.usda", [folder / "rigs.usda", SCENARIO])
    return result, open_stage(root, allow_external_assets=True)


def cameras(placed, status="written"):
    return [c for c in placed[0].report["cameras"] if c["status"] == status]


def test_report_follows_its_schema_and_the_layer_holds_the_written_cameras(placed):
    result, stage = placed
    validate_document(result.report, "camera_rigs_report", "report")
    assert result.report_path.exists() and result.report["layer"] == "rigs.usda"
    assert {c["rig"] for c in cameras(placed)} == {"cctv", "dashcam", "uav_nadir", "uav_oblique", "pedestrian_eye",
                                                    "wheelchair_eye"}
    in_layer = {p for p in camera_paths(stage)}
    assert all(c["prim_path"] in in_layer for c in cameras(placed))
    assert result.accepted == len(cameras(placed)) == 6 and result.rejected == 1


def test_a_camera_below_the_minimum_is_reported_and_not_written(placed):
    (rejected,) = cameras(placed, "rejected")
    assert rejected["name"] == "Walker" and rejected["min_target_px"] < MIN_PX
    assert f"fewer than --min-target-px {MIN_PX}" in rejected["reason"]
    assert "/World/Cameras/Walker" not in camera_paths(placed[1])


def test_every_rigs_pose_and_field_of_view_are_the_usd_cameras(placed):
    stage = placed[1]
    for cam in cameras(placed):
        for frame in cam["frames"]:
            usd = read_camera(stage, cam["prim_path"], frame["time_code"])
            assert np.allclose(usd.camera_to_world, frame["camera_to_world"], atol=1e-9), cam["name"]
            hfov = np.degrees(2 * np.arctan(cam["horizontal_aperture_mm"] / 2 / cam["focal_length_mm"]))
            assert usd.fov_deg(4, 3)[0] == pytest.approx(hfov, rel=1e-5)  # 4:3 filmbacks keep their width
            assert (usd.distortion.to_dict() if usd.distortion else None) == cam["distortion"]


def twin_caster(stage, time_code):
    """An Embree intersector over the twin (agents left out) and the class name of every triangle."""
    from synthua_usd.model.taxonomy import ClassMap

    class_map = ClassMap.default()
    snap = StageReader(stage, class_map).snapshot(time_code)
    meshes = [m for m in snap.meshes if not m.prim_path.startswith("/World/Agents/")]
    verts, faces, owner = snap.world_triangles(meshes)
    names = np.array([class_map.by_id(m.class_id).name for m in meshes], object)[owner]
    return trimesh.Trimesh(verts, faces, process=False, validate=False).ray, names


def test_heights_above_the_ground_are_the_rigs(placed):
    stage = placed[1]
    ray, _ = twin_caster(stage, 1.0)
    for cam in cameras(placed):
        if cam["rides_with"] or cam["rig"].startswith("uav"):
            continue
        eye = np.array(cam["frames"][0]["camera_to_world"])[:3, 3]
        ground, _, _ = ray.intersects_location([eye], [[0.0, 0.0, -1.0]], multiple_hits=False)
        assert eye[2] - ground[0, 2] == pytest.approx(cam["height_m"], abs=1e-3), cam["name"]


def test_the_dashcam_stays_on_the_road_at_every_time_code(placed):
    stage = placed[1]
    (dash,) = [c for c in cameras(placed) if c["rig"] == "dashcam"]
    ray, names = twin_caster(stage, 1.0)
    time_codes = np.arange(stage.GetStartTimeCode(), stage.GetEndTimeCode() + 1)
    eyes = np.array([read_camera(stage, dash["prim_path"], t).origin for t in time_codes])
    first = ray.intersects_first(eyes, np.tile([0.0, 0.0, -1.0], (len(eyes), 1)))
    assert np.all(first >= 0) and set(names[first]) <= set(ROAD_CLASSES)
    assert np.linalg.norm(eyes[-1] - eyes[0]) > 10.0  # it drove: 30 km/h for 47 time codes at 24/s is 16 m
    assert dash["on_road"]


def test_aimed_cameras_see_their_target_in_a_fresh_label_pass(placed, class_map):
    stage = placed[1]
    reader = StageReader(stage, class_map)
    session = RenderSession(RenderConfig(width=W, height=H, spp=1))
    aimed = [c for c in cameras(placed) if c["target"]]
    assert len(aimed) == 5
    for t in TIME_CODES:
        snap = reader.snapshot(t)
        for cam in aimed:
            ids = session.render(snap, read_camera(stage, cam["prim_path"], t), rgb=False).instance_ids
            seen = int(np.isin(ids, cam["target"]["instance_ids"]).sum())
            frame = next(f for f in cam["frames"] if f["time_code"] == t)
            assert seen == frame["target_px"] >= MIN_PX, (cam["name"], t)


def test_occlusion_is_visible_against_alone(placed):
    for cam in cameras(placed):
        for frame in cam["frames"]:
            if "target_px" not in frame:
                continue
            assert frame["alone_px"] >= frame["target_px"]
            if frame["alone_px"]:
                assert frame["occluded_fraction"] == pytest.approx(1 - frame["target_px"] / frame["alone_px"], abs=1e-4)
            assert sum(frame["parts_px"].values()) == frame["target_px"]


def test_default_report_time_codes_spread_over_the_range():
    assert default_time_codes(1, 48) == [1.0, 9.0, 17.0, 24.0, 32.0, 40.0, 48.0]
    assert default_time_codes(1, 3) == [1.0, 2.0, 3.0]
    assert default_time_codes(5, 5) == [5.0]
