"""A small scene for tests of authored normals: an icosphere under a scaled, turned transform."""

from __future__ import annotations

import numpy as np
from pxr import Sdf


def sphere_stage(path, normals: str | None, scale=(2.0, 1.0, 1.0), rotate_deg: float = 30.0):
    """An icosphere mesh (radius 1, labelled, under a scaled and turned Xform) with its analytic normals authored as
    ``normals`` ('vertex', 'faceVarying', 'primvar' for primvars:normals per vertex, 'bad' for zero vectors, or
    None) on a Z-up metre stage with a sky."""
    import trimesh
    from pxr import Gf, Usd, UsdGeom, UsdLux, UsdSemantics, Vt

    sphere = trimesh.creation.icosphere(2)
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, "Z")
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetDefaultPrim(UsdGeom.Xform.Define(stage, "/World").GetPrim())
    holder = UsdGeom.Xform.Define(stage, "/World/Holder")
    holder.AddRotateZOp().Set(rotate_deg)
    holder.AddScaleOp().Set(Gf.Vec3f(*scale))
    mesh = UsdGeom.Mesh.Define(stage, "/World/Holder/Ball")
    UsdSemantics.LabelsAPI.Apply(mesh.GetPrim(), "synthua").CreateLabelsAttr(["building"])
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(sphere.vertices.astype(np.float32)))
    mesh.CreateFaceVertexCountsAttr([3] * len(sphere.faces))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(sphere.faces.ravel().astype(np.int32)))
    mesh.CreateSubdivisionSchemeAttr("none")
    unit = (sphere.vertices / np.linalg.norm(sphere.vertices, axis=1, keepdims=True)).astype(np.float32)
    if normals == "vertex":
        mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(unit))
        mesh.SetNormalsInterpolation("vertex")
    elif normals == "faceVarying":
        mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(unit[sphere.faces.ravel()]))
        mesh.SetNormalsInterpolation("faceVarying")
    elif normals == "primvar":
        UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("normals", Sdf.ValueTypeNames.Normal3fArray, "vertex").Set(
            Vt.Vec3fArray.FromNumpy(unit))
    elif normals == "bad":
        mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(np.zeros_like(unit)))
        mesh.SetNormalsInterpolation("vertex")
    UsdLux.DomeLight.Define(stage, "/World/Sky")
    stage.GetRootLayer().Save()
    return stage
