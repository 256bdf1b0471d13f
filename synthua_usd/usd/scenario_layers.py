"""The thin layers of a scenario: cameras (UsdGeom), environment (UsdLux) and render settings (UsdRender)."""

from __future__ import annotations

from pxr import Gf, Kind, Sdf, Usd, UsdGeom, UsdLux, UsdRender

from synthua_usd import geometry as geo
from synthua_usd.cameras import CONFORM_EXPAND, CameraSpec
from synthua_usd.outputs import select_outputs
from synthua_usd.render_config import RenderConfig
from synthua_usd.scenario import CAMERAS_ROOT, Environment, StageMetadata
from synthua_usd.usd.authoring import define_xform, new_layer
from synthua_usd.usd.cameras import author_camera

RENDER_SETTINGS_PATH = "/Render/Settings"


def build_environment(meta: StageMetadata, env: Environment) -> Usd.Stage:
    """The sun as a ``DistantLight`` and the sky as a uniform ``DomeLight`` under ``/World/Environment``."""
    stage = new_layer(meta, f"Environment '{env.name}': sun and sky (UsdLux).")
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, "/World/Environment", kind=Kind.Tokens.group)
    sun = UsdLux.DistantLight.Define(stage, "/World/Environment/Sun")
    sun.CreateIntensityAttr(env.sun_intensity)
    sun.CreateAngleAttr(env.sun_angle_deg)
    sun.CreateColorAttr(Gf.Vec3f(*env.sun_color))
    # A distant light shines down its local -Z axis: tilt it off vertical, then turn it.
    sun_xf = UsdGeom.Xformable(sun.GetPrim())
    sun_xf.AddRotateZOp().Set(env.sun_turn_deg)
    sun_xf.AddRotateXOp().Set(env.sun_tilt_deg)
    sky = UsdLux.DomeLight.Define(stage, "/World/Environment/Sky")
    sky.CreateIntensityAttr(env.sky_intensity)
    sky.CreateColorAttr(Gf.Vec3f(*env.sky_color))
    return stage


def build_render_settings(meta: StageMetadata, camera_path: str, config: RenderConfig,
                          outputs: tuple[str, ...]) -> Usd.Stage:
    """``UsdRender`` settings (camera, resolution and spp of ``config``), one product, and a var per output."""
    stage = new_layer(meta, "UsdRender settings, product and AOVs.")
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    stage.DefinePrim("/Render", "Scope")
    settings = UsdRender.Settings.Define(stage, RENDER_SETTINGS_PATH)
    settings.CreateResolutionAttr(Gf.Vec2i(config.width, config.height))
    settings.CreateCameraRel().SetTargets([Sdf.Path(camera_path)])
    settings.CreateAspectRatioConformPolicyAttr(CONFORM_EXPAND)
    settings.GetPrim().CreateAttribute("synthua:spp", Sdf.ValueTypeNames.Int, custom=True).Set(config.spp)
    product = UsdRender.Product.Define(stage, "/Render/Products/Frame")
    product.CreateProductNameAttr("frame")
    var_paths = []
    for output in select_outputs(outputs):
        var = UsdRender.Var.Define(stage, f"/Render/Vars/{output.var}")
        var.CreateSourceNameAttr(output.source_name)
        var.CreateSourceTypeAttr(output.source_type)
        var.CreateDataTypeAttr(output.data_type)
        var_paths.append(var.GetPath())
    product.CreateOrderedVarsRel().SetTargets(var_paths)
    settings.CreateProductsRel().SetTargets([product.GetPath()])
    stage.GetRootLayer().customLayerData = {"renderSettingsPrimPath": RENDER_SETTINGS_PATH}
    return stage


def build_camera_layer(meta: StageMetadata, cameras: tuple[CameraSpec, ...], doc: str) -> Usd.Stage:
    """A cameras layer: every camera as ``/World/Cameras/<name>``."""
    stage = new_layer(meta, doc)
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, CAMERAS_ROOT, kind=Kind.Tokens.group)
    for cam in cameras:
        author_camera(stage, f"{CAMERAS_ROOT}/{cam.name}", geo.look_at(cam.eye, cam.target),
                      focal_length_mm=cam.focal_length_mm, horizontal_aperture_mm=cam.horizontal_aperture_mm,
                      vertical_aperture_mm=cam.vertical_aperture_mm, clip_near_m=cam.clip_near_m,
                      clip_far_m=cam.clip_far_m, meters_per_unit=meta.meters_per_unit, doc=cam.doc)
    return stage
