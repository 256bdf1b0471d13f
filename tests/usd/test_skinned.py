"""Time-sampled skinned characters cannot be posed by the reader: it says so instead of showing the bind pose
silently."""

import numpy as np
from pxr import Gf, Usd, UsdGeom, UsdSkel, Vt

from synthua_usd.usd.reader import StageReader, animated_skins


def _skinned_stage(path, animated: bool):
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(2)
    UsdGeom.Xform.Define(stage, "/World")
    root = UsdSkel.Root.Define(stage, "/World/Character")
    skel = UsdSkel.Skeleton.Define(stage, "/World/Character/Skel")
    skel.CreateJointsAttr(["hip"])
    skel.CreateBindTransformsAttr(Vt.Matrix4dArray([Gf.Matrix4d(1)]))
    skel.CreateRestTransformsAttr(Vt.Matrix4dArray([Gf.Matrix4d(1)]))
    anim = UsdSkel.Animation.Define(stage, "/World/Character/Skel/Walk")
    anim.CreateJointsAttr(["hip"])
    anim.CreateTranslationsAttr().Set(Vt.Vec3fArray([Gf.Vec3f(0, 0, 0)]), 1)
    if animated:
        anim.GetTranslationsAttr().Set(Vt.Vec3fArray([Gf.Vec3f(1, 0, 0)]), 2)
    anim.CreateRotationsAttr().Set(Vt.QuatfArray([Gf.Quatf(1)]))
    anim.CreateScalesAttr().Set(Vt.Vec3hArray([Gf.Vec3h(1, 1, 1)]))
    UsdSkel.BindingAPI.Apply(skel.GetPrim()).CreateAnimationSourceRel().SetTargets([anim.GetPath()])
    mesh = UsdGeom.Mesh.Define(stage, "/World/Character/Body")
    mesh.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (0, 1, 0)])
    mesh.CreateFaceVertexCountsAttr([3])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2])
    binding = UsdSkel.BindingAPI.Apply(mesh.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skel.GetPath()])
    binding.CreateJointIndicesPrimvar(constant=True).Set([0])
    binding.CreateJointWeightsPrimvar(constant=True).Set([1.0])
    stage.GetRootLayer().Save()
    return stage, root


def test_animated_skin_is_reported(tmp_path, class_map, caplog):
    stage, _ = _skinned_stage(tmp_path / "walk.usda", animated=True)
    assert animated_skins(stage) == [("/World/Character", "/World/Character/Skel/Walk", ["/World/Character/Body"])]
    with caplog.at_level("WARNING"):
        StageReader(stage, class_map).snapshot(1)
    assert "skinned meshes (e.g. /World/Character/Body) are animated by /World/Character/Skel/Walk" in caplog.text
    assert "bind pose" in caplog.text


def test_a_still_skin_is_not_reported(tmp_path):
    stage, _ = _skinned_stage(tmp_path / "still.usda", animated=False)
    assert animated_skins(stage) == []


def test_camera_auto_frames_the_bind_pose_that_renders(tmp_path, class_map):
    """At time code 2 the animation moves the skeleton 1 m along x; the mesh renders in its bind pose. The auto
    camera frames the mesh as rendered (before: the skeleton's animated bound, a point at (1, 0, 0))."""
    from synthua_usd.usd.cameras import author_auto_camera, read_camera

    stage, _ = _skinned_stage(tmp_path / "walk.usda", animated=True)
    camera = read_camera(stage, author_auto_camera(stage, 2), 2)
    points = StageReader(stage, class_map).snapshot(2).meshes[0].points
    pixels, depth = camera.project(points, 64, 48)
    assert (depth > 0).all() and (pixels >= 0).all() and (pixels[:, 0] < 64).all() and (pixels[:, 1] < 48).all()
    assert np.ptp(pixels[:, 0]) > 20  # the triangle fills the view, not a corner of it
