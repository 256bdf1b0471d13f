"""UsdGeom.Camera authoring and reading, with USD's lens units converted to millimetres.

USD measures focalLength and the apertures in tenths of a scene unit (so millimetres on a centimetre
stage, and 1/100 of the millimetre value on a metre stage). Everything outside this module uses mm.
"""

from __future__ import annotations

import numpy as np
from pxr import Gf, Usd, UsdGeom

from synthua_usd.cameras import PinholeCamera
from synthua_usd.errors import StageError
from synthua_usd.usd.prim_checks import camera_findings, lens_unit_mm, raise_first_error


def author_camera(stage: Usd.Stage, path: str, camera_to_world: np.ndarray, *, focal_length_mm: float,
                  horizontal_aperture_mm: float, vertical_aperture_mm: float, clip_near_m: float,
                  clip_far_m: float, meters_per_unit: float, doc: str = "") -> UsdGeom.Camera:
    """Define a perspective camera. ``camera_to_world`` (4, 4), column-vector convention, metres."""
    unit = lens_unit_mm(meters_per_unit)
    cam = UsdGeom.Camera.Define(stage, path)
    cam.CreateProjectionAttr(UsdGeom.Tokens.perspective)
    cam.CreateFocalLengthAttr(focal_length_mm / unit)
    cam.CreateHorizontalApertureAttr(horizontal_aperture_mm / unit)
    cam.CreateVerticalApertureAttr(vertical_aperture_mm / unit)
    cam.CreateClippingRangeAttr(Gf.Vec2f(clip_near_m / meters_per_unit, clip_far_m / meters_per_unit))
    # Gf matrices are row-vector (translation in the last row): the transpose of ours.
    cam.AddTransformOp().Set(Gf.Matrix4d(np.asarray(camera_to_world, float).T.tolist()))
    if doc:
        cam.GetPrim().SetDocumentation(doc)
    return cam


def camera_paths(stage: Usd.Stage) -> list[str]:
    """Paths of every camera in the stage, in traversal order."""
    return [str(p.GetPath()) for p in stage.Traverse() if p.IsA(UsdGeom.Camera)]


def read_camera(stage: Usd.Stage, path: str, time_code: float) -> PinholeCamera:
    """The camera at ``path`` at ``time_code`` in mm and world metres.

    Raises :class:`StageError` for a missing prim, a prim that is not a camera, or any error of
    :func:`synthua_usd.usd.prim_checks.camera_findings` (the check ``synthua validate stage`` runs too).
    """
    prim = stage.GetPrimAtPath(path) if path.startswith("/") else Usd.Prim()
    if not prim or not prim.IsActive():
        known = ", ".join(camera_paths(stage)) or "none"
        raise StageError(f"{stage.GetRootLayer().identifier}: no camera at '{path}'; cameras in the stage: {known}")
    if not prim.IsA(UsdGeom.Camera):
        raise StageError(f"{path}: prim of type '{prim.GetTypeName()}' is not a UsdGeom.Camera")
    cam = UsdGeom.Camera(prim)
    t = Usd.TimeCode(time_code)
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    raise_first_error(camera_findings(prim, t, mpu))
    unit = lens_unit_mm(mpu)
    near, far = cam.GetClippingRangeAttr().Get(t)
    m = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(t), float).T
    m[:3, 3] *= mpu
    return PinholeCamera(path=path, focal_length_mm=float(cam.GetFocalLengthAttr().Get(t)) * unit,
                         horizontal_aperture_mm=float(cam.GetHorizontalApertureAttr().Get(t)) * unit,
                         vertical_aperture_mm=float(cam.GetVerticalApertureAttr().Get(t)) * unit,
                         clip_near_m=float(near) * mpu, clip_far_m=float(far) * mpu, camera_to_world=m)
