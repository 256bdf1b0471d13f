"""Reading UsdRender settings: the defaults a render takes when the command line leaves them out."""

from __future__ import annotations

from dataclasses import dataclass

from pxr import Usd, UsdRender


@dataclass(frozen=True)
class StageRenderDefaults:
    settings_path: str | None = None
    camera_path: str | None = None
    resolution: tuple[int, int] | None = None
    spp: int | None = None
    var_names: tuple[str, ...] = ()


def render_defaults(stage: Usd.Stage) -> StageRenderDefaults:
    """From the stage's ``renderSettingsPrimPath`` (or its only RenderSettings prim), if any."""
    path = stage.GetMetadataByDictKey("customLayerData", "renderSettingsPrimPath")
    settings = UsdRender.Settings.Get(stage, path) if path else None
    if not settings:
        found = [p for p in stage.Traverse() if p.IsA(UsdRender.Settings)]
        if len(found) != 1:
            return StageRenderDefaults()
        settings = UsdRender.Settings(found[0])
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
