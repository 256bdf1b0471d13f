"""The thin layers of a scenario: cameras (UsdGeom), environment (conditions and UsdLux) and render settings
(UsdRender)."""

from __future__ import annotations

from pxr import Gf, Kind, Sdf, Usd, UsdGeom, UsdLux, UsdRender

from synthua_usd.composition.scenario import CAMERAS_ROOT, ENVIRONMENT_PATH, Environment, StageMetadata
from synthua_usd.core.outputs import select_outputs
from synthua_usd.model import meshes as geo
from synthua_usd.model.cameras import CONFORM_EXPAND, CameraSpec
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.usd.authoring import define_xform, new_layer
from synthua_usd.usd.cameras import author_camera
from synthua_usd.usd.conditions import SKY, SUN, author_conditions

RENDER_SETTINGS_PATH = "/Render/Settings"


def build_environment(meta: StageMetadata, env: Environment) -> Usd.Stage:
    """``/World/Environment`` with its ``condition`` variant set (:mod:`synthua_usd.usd.conditions`), a
    ``DistantLight`` sun and a uniform ``DomeLight`` sky that each variant poses for viewers."""
    stage = new_layer(meta, f"Environment: the conditions {', '.join(c.name for c in env.conditions)} "
                            f"(variant set 'condition', default '{env.default}'); UsdLux sun and sky.")
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, ENVIRONMENT_PATH, kind=Kind.Tokens.group)
    sun = UsdLux.DistantLight.Define(stage, f"{ENVIRONMENT_PATH}/{SUN}")
    sun.CreateAngleAttr(0.53)
    sun_xf = UsdGeom.Xformable(sun.GetPrim())
    sun_xf.AddRotateZOp()
    sun_xf.AddRotateXOp()
    UsdLux.DomeLight.Define(stage, f"{ENVIRONMENT_PATH}/{SKY}").CreateColorAttr(Gf.Vec3f(0.75, 0.85, 1.0))
    author_conditions(stage, env.conditions, env.default)
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
                      clip_far_m=cam.clip_far_m, meters_per_unit=meta.meters_per_unit, doc=cam.doc,
                      rig_type=cam.rig_type)
    return stage
