"""What a stage holds, for people without usdview: layers, classes, cameras, lights, conditions, time range."""

from __future__ import annotations

import math
import textwrap
from collections import Counter
from dataclasses import dataclass, field

from pxr import Usd, UsdGeom, UsdLux

from synthua_usd.core.errors import escape_controls
from synthua_usd.model.conditions import display_order
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.usd.conditions import condition_names, selected_condition
from synthua_usd.usd.prim_checks import lens_unit_mm
from synthua_usd.usd.semantics import label_sites, renderable_gprims
from synthua_usd.usd.stage_io import time_range


@dataclass
class StageSummary:
    root: str
    layers: list[str]
    up_axis: str
    meters_per_unit: float
    default_prim: str
    time_codes_per_second: float
    time_range: tuple[float, float] | None
    prim_count: int
    gprim_count: int
    triangle_estimate: int
    classes: dict[str, int] = field(default_factory=dict)  # label -> labelled prims (instances)
    unlabelled_gprims: int = 0
    cameras: list[dict] = field(default_factory=list)
    lights: list[dict] = field(default_factory=list)
    conditions: list[str] = field(default_factory=list)  # shipped order first; see synthua_usd.model.conditions
    condition: str | None = None  # the one the stage selects

    def format(self) -> str:
        # Layer files and names come from the user's files: control characters escaped, one line each.
        lines = [f"stage      {escape_controls(self.root)}",
                 "layers     " + ("\n           ".join(map(escape_controls, self.layers))),
                 f"upAxis     {self.up_axis}    metersPerUnit {self.meters_per_unit:g}    "
                 f"defaultPrim {escape_controls(self.default_prim or '(none)')}",
                 f"time       {'static' if not self.time_range else f'{self.time_range[0]:g}..{self.time_range[1]:g}'}"
                 f" at {self.time_codes_per_second:g} time codes/s",
                 f"prims      {self.prim_count} ({self.gprim_count} renderable gprims, ~{self.triangle_estimate} triangles)",
                 "classes    " + ("\n           ".join(textwrap.wrap(
                     "  ".join(escape_controls(f"{k}:{v}") for k, v in sorted(self.classes.items())), 88, break_on_hyphens=False))
                     or "(none)")]
        if self.unlabelled_gprims:
            lines.append(f"           {self.unlabelled_gprims} gprims without a class")
        lines.append("cameras    " + ("\n           ".join(
            f"{escape_controls(c['path'])}  f={c['focal_length_mm']:g} mm  aperture {c['horizontal_aperture_mm']:g}x"
            f"{c['vertical_aperture_mm']:g} mm  hfov {c['hfov_deg']:.1f} deg" for c in self.cameras) or "(none)"))
        lines.append("lights     " + ("\n           ".join(
            f"{escape_controls(l['path'])}  {l['type']}  intensity {l['intensity']:g}" for l in self.lights) or "(none)"))
        lines.append("conditions " + ("  ".join(escape_controls(f"{c}*" if c == self.condition else c)
                                                for c in self.conditions)
                                      + "   (* selected; render --condition NAME picks another)"
                                      if self.conditions else "(none)"))
        return "\n".join(lines)


def summarize(stage: Usd.Stage, class_map: ClassMap) -> StageSummary:
    layer_stack = [layer.identifier for layer in stage.GetLayerStack(includeSessionLayers=False)]
    classes: Counter[str] = Counter()
    seen_sites: set[str] = set()
    unlabelled = 0
    tris = 0
    gprims = renderable_gprims(stage)
    for prim in gprims:
        sites = label_sites(prim, class_map.taxonomy)
        if not sites:
            unlabelled += 1
        elif sites[0].prim_path not in seen_sites:
            seen_sites.add(sites[0].prim_path)
            for label in sites[0].labels:
                classes[label] += 1
        if prim.IsA(UsdGeom.Mesh):
            counts = UsdGeom.Mesh(prim).GetFaceVertexCountsAttr().Get() or []
            tris += int(sum(max(c - 2, 0) for c in counts))
    unit = lens_unit_mm(UsdGeom.GetStageMetersPerUnit(stage))
    cameras = []
    for prim in stage.Traverse():
        if prim.IsA(UsdGeom.Camera):
            cam = UsdGeom.Camera(prim)
            f = cam.GetFocalLengthAttr().Get() * unit
            h = cam.GetHorizontalApertureAttr().Get() * unit
            v = cam.GetVerticalApertureAttr().Get() * unit
            cameras.append({"path": str(prim.GetPath()), "focal_length_mm": f, "horizontal_aperture_mm": h,
                            "vertical_aperture_mm": v,
                            "hfov_deg": math.degrees(2 * math.atan(h / (2 * f))) if f > 0 else float("nan")})
    lights = [{"path": str(p.GetPath()), "type": p.GetTypeName(),
               "intensity": float(UsdLux.LightAPI(p).GetIntensityAttr().Get() or 0.0)}
              for p in stage.Traverse() if p.HasAPI(UsdLux.LightAPI)]
    return StageSummary(root=stage.GetRootLayer().identifier, layers=layer_stack,
                        up_axis=str(UsdGeom.GetStageUpAxis(stage)), meters_per_unit=UsdGeom.GetStageMetersPerUnit(stage),
                        default_prim=str(stage.GetDefaultPrim().GetPath()) if stage.GetDefaultPrim() else "",
                        time_codes_per_second=stage.GetTimeCodesPerSecond(), time_range=time_range(stage),
                        prim_count=sum(1 for _ in stage.Traverse()), gprim_count=len(gprims), triangle_estimate=tris,
                        classes=dict(classes), unlabelled_gprims=unlabelled, cameras=cameras, lights=lights,
                        conditions=display_order(condition_names(stage)), condition=selected_condition(stage))
