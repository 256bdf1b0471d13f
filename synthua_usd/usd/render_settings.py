"""Reading UsdRender settings: the defaults a render takes when the command line leaves them out."""

from __future__ import annotations

from dataclasses import dataclass

from pxr import Usd, UsdGeom, UsdRender

from synthua_usd.core.errors import echo
from synthua_usd.core.findings import Finding
from synthua_usd.model.render_config import MAX_SIDE, MAX_SPP
from synthua_usd.usd.prim_checks import raise_first_error


@dataclass(frozen=True)
class StageRenderDefaults:
    settings_path: str | None = None
    camera_path: str | None = None
    resolution: tuple[int, int] | None = None
    spp: int | None = None
    var_names: tuple[str, ...] = ()

    def render_values(self) -> dict:
        """What the settings say of a render, as :func:`synthua_usd.model.render_config.resolve_render`'s
        ``stage`` source: width, height and spp, None where the stage authors none."""
        width, height = self.resolution or (None, None)
        return {"width": width, "height": height, "spp": self.spp}


def settings_findings(settings: UsdRender.Settings, rule: str = "render-settings") -> list[Finding]:
    """Render settings name cameras that exist, a resolution in range and a sample count in range."""
    stage = settings.GetPrim().GetStage()
    where = str(settings.GetPath())
    out = []
    for target in settings.GetCameraRel().GetForwardedTargets():
        cam = stage.GetPrimAtPath(target)
        if not cam or not cam.IsA(UsdGeom.Camera):
            out.append(Finding(rule, where, f"camera relationship targets {target}, which is not a camera in this "
                                            f"stage; expected a UsdGeom.Camera"))
    res = settings.GetResolutionAttr().Get()
    if res is not None and not all(0 < int(v) <= MAX_SIDE for v in res):
        out.append(Finding(rule, where, f"resolution is {tuple(res)}; expected width and height in 1..{MAX_SIDE}"))
    spp = settings.GetPrim().GetAttribute("synthua:spp")
    if spp and spp.HasAuthoredValue() and not (isinstance(spp.Get(), int) and 1 <= spp.Get() <= MAX_SPP):
        out.append(Finding(rule, where, f"synthua:spp is {echo(spp.Get())}; expected an integer in 1..{MAX_SPP}"))
    return out


def render_defaults(stage: Usd.Stage) -> StageRenderDefaults:
    """From the stage's ``renderSettingsPrimPath`` (or its only RenderSettings prim), if any. Raises
    :class:`StageError` for the first error of :func:`settings_findings` (validation reports them all)."""
    path = stage.GetMetadataByDictKey("customLayerData", "renderSettingsPrimPath")
    settings = UsdRender.Settings.Get(stage, path) if path else None
    if not settings:
        found = [p for p in stage.Traverse() if p.IsA(UsdRender.Settings)]
        if len(found) != 1:
            return StageRenderDefaults()
        settings = UsdRender.Settings(found[0])
    raise_first_error(settings_findings(settings))
    cams = settings.GetCameraRel().GetForwardedTargets()
    res = settings.GetResolutionAttr().Get()
    spp_attr = settings.GetPrim().GetAttribute("synthua:spp")
    var_names = []
    for product_path in settings.GetProductsRel().GetForwardedTargets():
        product = UsdRender.Product(stage.GetPrimAtPath(product_path))
        if product:
            var_names += [t.name for t in product.GetOrderedVarsRel().GetForwardedTargets()]
    return StageRenderDefaults(settings_path=str(settings.GetPath()), camera_path=str(cams[0]) if cams else None,
                               resolution=(int(res[0]), int(res[1])) if res else None,
                               spp=int(spp_attr.Get()) if spp_attr and spp_attr.HasAuthoredValue() else None,
                               var_names=tuple(var_names))
