"""UsdGeom.Camera authoring and reading, with USD's lens units converted to millimetres.

USD measures focalLength and the apertures in tenths of a scene unit (so millimetres on a centimetre
stage, and 1/100 of the millimetre value on a metre stage). Everything outside this module uses mm.

Lens distortion is stored on the camera prim as custom attributes (not an applied schema: a schema would
need a plugin every reader must load, while custom attributes open anywhere): ``synthua:distortion:model
= "brown_conrady"`` and the doubles ``synthua:distortion:k1``, ``k2``, ``k3``, ``p1``, ``p2`` (OpenCV's
convention, see :mod:`synthua_usd.model.distortion`).
"""

from __future__ import annotations

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom

from synthua_usd.core.errors import StageError
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.distortion import COEFFICIENTS, MODEL, BrownConrady
from synthua_usd.usd.prim_checks import DISTORTION_PREFIX, camera_findings, lens_unit_mm, raise_first_error, read_distortion
from synthua_usd.usd.stage_io import prim_path


def author_camera(stage: Usd.Stage, path: str, camera_to_world: np.ndarray, *, focal_length_mm: float,
                  horizontal_aperture_mm: float, vertical_aperture_mm: float, clip_near_m: float,
                  clip_far_m: float, meters_per_unit: float, doc: str = "",
                  time_samples: dict[float, np.ndarray] | None = None,
                  distortion: BrownConrady | None = None, rig_type: str | None = None) -> UsdGeom.Camera:
    """Define a perspective camera. ``camera_to_world`` (4, 4), column-vector convention, metres; with
    ``time_samples`` ({time code: (4, 4)}) the transform is time-sampled instead (a moving camera);
    ``rig_type`` is authored as ``synthua:rig:type``."""
    unit = lens_unit_mm(meters_per_unit)
    cam = UsdGeom.Camera.Define(stage, path)
    cam.CreateProjectionAttr(UsdGeom.Tokens.perspective)
    cam.CreateFocalLengthAttr(focal_length_mm / unit)
    cam.CreateHorizontalApertureAttr(horizontal_aperture_mm / unit)
    cam.CreateVerticalApertureAttr(vertical_aperture_mm / unit)
    cam.CreateClippingRangeAttr(Gf.Vec2f(clip_near_m / meters_per_unit, clip_far_m / meters_per_unit))
    op = cam.AddTransformOp()
    if time_samples:
        for t, m in sorted(time_samples.items()):
            op.Set(_gf_matrix(m, meters_per_unit), Usd.TimeCode(t))
    else:
        op.Set(_gf_matrix(camera_to_world, meters_per_unit))
    if distortion is not None and not distortion.is_zero:
        author_distortion(cam.GetPrim(), distortion)
    if rig_type:
        cam.GetPrim().CreateAttribute(RIG_TYPE_ATTRIBUTE, Sdf.ValueTypeNames.Token, custom=True).Set(rig_type)
    if doc:
        cam.GetPrim().SetDocumentation(doc)
    return cam


def _gf_matrix(camera_to_world: np.ndarray, meters_per_unit: float) -> Gf.Matrix4d:
    """Our (4, 4) metres matrix as USD's: Gf matrices are row-vector (translation in the last row), the
    transpose of ours, and translations are in scene units."""
    m = np.array(camera_to_world, float)
    m[:3, 3] /= meters_per_unit
    return Gf.Matrix4d(m.T.tolist())


def author_distortion(prim: Usd.Prim, distortion: BrownConrady) -> None:
    """Store ``distortion`` on a camera prim as ``synthua:distortion:*`` custom attributes."""
    prim.CreateAttribute(DISTORTION_PREFIX + "model", Sdf.ValueTypeNames.Token, custom=True).Set(MODEL)
    for name in COEFFICIENTS:
        prim.CreateAttribute(DISTORTION_PREFIX + name, Sdf.ValueTypeNames.Double, custom=True).Set(
            getattr(distortion, name))


def camera_paths(stage: Usd.Stage) -> list[str]:
    """Paths of every camera in the stage, in traversal order."""
    return [str(p.GetPath()) for p in stage.Traverse() if p.IsA(UsdGeom.Camera)]


def read_camera(stage: Usd.Stage, path: str, time_code: float) -> PinholeCamera:
    """The camera at ``path`` at ``time_code`` in mm and world metres.

    Raises :class:`StageError` for a path that is not exactly a prim path (:func:`stage_io.prim_path`), a
    missing prim, a prim that is not a camera, or any error of
    :func:`synthua_usd.usd.prim_checks.camera_findings` (the check ``synthua validate stage`` runs too).
    """
    prim = stage.GetPrimAtPath(prim_path(path, stage.GetRootLayer().identifier, "camera"))
    if not prim or not prim.IsActive() or str(prim.GetPath()) != path:
        known = ", ".join(camera_paths(stage)) or "none"
        raise StageError(f"{stage.GetRootLayer().identifier}: no camera at '{path}'; cameras in the stage: {known}")
    if not prim.IsA(UsdGeom.Camera):
        raise StageError(f"{path}: prim of type '{prim.GetTypeName()}' is not a UsdGeom.Camera")
    cam = UsdGeom.Camera(prim)
    t = Usd.TimeCode(time_code)
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    raise_first_error(camera_findings(prim, t, mpu))
    _, distortion = read_distortion(prim, t)
    unit = lens_unit_mm(mpu)
    near, far = cam.GetClippingRangeAttr().Get(t)
    m = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(t), float).T
    m[:3, 3] *= mpu
    return PinholeCamera(path=path, focal_length_mm=float(cam.GetFocalLengthAttr().Get(t)) * unit,
                         horizontal_aperture_mm=float(cam.GetHorizontalApertureAttr().Get(t)) * unit,
                         vertical_aperture_mm=float(cam.GetVerticalApertureAttr().Get(t)) * unit,
                         clip_near_m=float(near) * mpu, clip_far_m=float(far) * mpu, camera_to_world=m,
                         distortion=distortion, exposure_ev=float(cam.GetExposureAttr().Get(t) or 0.0))


#: The rig type a camera stands for (cctv, dashcam, uav_nadir, ...: :data:`synthua_usd.composition.rigs.RIG_TYPES`).
RIG_TYPE_ATTRIBUTE = "synthua:rig:type"


def camera_rig_type(stage: Usd.Stage, path: str) -> str | None:
    """The rig type a camera was placed as (``synthua:rig:type``, see :mod:`synthua_usd.usd.rig_layer`), or
    None for a camera authored by hand."""
    attr = stage.GetPrimAtPath(path).GetAttribute(RIG_TYPE_ATTRIBUTE)
    value = attr.Get() if attr and attr.HasAuthoredValue() else None
    return str(value) if value else None


#: The path ``--camera auto`` authors its camera at, in the stage's session layer (never in the user's files).
AUTO_CAMERA_PATH = "/SynthuaAutoCamera"


def rendered_bound(stage: Usd.Stage, time_code: float) -> Gf.Range3d:
    """The world bounds (stage units) of what the reader renders at ``time_code``: every renderable gprim's
    extent computed from its own points or size (an authored ``extent`` may be stale), placed by its
    transform. Not ``BBoxCache`` of the root: for a ``SkelRoot`` it bounds the skeleton's animated pose, while
    skinned meshes render in their bind pose (the reader does not apply UsdSkel skinning), so a walking figure
    was framed where it is not drawn."""
    from synthua_usd.usd.semantics import renderable_gprims

    t = Usd.TimeCode(time_code)
    xcache = UsdGeom.XformCache(t)
    total = Gf.Range3d()
    for prim in renderable_gprims(stage, time_code):
        extent = UsdGeom.Boundable.ComputeExtentFromPlugins(UsdGeom.Boundable(prim), t)
        if extent is None or len(extent) != 2:
            continue
        box = Gf.BBox3d(Gf.Range3d(Gf.Vec3d(*extent[0]), Gf.Vec3d(*extent[1])), xcache.GetLocalToWorldTransform(prim))
        total.UnionWith(box.ComputeAlignedRange())
    return total


def author_auto_camera(stage: Usd.Stage, time_code: float) -> str:
    """Author a camera framing what the stage renders at ``time_code`` (:func:`rendered_bound`; the overview rule of
    :func:`synthua_usd.geometry.framing.overview_view`: every corner inside a full-frame 24 mm view, from the tightest
    of 16 directions) into the stage's session layer at :data:`AUTO_CAMERA_PATH`; returns the path. Y-up and
    any ``metersPerUnit`` are honoured. Raises :class:`StageError` when the stage has no bounded geometry."""
    from synthua_usd.geometry.framing import LENS_MM, overview_view
    from synthua_usd.model.meshes import look_at

    t = Usd.TimeCode(time_code)
    bound = rendered_bound(stage, time_code)
    if bound.IsEmpty():
        raise StageError(f"{stage.GetRootLayer().identifier}: --camera auto: the stage has no geometry with bounds; "
                         f"expected gprims to frame")
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    lo, hi = np.array(bound.GetMin(), float) * mpu, np.array(bound.GetMax(), float) * mpu
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    # Frame in a Z-up frame: a Y-up stage's (x, y, z) is (x, -z, y) there.
    y_up = UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
    to_stage = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]]) if y_up else np.eye(3)
    eye, target, dist = overview_view(corners @ to_stage)  # rows: (to_stage.T @ p).T = p @ to_stage
    m = np.eye(4)
    m[:3] = to_stage @ look_at(eye, target)[:3]
    size = float(np.linalg.norm(hi - lo))
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        author_camera(stage, AUTO_CAMERA_PATH, m, focal_length_mm=LENS_MM[0], horizontal_aperture_mm=LENS_MM[1],
                      vertical_aperture_mm=LENS_MM[2], clip_near_m=max(dist - size, dist / 1000),
                      clip_far_m=dist + 2 * size, meters_per_unit=mpu,
                      doc="--camera auto: frames the stage's bounds (session layer only).")
    return AUTO_CAMERA_PATH
