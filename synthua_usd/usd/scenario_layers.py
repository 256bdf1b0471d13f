"""Layers every scenario needs besides its twin: environment (UsdLux), render settings (UsdRender), and an
automatic camera rig for twins that come without cameras (imports)."""

from __future__ import annotations

import numpy as np
from pxr import Gf, Kind, Sdf, Usd, UsdGeom, UsdLux, UsdRender

from synthua_usd import geometry as geo
from synthua_usd.cameras import CameraRig
from synthua_usd.usd.authoring import StageMetadata, define_xform, new_layer
from synthua_usd.usd.cameras import author_camera


def build_environment(meta: StageMetadata) -> Usd.Stage:
    """Clear day: a sun 50 degrees high in the south-east and a uniform blue-grey sky."""
    stage = new_layer(meta, "Clear-day sun and sky (UsdLux).")
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, "/World/Environment", kind=Kind.Tokens.group)
    sun = UsdLux.DistantLight.Define(stage, "/World/Environment/Sun")
    sun.CreateIntensityAttr(3.0)
    sun.CreateAngleAttr(0.53)
    sun.CreateColorAttr(Gf.Vec3f(1.0, 0.96, 0.9))
    # A distant light shines down its local -Z axis: tilt it 40 degrees off vertical, then turn it.
    sun_xf = UsdGeom.Xformable(sun.GetPrim())
    sun_xf.AddRotateZOp().Set(-35.0)
    sun_xf.AddRotateXOp().Set(40.0)
    sky = UsdLux.DomeLight.Define(stage, "/World/Environment/Sky")
    sky.CreateIntensityAttr(0.6)
    sky.CreateColorAttr(Gf.Vec3f(0.75, 0.85, 1.0))
    return stage


RENDER_VARS = (
    # name, sourceName, sourceType, dataType
    ("rgb", "LdrColor", "raw", "color3f"),
    ("class_id", "synthua:class_id", "primvar", "int"),
    ("instance_id", "synthua:instance_id", "primvar", "int"),
    ("depth", "depth", "raw", "float"),
)


def build_render_settings(meta: StageMetadata, camera: str = "/World/Cameras/CCTV",
                          resolution: tuple[int, int] = (1280, 960)) -> Usd.Stage:
    stage = new_layer(meta, "UsdRender settings, product and AOVs.")
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    stage.DefinePrim("/Render", "Scope")
    settings = UsdRender.Settings.Define(stage, "/Render/Settings")
    settings.CreateResolutionAttr(Gf.Vec2i(*resolution))
    settings.CreateCameraRel().SetTargets([Sdf.Path(camera)])
    settings.CreateAspectRatioConformPolicyAttr(UsdRender.Tokens.expandAperture)
    settings.GetPrim().CreateAttribute("synthua:spp", Sdf.ValueTypeNames.Int, custom=True).Set(64)
    product = UsdRender.Product.Define(stage, "/Render/Products/Frame")
    product.CreateProductNameAttr("frame")
    var_paths = []
    for name, source, source_type, data_type in RENDER_VARS:
        var = UsdRender.Var.Define(stage, f"/Render/Vars/{name}")
        var.CreateSourceNameAttr(source)
        var.CreateSourceTypeAttr(source_type)
        var.CreateDataTypeAttr(data_type)
        var_paths.append(var.GetPath())
    product.CreateOrderedVarsRel().SetTargets(var_paths)
    settings.CreateProductsRel().SetTargets([product.GetPath()])
    stage.GetRootLayer().customLayerData = {"renderSettingsPrimPath": "/Render/Settings"}
    return stage


def build_overview_cameras(meta: StageMetadata, bounds_min, bounds_max, street_point=None,
                           street_direction=(1.0, 0.0)) -> Usd.Stage:
    """Cameras for a twin of any size: ``Overview`` (oblique, 45 degrees down, whole extent in view) and
    ``Street`` (1.6 m above ``street_point``, default the centre, looking along ``street_direction``).
    Full-frame 24 mm lenses."""
    lo, hi = np.asarray(bounds_min, float), np.asarray(bounds_max, float)
    centre = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi[:2] - lo[:2])) / 2, 1.0)
    # 24 mm on 36 x 24 mm sees ~74 x 53 degrees; 1.4 radii away the extent's circle fits at 45 degrees.
    dist = 1.4 * radius
    eye = centre + np.array([-dist * 0.5, -dist * 0.5, dist * 0.7071])
    stage = new_layer(meta, "Automatic cameras for an imported twin.")
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, "/World/Cameras", kind=Kind.Tokens.group)
    far = float(4 * dist + 1000)
    author_camera(stage, "/World/Cameras/Overview", geo.look_at(eye, centre), focal_length_mm=24,
                  horizontal_aperture_mm=36, vertical_aperture_mm=24, clip_near_m=0.5, clip_far_m=far,
                  meters_per_unit=meta.meters_per_unit, doc="Oblique overview of the whole twin.")
    ground = np.asarray(street_point if street_point is not None else (centre[0], centre[1], lo[2]), float)
    street_eye = ground + [0.0, 0.0, 1.6]
    d = np.asarray(street_direction, float)[:2]
    d = d / (np.linalg.norm(d) or 1.0)
    author_camera(stage, "/World/Cameras/Street", geo.look_at(street_eye, street_eye + [10 * d[0], 10 * d[1], -0.5]),
                  focal_length_mm=24, horizontal_aperture_mm=36, vertical_aperture_mm=24, clip_near_m=0.05,
                  clip_far_m=far, meters_per_unit=meta.meters_per_unit, doc="Eye level at the twin's centre.")
    return stage


def build_camera_layer(meta: StageMetadata, rigs: tuple[CameraRig, ...], doc: str) -> Usd.Stage:
    """A cameras layer: every rig as ``/World/Cameras/<name>``."""
    stage = new_layer(meta, doc)
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, "/World/Cameras", kind=Kind.Tokens.group)
    for rig in rigs:
        author_camera(stage, f"/World/Cameras/{rig.name}", geo.look_at(rig.eye, rig.target),
                      focal_length_mm=rig.focal_length_mm, horizontal_aperture_mm=rig.horizontal_aperture_mm,
                      vertical_aperture_mm=rig.vertical_aperture_mm, clip_near_m=rig.clip_near_m,
                      clip_far_m=rig.clip_far_m, meters_per_unit=meta.meters_per_unit, doc=rig.doc)
    return stage
