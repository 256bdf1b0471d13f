"""Building footprints (GeoJSON polygons with a height or a number of levels) → LoD1 extruded blocks.

Heights: ``height`` (metres above ground) or ``levels`` / ``building:levels`` × ``storey_height_m``;
optional ``min_height``. Coordinates are WGS84 lon/lat (RFC 7946) and are projected to a local transverse
Mercator, or, when the file names a projected CRS in a legacy ``crs`` member, used as metres. Each
building is one ``building`` instance with ``Walls`` and ``Roof`` parts.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from synthua_usd.errors import InputError
from synthua_usd.importers.crs import local_tmerc, lonlat_to, require_projected_metres
from synthua_usd.scene import Material
from synthua_usd.twin import TwinModel, TwinObject, TwinPart, prim_name, unique_paths

MATERIALS = {"Wall": Material("Wall", (0.55, 0.5, 0.45), 0.9), "Roof": Material("Roof", (0.3, 0.12, 0.08), 0.8)}
HEIGHT_KEYS = ("height",)
LEVEL_KEYS = ("levels", "building:levels")


def _rings(geometry: dict, where: str) -> list[list[np.ndarray]]:
    kind = geometry.get("type") if isinstance(geometry, dict) else None
    if kind == "Polygon":
        polygons = [geometry.get("coordinates")]
    elif kind == "MultiPolygon":
        polygons = geometry.get("coordinates")
    else:
        raise InputError(f"{where}: geometry type '{kind}' is not a footprint; expected Polygon or MultiPolygon")
    out = []
    for poly in polygons or []:
        try:
            rings = [np.asarray(ring, float)[:, :2] for ring in poly]
        except (ValueError, IndexError, TypeError):
            raise InputError(f"{where}: polygon coordinates should be lists of [x, y] pairs") from None
        if not rings or len(rings[0]) < 4:
            raise InputError(f"{where}: polygon has {len(rings[0]) if rings else 0} vertices; a closed ring needs at "
                             f"least 4")
        for ring in rings:
            if not np.all(np.isfinite(ring)):
                raise InputError(f"{where}: polygon has NaN or infinite coordinates")
        out.append(rings)
    if not out:
        raise InputError(f"{where}: empty geometry")
    return out


def _height(props: dict, where: str, storey_height_m: float) -> tuple[float, float]:
    base = float(props.get("min_height", 0.0) or 0.0)
    for key in HEIGHT_KEYS:
        if props.get(key) not in (None, ""):
            value = _number(props[key], f"{where}: property '{key}'")
            break
    else:
        for key in LEVEL_KEYS:
            if props.get(key) not in (None, ""):
                value = _number(props[key], f"{where}: property '{key}'") * storey_height_m
                break
        else:
            raise InputError(f"{where}: no height; expected a 'height' (m) or 'levels' property")
    if not value > base:
        raise InputError(f"{where}: height {value:g} m should be above min_height {base:g} m")
    return base, value


def _number(value, where: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{where} should be a number, but was {value!r}") from None
    if not np.isfinite(out):
        raise InputError(f"{where} should be finite, but was {value!r}")
    return out


def _extrude(rings: list[np.ndarray], base: float, top: float):
    from shapely.geometry import Polygon

    poly = Polygon(rings[0], rings[1:]).buffer(0)  # buffer(0) repairs self-touching rings
    if poly.is_empty or poly.area <= 0:
        return None
    polys = list(poly.geoms) if poly.geom_type == "MultiPolygon" else [poly]
    meshes = [trimesh.creation.extrude_polygon(p, height=top - base) for p in polys]
    mesh = trimesh.util.concatenate(meshes)
    mesh.apply_translation((0, 0, base))
    normals = mesh.face_normals
    roof = normals[:, 2] > 0.5
    wall = np.abs(normals[:, 2]) <= 0.5  # the downward base is never seen from the street: dropped
    return mesh, roof, wall


def _part(name: str, mesh: trimesh.Trimesh, mask: np.ndarray, surface: str) -> TwinPart:
    sub = mesh.submesh([np.flatnonzero(mask)], append=True)
    return TwinPart(name, np.asarray(sub.vertices, float), np.asarray(sub.faces, np.int64),
                    "Roof" if surface == "roof" else "Wall", {"surface": surface})


def import_footprints(path: str | Path, storey_height_m: float = 3.0, **_ignored) -> TwinModel:
    """Extrude every footprint polygon of a GeoJSON FeatureCollection into a labelled building."""
    from synthua_usd.schemas import read_json

    path = Path(path)
    doc = read_json(path)
    if not isinstance(doc, dict) or doc.get("type") != "FeatureCollection":
        raise InputError(f"{path}: expected a GeoJSON FeatureCollection, found "
                         f"{doc.get('type') if isinstance(doc, dict) else type(doc).__name__}")
    features = doc.get("features") or []
    if not features:
        raise InputError(f"{path}: the FeatureCollection has no features")
    parsed = []
    for i, feat in enumerate(features):
        props = (feat or {}).get("properties") or {}
        where = f"{path}: features[{i}]" + (f" ({props['name']})" if props.get("name") else "")
        parsed.append((i, props, _rings((feat or {}).get("geometry"), where), _height(props, where, storey_height_m)))
    all_xy = np.concatenate([r for _, _, polys, _ in parsed for rings in polys for r in rings])
    crs_member = ((doc.get("crs") or {}).get("properties") or {}).get("name")
    if crs_member:
        crs = require_projected_metres(crs_member, str(path))
        origin = all_xy.mean(axis=0)
        crs_text = crs.to_string()
        project = lambda xy: xy - origin
    else:
        if np.abs(all_xy[:, 0]).max() > 180 or np.abs(all_xy[:, 1]).max() > 90:
            raise InputError(f"{path}: coordinates exceed lon/lat ranges but the file names no CRS; add a 'crs' "
                             f"member for projected coordinates")
        crs_text = local_tmerc(all_xy)
        origin = np.zeros(2)
        project = lambda xy: lonlat_to(crs_text, xy)
    objects = []
    for i, props, polys, (base, top) in parsed:
        name = prim_name(props.get("name") or props.get("id") or f"Building_{i:04d}", "Building")
        parts = []
        for k, rings in enumerate(polys):
            made = _extrude([project(r) for r in rings], base, top)
            if made is None:
                raise InputError(f"{path}: features[{i}]: polygon {k} has no area")
            mesh, roof, wall = made
            suffix = f"_{k}" if len(polys) > 1 else ""
            parts += [_part(f"Walls{suffix}", mesh, wall, "wall"), _part(f"Roof{suffix}", mesh, roof, "roof")]
        objects.append(TwinObject(f"Buildings/{name}", "building", tuple(parts),
                                  {"source_feature": i, "height_m": top, "min_height_m": base}))
    return TwinModel(objects=tuple(unique_paths(objects)), materials=dict(MATERIALS), source=str(path),
                     origin_offset_m=(float(origin[0]), float(origin[1]), 0.0), crs=crs_text,
                     report={"buildings": len(objects)})

