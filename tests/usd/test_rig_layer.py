"""The cameras layer of placed rigs: what is authored reads back as the same camera (pose at every time
code, field of view, lens distortion), moving rigs are time-sampled, and the rig's provenance is on the prim."""

import math

import numpy as np
import pytest
from pxr import Usd, UsdGeom

from synthua_usd.composition.rigs import RigSpec
from synthua_usd.composition.scenario import StageMetadata
from synthua_usd.geometry.placement import Placement
from synthua_usd.model.meshes import look_at
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.prim_checks import camera_findings
from synthua_usd.usd.rig_layer import PlacedRig, build_rig_layer

META = StageMetadata(start_time_code=1.0, end_time_code=4.0)
TIME_CODES = [1.0, 2.0, 3.0, 4.0]


@pytest.fixture(scope="module")
def rigs():
    cctv = PlacedRig("CCTV_A", RigSpec.parse("cctv:k1=-0.1,k2=0.02,p1=0.001"),
                     Placement(7.5, "pole", pose=look_at((3, -8, 6), (0, 0, 0.8))), "/World/Agents/Agent_0001")
    track = {t: look_at((t, 0.0, 1.35), (t + 10.0, 0.5, 1.0)) for t in TIME_CODES}
    dashcam = PlacedRig("Dash", RigSpec.parse("dashcam"), Placement(3.0, "road", track=track), None)
    ride = {t: look_at((0.0, t, 1.2), (0.0, t + 5.0, 1.0)) for t in TIME_CODES}
    rider = PlacedRig("WC", RigSpec.parse("wheelchair_eye:ride=auto"),
                      Placement(24.0, "riding", track=ride, rides_with="/World/Agents/Agent_0003"), None)
    return [cctv, dashcam, rider]


@pytest.fixture(scope="module")
def stage(rigs, tmp_path_factory):
    path = tmp_path_factory.mktemp("rigs") / "rigs.usda"
    layer = build_rig_layer(META, rigs, "test rigs")  # the stage owns its layer: keep it while exporting
    layer.GetRootLayer().Export(str(path))
    return Usd.Stage.Open(str(path))


@pytest.mark.parametrize("t", TIME_CODES)
def test_every_rig_reads_back_with_its_pose_and_field_of_view(rigs, stage, t):
    for rig in rigs:
        expected = rig.placement.camera(rig.spec, rig.prim_path, t)
        got = read_camera(stage, rig.prim_path, t)
        assert np.allclose(got.camera_to_world, expected.camera_to_world, atol=1e-9), rig.name
        assert got.fov_deg(1280, 960) == pytest.approx(expected.fov_deg(1280, 960), rel=1e-6)
        assert (got.clip_near_m, got.clip_far_m) == pytest.approx((expected.clip_near_m, expected.clip_far_m), rel=1e-6)
        assert got.distortion == expected.distortion


def test_lens_values_are_tenths_of_a_scene_unit(stage):
    cam = UsdGeom.Camera(stage.GetPrimAtPath("/World/Cameras/CCTV_A"))
    assert cam.GetFocalLengthAttr().Get() == pytest.approx(0.075)  # 7.5 mm on a metre stage
    assert cam.GetHorizontalApertureAttr().Get() == pytest.approx(0.048)
    fov = read_camera(stage, "/World/Cameras/CCTV_A", 1).fov_deg(4, 3)[0]
    assert fov == pytest.approx(math.degrees(2 * math.atan(4.8 / 2 / 7.5)))


def test_moving_rigs_are_time_sampled_and_fixed_ones_are_not(stage):
    def samples(name):
        op = UsdGeom.Xformable(stage.GetPrimAtPath(f"/World/Cameras/{name}")).GetOrderedXformOps()[0]
        return op.GetAttr().GetTimeSamples()

    assert samples("CCTV_A") == [] and samples("Dash") == TIME_CODES and samples("WC") == TIME_CODES


def test_provenance_and_distortion_are_on_the_prim(stage):
    cctv = stage.GetPrimAtPath("/World/Cameras/CCTV_A")
    assert cctv.GetAttribute("synthua:rig:type").Get() == "cctv"
    assert cctv.GetAttribute("synthua:rig:height_m").Get() == 6.0
    assert [str(p) for p in cctv.GetRelationship("synthua:rig:target").GetTargets()] == ["/World/Agents/Agent_0001"]
    assert cctv.GetAttribute("synthua:distortion:model").Get() == "brown_conrady"
    assert cctv.GetAttribute("synthua:distortion:k1").Get() == -0.1
    rider = stage.GetPrimAtPath("/World/Cameras/WC")
    assert [str(p) for p in rider.GetRelationship("synthua:rig:rides_with").GetTargets()] == ["/World/Agents/Agent_0003"]
    assert not rider.GetAttribute("synthua:distortion:model")  # no distortion: nothing authored
    for prim in (cctv, rider):
        assert camera_findings(prim, Usd.TimeCode(1), 1.0) == []


def test_validation_reports_bad_distortion_attributes(stage):
    prim = stage.GetPrimAtPath("/World/Cameras/CCTV_A")
    prim.GetAttribute("synthua:distortion:k1").Set(-5.0)
    prim.GetAttribute("synthua:distortion:model").Set("fisheye")
    try:
        messages = [f.message for f in camera_findings(prim, Usd.TimeCode(1), 1.0)]
    finally:
        prim.GetAttribute("synthua:distortion:k1").Set(-0.1)
        prim.GetAttribute("synthua:distortion:model").Set("brown_conrady")
    assert messages == ["synthua:distortion:model is 'fisheye'; expected 'brown_conrady'"]
    prim.GetAttribute("synthua:distortion:k1").Set(-5.0)
    try:
        messages = [f.message for f in camera_findings(prim, Usd.TimeCode(1), 1.0)]
    finally:
        prim.GetAttribute("synthua:distortion:k1").Set(-0.1)
    assert len(messages) == 1 and "has no inverse" in messages[0]
