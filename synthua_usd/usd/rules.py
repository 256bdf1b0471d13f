"""Stage validation: OpenUSD's own UsdValidation validators plus synthua's rules.

Each rule is a small object with a name and ``check(context) -> list[Finding]``; rules collect findings
and never raise on a bad stage. The CLI decides what is fatal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pxr import Usd, UsdGeom, UsdRender, UsdSemantics, UsdValidation

from synthua_usd.findings import Finding, Severity
from synthua_usd.taxonomy import ClassMap
from synthua_usd.usd.cameras import lens_unit_mm
from synthua_usd.usd.semantics import label_sites, renderable_gprims

#: Plausible physical lens values; outside them the authored numbers are probably in the wrong unit.
FOCAL_RANGE_MM = (1.0, 2000.0)
APERTURE_RANGE_MM = (1.0, 100.0)


@dataclass(frozen=True)
class RuleContext:
    stage: Usd.Stage
    class_map: ClassMap

    @property
    def root(self) -> str:
        return self.stage.GetRootLayer().identifier


class UsdValidationRule:
    """Every validator registered with OpenUSD's UsdValidation (usdGeom, usdShade, usdLux, usdSkel, ...)."""

    name = "usd-validation"
    _SEVERITY = {UsdValidation.ValidationErrorType.Error: Severity.ERROR,
                 UsdValidation.ValidationErrorType.Warn: Severity.WARNING,
                 UsdValidation.ValidationErrorType.Info: Severity.INFO}

    def check(self, ctx: RuleContext) -> list[Finding]:
        registry = UsdValidation.ValidationRegistry()
        context = UsdValidation.ValidationContext(registry.GetOrLoadAllValidators())
        out = []
        for error in context.Validate(ctx.stage):
            sites = [str(s.GetPrim().GetPath()) if s.IsPrim() and not s.GetPrim().IsPseudoRoot()
                     else (s.GetLayer().identifier if s.GetLayer() else "") for s in error.GetSites()]
            where = ", ".join(s for s in sites if s) or ctx.root
            validator = error.GetValidator()
            rule = validator.GetMetadata().name if validator else error.GetName()
            out.append(Finding(rule, where, error.GetMessage(), self._SEVERITY.get(error.GetType(), Severity.ERROR)))
        return out


class StageMetadataRule:
    """The metadata every synthua stage states explicitly (UsdValidation checks upAxis/metersPerUnit too)."""

    name = "stage-metadata"

    def check(self, ctx: RuleContext) -> list[Finding]:
        layer = ctx.stage.GetRootLayer()
        out = []
        if not layer.pseudoRoot.HasInfo("timeCodesPerSecond"):
            out.append(Finding(self.name, ctx.root, "timeCodesPerSecond is not stated; expected it on the root layer "
                                                    "(e.g. 24) so animation plays at a known rate"))
        mpu = UsdGeom.GetStageMetersPerUnit(ctx.stage)
        if layer.pseudoRoot.HasInfo("metersPerUnit") and not math.isclose(mpu, 1.0):
            out.append(Finding(self.name, ctx.root, f"metersPerUnit is {mpu:g}; synthua layers are authored in "
                                                    f"metres (1.0). Other units render, scaled to metres",
                               Severity.WARNING))
        return out


class GprimClassRule:
    """Every renderable gprim has exactly one class: one labelled prim on its ancestor chain, one label."""

    name = "gprim-has-one-class"

    def check(self, ctx: RuleContext) -> list[Finding]:
        tax = ctx.class_map.taxonomy
        out = []
        for prim in renderable_gprims(ctx.stage):
            path = str(prim.GetPath())
            sites = label_sites(prim, tax)
            if not sites:
                out.append(Finding(self.name, path, f"has no class: neither it nor an ancestor has "
                                                    f"semantics:labels:{tax}; label it or an ancestor"))
            elif len(sites) > 1:
                found = ", ".join(f"{s.prim_path} {list(s.labels)}" for s in sites)
                out.append(Finding(self.name, path, f"inherits labels from {len(sites)} prims ({found}); expected "
                                                    f"one labelled prim per object, remove the nested labels"))
            elif len(sites[0].labels) != 1:
                out.append(Finding(self.name, path, f"its labelled prim {sites[0].prim_path} has "
                                                    f"{len(sites[0].labels)} labels {list(sites[0].labels)}; "
                                                    f"expected exactly one"))
        return out


class LabelInClassMapRule:
    """Every label of the taxonomy names a class (or alias) of the class map."""

    name = "label-in-class-map"

    def check(self, ctx: RuleContext) -> list[Finding]:
        tax = ctx.class_map.taxonomy
        out = []
        for prim in ctx.stage.Traverse():
            if tax not in UsdSemantics.LabelsAPI.GetDirectTaxonomies(prim):
                continue
            for label in UsdSemantics.LabelsAPI(prim, tax).GetLabelsAttr().Get() or []:
                if ctx.class_map.resolve(str(label)) is None:
                    out.append(Finding(self.name, str(prim.GetPath()),
                                       f"label '{label}' is not a class of {ctx.class_map.source}; "
                                       f"use a class name or alias from it (see `synthua inspect`)"))
        return out


class CameraLensRule:
    """Cameras are perspective with positive, plausible lens values and a valid clipping range."""

    name = "camera-lens"

    def check(self, ctx: RuleContext) -> list[Finding]:
        unit = lens_unit_mm(UsdGeom.GetStageMetersPerUnit(ctx.stage))
        out = []
        for prim in ctx.stage.Traverse():
            if not prim.IsA(UsdGeom.Camera):
                continue
            path = str(prim.GetPath())
            cam = UsdGeom.Camera(prim)
            if cam.GetProjectionAttr().Get() != UsdGeom.Tokens.perspective:
                out.append(Finding(self.name, path, f"projection is '{cam.GetProjectionAttr().Get()}'; only "
                                                    f"'perspective' renders"))
            for attr, lo_hi in (("focalLength", FOCAL_RANGE_MM), ("horizontalAperture", APERTURE_RANGE_MM),
                                ("verticalAperture", APERTURE_RANGE_MM)):
                value = prim.GetAttribute(attr).Get()
                if value is None or not math.isfinite(value) or value <= 0:
                    out.append(Finding(self.name, path, f"{attr} is {value}; expected a positive value"))
                    continue
                mm = value * unit
                if not lo_hi[0] <= mm <= lo_hi[1]:
                    out.append(Finding(self.name, path,
                                       f"{attr} = {value:g} is {mm:g} mm, outside the plausible {lo_hi[0]:g}-{lo_hi[1]:g} "
                                       f"mm; USD lens values are in tenths of a scene unit ({unit:g} mm here)",
                                       Severity.WARNING))
            for attr in ("horizontalApertureOffset", "verticalApertureOffset"):
                if prim.GetAttribute(attr).Get():
                    out.append(Finding(self.name, path, f"{attr} is {prim.GetAttribute(attr).Get()}; lens shift is "
                                                        f"not supported, expected 0"))
            near, far = cam.GetClippingRangeAttr().Get()
            if not 0 < near < far:
                out.append(Finding(self.name, path, f"clippingRange is ({near:g}, {far:g}); expected 0 < near < far"))
        return out


class RenderSettingsRule:
    """UsdRender settings name an existing camera and a positive resolution."""

    name = "render-settings"

    def check(self, ctx: RuleContext) -> list[Finding]:
        out = []
        for prim in ctx.stage.Traverse():
            if not prim.IsA(UsdRender.Settings):
                continue
            settings = UsdRender.Settings(prim)
            for target in settings.GetCameraRel().GetForwardedTargets():
                cam = ctx.stage.GetPrimAtPath(target)
                if not cam or not cam.IsA(UsdGeom.Camera):
                    out.append(Finding(self.name, str(prim.GetPath()), f"camera relationship targets {target}, "
                                                                       f"which is not a camera in this stage"))
            res = settings.GetResolutionAttr().Get()
            if res is not None and (res[0] <= 0 or res[1] <= 0):
                out.append(Finding(self.name, str(prim.GetPath()), f"resolution is {tuple(res)}; expected positive"))
        return out


DEFAULT_RULES = (UsdValidationRule(), StageMetadataRule(), GprimClassRule(), LabelInClassMapRule(),
                 CameraLensRule(), RenderSettingsRule())


def validate_stage(stage: Usd.Stage, class_map: ClassMap, rules=DEFAULT_RULES) -> list[Finding]:
    ctx = RuleContext(stage, class_map)
    return [f for rule in rules for f in rule.check(ctx)]
