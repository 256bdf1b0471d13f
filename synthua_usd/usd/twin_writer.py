"""Writing a :class:`TwinModel` as two layers: ``twin.usda`` (geometry, materials) and ``semantics.usda``
(UsdSemantics label overs), plus a ``scenario.usda`` that composes them with default cameras and light
when asked. Every object path and label is checked against the class map before anything is written."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pxr import Gf, Kind, Sdf

from synthua_usd.errors import InputError
from synthua_usd.taxonomy import ClassMap
from synthua_usd.twin import TwinModel, prim_name
from synthua_usd.usd.authoring import (StageMetadata, apply_label, define_mesh, define_preview_material,
                                       define_xform, new_layer, save_layer_atomic, set_kind)
from synthua_usd.usd.compose import compose_layers
from synthua_usd.usd.scenario_layers import build_environment, build_overview_cameras, build_render_settings

TWIN_ROOT = "/World/Twin"


def write_twin(model: TwinModel, out_dir: str | Path, class_map: ClassMap,
               meta: StageMetadata = StageMetadata(start_time_code=1, end_time_code=1)) -> list[Path]:
    """Write ``twin.usda`` and ``semantics.usda`` into ``out_dir``; returns their paths."""
    for obj in model.objects:
        if class_map.resolve(obj.label) is None:
            raise InputError(f"{model.source}: object {obj.path}: label '{obj.label}' is not a class of "
                             f"{class_map.source}")
    twin = new_layer(meta, f"synthua twin from {model.source}: geometry and UsdPreviewSurface materials.")
    twin.SetDefaultPrim(define_xform(twin, "/World", kind=Kind.Tokens.assembly).GetPrim())
    define_xform(twin, TWIN_ROOT, kind=Kind.Tokens.group)
    data = {"synthua:source": model.source,
            "synthua:origin_offset_m": Gf.Vec3d(*model.origin_offset_m)}
    if model.crs:
        data["synthua:crs"] = model.crs
    twin.GetRootLayer().customLayerData = data
    looks = {key: define_preview_material(twin, f"/World/Looks/{_safe(key)}", spec)
             for key, spec in sorted(model.materials.items())}
    semantics = new_layer(meta, f"synthua twin from {model.source}: class labels (taxonomy '{class_map.taxonomy}').")
    semantics.SetDefaultPrim(semantics.OverridePrim("/World"))
    for obj in model.objects:
        path = f"{TWIN_ROOT}/{obj.path}"
        parent = path.rsplit("/", 1)[0]
        if not twin.GetPrimAtPath(parent):
            # Intermediate folders group models.
            pieces = parent.split("/")
            for i in range(4, len(pieces) + 1):
                sub = "/".join(pieces[:i])
                if not twin.GetPrimAtPath(sub):
                    define_xform(twin, sub, kind=Kind.Tokens.group)
        xf = define_xform(twin, path)
        set_kind(xf.GetPrim(), Kind.Tokens.component)
        for key, value in sorted(obj.attributes.items()):
            _set_custom(xf.GetPrim(), key, value)
        for part in obj.parts:
            if len(part.triangles) == 0:
                continue
            mesh = define_mesh(twin, f"{path}/{part.name}", part.points, part.triangles, looks[part.material])
            for key, value in sorted(part.attributes.items()):
                _set_custom(mesh.GetPrim(), key, value)
        apply_label(semantics.OverridePrim(path), class_map.taxonomy, class_map.resolve(obj.label).name)
    out_dir = Path(out_dir)
    return [save_layer_atomic(twin.GetRootLayer(), out_dir / "twin.usda"),
            save_layer_atomic(semantics.GetRootLayer(), out_dir / "semantics.usda")]


def _safe(key: str) -> str:
    return prim_name(key, "Material")


def _set_custom(prim, key: str, value) -> None:
    """A ``synthua:``-namespaced custom attribute holding source provenance (strings, numbers)."""
    name = key if ":" in key else f"synthua:{key}"
    if isinstance(value, bool):
        prim.CreateAttribute(name, Sdf.ValueTypeNames.Bool, custom=True).Set(value)
    elif isinstance(value, int):
        prim.CreateAttribute(name, Sdf.ValueTypeNames.Int, custom=True).Set(value)
    elif isinstance(value, float):
        prim.CreateAttribute(name, Sdf.ValueTypeNames.Double, custom=True).Set(value)
    else:
        prim.CreateAttribute(name, Sdf.ValueTypeNames.String, custom=True).Set(str(value))


def write_twin_scenario(model: TwinModel, out_dir: str | Path, class_map: ClassMap) -> list[Path]:
    """The twin and semantics layers, plus automatic cameras, a clear-day environment, render settings and
    ``scenario.usda`` composing them, so that an import renders with ``synthua render`` as it is."""
    out_dir = Path(out_dir)
    meta = StageMetadata(start_time_code=1, end_time_code=1)
    points = [p.points for o in model.objects for p in o.parts if len(p.points)]
    if not points:
        raise InputError(f"{model.source}: the import produced no geometry")
    allp = np.concatenate(points)
    written = write_twin(model, out_dir, class_map, meta)
    point, direction = _street_view(model, allp)
    extra = {"cameras.usda": build_overview_cameras(meta, allp.min(axis=0), allp.max(axis=0), point, direction),
             "environment.usda": build_environment(meta),
             "render.usda": build_render_settings(meta, camera="/World/Cameras/Overview")}
    for name, stage in extra.items():
        written.append(save_layer_atomic(stage.GetRootLayer(), out_dir / name))
    order = ["render.usda", "environment.usda", "cameras.usda", "semantics.usda", "twin.usda"]
    written.append(compose_layers(out_dir / "scenario.usda", [out_dir / n for n in order],
                                  doc=f"synthua scenario for the twin imported from {model.source}."))
    return written


def _street_view(model: TwinModel, points):
    """A ground point on the road (or sidewalk) part nearest the twin's centre, and the road's main
    direction there; (None, (1, 0)) when the twin has no road."""
    centre = (points.min(axis=0) + points.max(axis=0)) / 2
    best = None
    for obj in model.objects:
        if obj.label not in ("road", "street_road", "sidewalk"):
            continue
        for part in obj.parts:
            tris = part.points[part.triangles]
            centroids = tris.mean(axis=1)
            up = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])[:, 2] > 0
            if not up.any():
                continue
            d = np.linalg.norm(centroids[up, :2] - centre[:2], axis=1)
            k = int(np.argmin(d))
            if best is None or d[k] < best[0]:
                best = (d[k], centroids[up][k], part.points)
    if best is None:
        return None, (1.0, 0.0)
    xy = best[2][:, :2] - best[2][:, :2].mean(axis=0)
    direction = np.linalg.svd(xy, full_matrices=False)[2][0] if len(xy) > 1 else np.array([1.0, 0.0])
    return best[1], tuple(direction)
