"""Conditions in USD: a ``condition`` variant set on the environment prim, authored and read back.

Each variant sets ``synthua:condition:*`` attributes (the fields of
:class:`synthua_usd.model.conditions.Condition`, camelCase, with their units in the name, e.g.
``double synthua:condition:fogVisibilityM = inf``) on ``/World/Environment``, and poses the prim's
``UsdLux`` ``Sun`` and ``Sky`` as a viewer's approximation of that condition (direction, a rough
intensity). synthua's renderer uses the attributes, not the approximation (see docs/rigs-and-conditions.md).

A render chooses a condition without editing any layer: :func:`condition_selected` sets the variant
selection in the stage's session layer, which is never saved, and restores it afterwards.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import fields
from typing import overload

from pxr import Gf, Sdf, Usd, UsdLux

from synthua_usd.composition.scenario import ENVIRONMENT_PATH
from synthua_usd.core.errors import InputError, StageError, echo
from synthua_usd.model.conditions import Condition, display_order
from synthua_usd.model.photometry import CCT_3000K, CD_PER_M2_PER_UNIT

VARIANT_SET = "condition"
PREFIX = "synthua:condition:"
SUN = "Sun"
SKY = "Sky"
#: The UsdLux approximation for viewers: about 90 klx of direct sun and a 0.08-unit sky at noon, in the
#: renderer's units (:mod:`synthua_usd.model.photometry`).
_VIEWER_SUN = 1.2
_VIEWER_SKY = 0.08


def attribute_name(field_name: str) -> str:
    """``synthua:condition:fogVisibilityM`` for the field ``fog_visibility_m``."""
    head, *rest = field_name.split("_")
    return PREFIX + head + "".join(word.capitalize() for word in rest)


def _value_type(value) -> Sdf.ValueTypeName:
    if isinstance(value, bool):
        return Sdf.ValueTypeNames.Bool
    if isinstance(value, str):
        return Sdf.ValueTypeNames.String
    return Sdf.ValueTypeNames.Double


_FIELDS = tuple(f.name for f in fields(Condition) if f.name != "name")


def author_conditions(stage: Usd.Stage, conditions: tuple[Condition, ...], default: str) -> None:
    """Add the ``condition`` variant set to the environment prim (with its ``Sun`` DistantLight and ``Sky``
    DomeLight already defined), one variant per condition, ``default`` selected."""
    names = [c.name for c in conditions]
    if default not in names:
        raise StageError(f"default condition '{echo(default)}' is not one of {names}")
    prim = stage.GetPrimAtPath(ENVIRONMENT_PATH)
    vset = prim.GetVariantSets().AddVariantSet(VARIANT_SET)
    for condition in conditions:
        vset.AddVariant(condition.name)
        vset.SetVariantSelection(condition.name)
        with vset.GetVariantEditContext():
            for name in _FIELDS:
                value = getattr(condition, name)
                prim.CreateAttribute(attribute_name(name), _value_type(value), custom=True).Set(value)
            _pose_viewer_lights(prim, condition)
    vset.SetVariantSelection(default)


def _pose_viewer_lights(prim: Usd.Prim, condition: Condition) -> None:
    """Tilt the distant light so that it shines from the sun's direction, and give sun and sky a rough
    strength: a DistantLight shines down its local -Z, turned by rotateZ then tilted by rotateX."""
    sun = UsdLux.DistantLight(prim.GetChild(SUN))
    sun.GetPrim().GetAttribute("xformOp:rotateX").Set(90.0 - condition.sun_elevation_deg)
    sun.GetPrim().GetAttribute("xformOp:rotateZ").Set(180.0 - condition.sun_azimuth_deg)
    if condition.sun_up:
        beam = math.exp(-condition.fog_extinction_per_m * condition.fog_top_m
                        / math.sin(math.radians(condition.sun_elevation_deg)))
        sun.CreateIntensityAttr(_VIEWER_SUN * beam)
        sun.CreateColorAttr(Gf.Vec3f(*(c / max(CCT_3000K) for c in CCT_3000K))
                            if condition.sun_elevation_deg < 10 else Gf.Vec3f(1.0, 0.96, 0.9))
        UsdLux.DomeLight(prim.GetChild(SKY)).CreateIntensityAttr(_VIEWER_SKY)
    else:
        sun.CreateIntensityAttr(0.0)
        UsdLux.DomeLight(prim.GetChild(SKY)).CreateIntensityAttr(
            condition.night_sky_luminance_cd_m2 / CD_PER_M2_PER_UNIT)


# --- reading ---------------------------------------------------------------------------------------------

def _variant_set(stage: Usd.Stage) -> Usd.VariantSet | None:
    prim = stage.GetPrimAtPath(ENVIRONMENT_PATH)
    if not prim or not prim.GetVariantSets().HasVariantSet(VARIANT_SET):
        return None
    return prim.GetVariantSets().GetVariantSet(VARIANT_SET)


def condition_names(stage: Usd.Stage) -> list[str]:
    """The conditions the stage offers (its variants, sorted by name as USD lists them); empty when none."""
    vset = _variant_set(stage)
    return list(vset.GetVariantNames()) if vset else []


def selected_condition(stage: Usd.Stage) -> str | None:
    """The condition the composed stage selects, or None when it offers none."""
    vset = _variant_set(stage)
    return (vset.GetVariantSelection() or None) if vset else None


def _stage_name(stage: Usd.Stage) -> str:
    return stage.GetRootLayer().identifier


def check_condition_name(stage: Usd.Stage, name: str) -> None:
    """Raise :class:`StageError` unless ``stage`` offers the condition ``name``; the message lists those it offers."""
    names = condition_names(stage)
    if not names:
        raise StageError(f"{_stage_name(stage)}: offers no conditions (no '{VARIANT_SET}' variant set on "
                         f"{ENVIRONMENT_PATH}); expected a scenario written by synthua create or twin import")
    if name not in names:
        raise StageError(f"{_stage_name(stage)}: no condition '{echo(name)}'; conditions in the stage: "
                         f"{', '.join(display_order(names))}")


@contextmanager
def condition_selected(stage: Usd.Stage, name: str | None):
    """Within the block, ``stage`` composes the condition ``name`` (None: leave the selection alone). The
    selection is authored in the session layer, never in the user's files, and restored on exit."""
    if name is None:
        yield
        return
    check_condition_name(stage, name)
    if _variant_set(stage).GetVariantSelection() == name:  # composed so already: nothing to author (or notify)
        yield
        return
    session = stage.GetSessionLayer()
    spec = session.GetPrimAtPath(ENVIRONMENT_PATH)
    before = dict(spec.variantSelections).get(VARIANT_SET) if spec else None
    with Usd.EditContext(stage, session):
        _variant_set(stage).SetVariantSelection(name)
    try:
        yield
    finally:
        with Usd.EditContext(stage, session):
            if before is None:
                _variant_set(stage).ClearVariantSelection()
            else:
                _variant_set(stage).SetVariantSelection(before)


@overload
def read_condition(stage: Usd.Stage, name: str) -> Condition: ...


@overload
def read_condition(stage: Usd.Stage, name: str | None = None) -> Condition | None: ...


def read_condition(stage: Usd.Stage, name: str | None = None) -> Condition | None:
    """The condition ``name`` (default: the stage's selection) as plain data, or None when the stage
    offers no conditions and none was asked for. Attributes a stage lacks take the dataclass defaults;
    values of the wrong type or out of range are a :class:`StageError` naming the attribute."""
    if name is None and _variant_set(stage) is None:
        return None
    with condition_selected(stage, name):
        prim = stage.GetPrimAtPath(ENVIRONMENT_PATH)
        chosen = _variant_set(stage).GetVariantSelection()
        if not chosen:
            raise StageError(f"{_stage_name(stage)}: {ENVIRONMENT_PATH} selects no '{VARIANT_SET}' variant; "
                             f"expected one of {', '.join(condition_names(stage))}")
        values = {}
        for field_name in _FIELDS:
            attr = prim.GetAttribute(attribute_name(field_name))
            if attr and attr.HasAuthoredValue():
                value = attr.Get()
                values[field_name] = float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) \
                    else value
        try:
            return Condition(name=chosen, **values)
        except (InputError, TypeError) as exc:  # the dataclass's range checks; attributes of odd types
            raise StageError(f"{_stage_name(stage)}: {ENVIRONMENT_PATH} variant '{echo(chosen)}': {exc}") from None

