"""Stage validation: OpenUSD's own UsdValidation validators plus synthua's rules.

Each rule is a small object with a name and ``check(context) -> list[Finding]``; rules collect findings
and never raise on a bad stage. The CLI decides what is fatal. Rules about what render refuses run the
very checks the reader runs (:mod:`synthua_usd.usd.prim_checks`), so validation and render agree; and when
the rules find no error, the reader itself reads the stage at its start time code (:class:`RenderReadsRule`),
so that nothing render refuses there passes validation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pxr import Gf, Usd, UsdGeom, UsdLux, UsdRender, UsdValidation

from synthua_usd.core.errors import SynthuaError
from synthua_usd.core.findings import Finding, Severity
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.usd.prim_checks import (SHAPE_PARAMETERS, camera_findings, label_findings, mesh_topology,
                                        shape_findings)
from synthua_usd.usd.reader import read_snapshot, unsupported_gprim_message, unsupported_light_message
from synthua_usd.usd.render_settings import settings_findings
from synthua_usd.usd.semantics import direct_labels, label_sites, renderable_gprims


@dataclass(frozen=True)
class RuleContext:
    stage: Usd.Stage
    class_map: ClassMap

    @property
    def root(self) -> str:
        return self.stage.GetRootLayer().identifier

    @property
    def start(self) -> Usd.TimeCode:
        """The time code render reads by default: the stage's start, or the default time of a static stage."""
        return Usd.TimeCode(self.stage.GetStartTimeCode()) if self.stage.HasAuthoredTimeCodeRange() \
            else Usd.TimeCode.Default()

    def prims(self) -> list[Usd.Prim]:
        """Every prim of the stage, those of instance prototypes included (once each)."""
        return list(self.stage.Traverse()) + [p for proto in self.stage.GetPrototypes() for p in Usd.PrimRange(proto)]


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
    """Every renderable gprim has one labelled prim on its ancestor chain (how many labels that prim holds
    is :class:`LabelInClassMapRule`'s concern)."""

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
        return out


class LabelInClassMapRule:
    """Every labelled prim holds one label of the taxonomy, naming a class (or alias) of the class map."""

    name = "label-in-class-map"

    def check(self, ctx: RuleContext) -> list[Finding]:
        out = []
        for prim in ctx.stage.Traverse():
            labels = direct_labels(prim, ctx.class_map.taxonomy)
            if labels is not None:
                out += label_findings(str(prim.GetPath()), labels, ctx.class_map, self.name)
        return out


class MeshTopologyRule:
    """Renderable meshes have consistent faces and finite points (what the reader refuses)."""

    name = "mesh-topology"

    def check(self, ctx: RuleContext) -> list[Finding]:
        out = []
        for prim in renderable_gprims(ctx.stage):
            if prim.IsA(UsdGeom.Mesh):
                out += mesh_topology(prim, ctx.start, self.name)[0]
        return out


class GprimShapeRule:
    """Implicit gprims (Cube, Sphere, Cylinder, Cone, Capsule) have finite, positive sizes (what the reader
    refuses): a negative radius turns the sphere inside out, a NaN size has no surface."""

    name = "gprim-shape"

    def check(self, ctx: RuleContext) -> list[Finding]:
        return [f for prim in renderable_gprims(ctx.stage) for f in shape_findings(prim, ctx.start, self.name)]


def _numbers(value) -> np.ndarray | None:
    """The numbers of a scalar, vector, matrix or quaternion value as a float array; None for anything else
    (tokens, strings, asset paths, booleans)."""
    if value is None or isinstance(value, (bool, str)):
        return None
    if isinstance(value, (Gf.Quatd, Gf.Quatf, Gf.Quath)):
        return np.array([value.GetReal(), *value.GetImaginary()], float)
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None


class FiniteValuesRule:
    """Every authored number that is not an array (transform operations, sizes, lens values, light and
    material inputs), by default and at every time sample, is finite (a custom attribute's may be infinite,
    never NaN): a NaN translate or light intensity renders nothing, or NaN pixels, at some time code.
    (Arrays: :class:`MeshTopologyRule`.)"""

    name = "finite-values"

    def check(self, ctx: RuleContext) -> list[Finding]:
        out = []
        for prim in ctx.prims():
            shape = {name for name, _ in SHAPE_PARAMETERS.get(prim.GetTypeName(), ())}  # GprimShapeRule's
            for attr in prim.GetAttributes():
                if attr.GetTypeName().isArray or not attr.HasAuthoredValue() or attr.GetName() in shape:
                    continue
                finding = self._first_bad_value(attr)
                if finding:
                    out.append(Finding(self.name, str(prim.GetPath()), finding))
        return out

    @staticmethod
    def _first_bad_value(attr: Usd.Attribute) -> str | None:
        # A custom attribute may say "unbounded" with infinity (synthua:condition:fogVisibilityM = inf: no fog);
        # a schema attribute, and NaN anywhere, may not.
        custom = attr.IsCustom()
        for t in [Usd.TimeCode.Default()] + [Usd.TimeCode(t) for t in attr.GetTimeSamples()]:
            value = attr.Get(t)
            numbers = _numbers(value)
            if numbers is not None and (np.isnan(numbers).any() if custom else not np.isfinite(numbers).all()):
                when = "by default" if t.IsDefault() else f"at time code {t.GetValue():g}"
                return f"{attr.GetName()} is {value} {when}; expected {'numbers' if custom else 'finite numbers'}"
        return None


class SupportedPrimRule:
    """Every renderable gprim and every light is of a type the translator handles."""

    name = "supported-prim"

    def check(self, ctx: RuleContext) -> list[Finding]:
        out = [Finding(self.name, str(p.GetPath()), unsupported_gprim_message(p))
               for p in renderable_gprims(ctx.stage) if unsupported_gprim_message(p)]
        out += [Finding(self.name, str(p.GetPath()), unsupported_light_message(p))
                for p in ctx.stage.Traverse() if p.HasAPI(UsdLux.LightAPI) and unsupported_light_message(p)]
        return out


class CameraLensRule:
    """Cameras are perspective with positive, plausible lens values and a valid clipping range."""

    name = "camera-lens"

    def check(self, ctx: RuleContext) -> list[Finding]:
        mpu = UsdGeom.GetStageMetersPerUnit(ctx.stage)
        return [f for prim in ctx.stage.Traverse() if prim.IsA(UsdGeom.Camera)
                for f in camera_findings(prim, ctx.start, mpu, self.name)]


class RenderSettingsRule:
    """UsdRender settings name an existing camera and a positive resolution."""

    name = "render-settings"

    def check(self, ctx: RuleContext) -> list[Finding]:
        return [f for prim in ctx.stage.Traverse() if prim.IsA(UsdRender.Settings)
                for f in settings_findings(UsdRender.Settings(prim), self.name)]


class RenderableRule:
    """What render needs besides valid prims: at least one renderable gprim and one camera."""

    name = "renderable"

    def check(self, ctx: RuleContext) -> list[Finding]:
        out = []
        if not renderable_gprims(ctx.stage):
            out.append(Finding(self.name, ctx.root, "has no renderable geometry (no visible Mesh, Cube, Sphere, "
                                                    "Cylinder, Cone or Capsule); expected a twin to render"))
        if not any(p.IsA(UsdGeom.Camera) for p in ctx.stage.Traverse()):
            out.append(Finding(self.name, ctx.root, "has no camera; expected a UsdGeom.Camera to render from "
                                                    "(author one, or compose a cameras layer)"))
        return out


class RenderReadsRule:
    """The reader render runs reads the stage at its start time code: whatever it refuses that no rule above
    names (a lamp role, keypoints, more instances than the instance map holds, ...) is a finding in its words."""

    name = "render-reads"

    def check(self, ctx: RuleContext) -> list[Finding]:
        try:
            read_snapshot(ctx.stage, ctx.stage.GetStartTimeCode(), ctx.class_map)
        except SynthuaError as exc:
            text = str(exc)
            where, _, message = text.partition(": ") if text.startswith("/") else (ctx.root, "", text)
            return [Finding(self.name, where, message or text)]
        return []


DEFAULT_RULES = (UsdValidationRule(), StageMetadataRule(), GprimClassRule(), LabelInClassMapRule(),
                 MeshTopologyRule(), GprimShapeRule(), FiniteValuesRule(), SupportedPrimRule(), CameraLensRule(),
                 RenderSettingsRule(), RenderableRule())


def validate_stage(stage: Usd.Stage, class_map: ClassMap, rules=DEFAULT_RULES,
                   last=RenderReadsRule()) -> list[Finding]:
    """The findings of ``rules``, then, when none is an error, of ``last`` (the reader's own read, which stops
    at its first refusal: it would only repeat an error the rules already name)."""
    ctx = RuleContext(stage, class_map)
    findings = [f for rule in rules for f in rule.check(ctx)]
    if last is not None and not any(f.severity is Severity.ERROR for f in findings):
        findings += last.check(ctx)
    return findings
