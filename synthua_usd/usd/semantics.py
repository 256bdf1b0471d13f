"""Reading class labels authored with UsdSemantics.LabelsAPI (``semantics:labels:<taxonomy>``).

A prim's class comes from the one prim on its ancestor chain (itself included) that carries labels of
the taxonomy. That prim is the *instance*: everything below it is one object in instance maps.
"""

from __future__ import annotations

from dataclasses import dataclass

from pxr import Usd, UsdGeom, UsdSemantics


@dataclass(frozen=True)
class LabelSite:
    """A prim carrying labels: its path and the labels authored there (at the queried time)."""

    prim_path: str
    labels: tuple[str, ...]


def direct_labels(prim: Usd.Prim, taxonomy: str, time_code: float = Usd.TimeCode.Default()) -> tuple[str, ...] | None:
    """Labels authored on ``prim`` itself for ``taxonomy``, or None when it has no such LabelsAPI."""
    if taxonomy not in UsdSemantics.LabelsAPI.GetDirectTaxonomies(prim):
        return None
    value = UsdSemantics.LabelsAPI(prim, taxonomy).GetLabelsAttr().Get(time_code)
    return tuple(str(v) for v in value) if value is not None else ()


def label_sites(prim: Usd.Prim, taxonomy: str, time_code: float = Usd.TimeCode.Default()) -> list[LabelSite]:
    """Every labelled prim from ``prim`` up to the root, nearest first."""
    out = []
    while prim and not prim.IsPseudoRoot():
        labels = direct_labels(prim, taxonomy, time_code)
        if labels is not None:
            out.append(LabelSite(str(prim.GetPath()), labels))
        prim = prim.GetParent()
    return out


def is_renderable_gprim(prim: Usd.Prim, time_code: float = Usd.TimeCode.Default()) -> bool:
    """A gprim that shows up in a final render: visible, and of purpose default or render."""
    if not prim.IsA(UsdGeom.Gprim):
        return False
    img = UsdGeom.Imageable(prim)
    if img.ComputeVisibility(time_code) == UsdGeom.Tokens.invisible:
        return False
    return img.ComputePurpose() in (UsdGeom.Tokens.default_, UsdGeom.Tokens.render)


def renderable_gprims(stage: Usd.Stage, time_code: float = Usd.TimeCode.Default()) -> list[Usd.Prim]:
    """Renderable gprims in traversal order, instance proxies included."""
    return [p for p in Usd.PrimRange.Stage(stage, Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate))
            if is_renderable_gprim(p, time_code)]
