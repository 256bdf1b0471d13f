"""Building footprints (GeoJSON polygons with a height or a number of levels) → LoD1 extruded blocks.

Heights (:mod:`synthua_usd.importers.heights`): ``height`` (metres, or text with a unit), else ``levels`` /
``building:levels`` × ``storey_height_m`` (plus the roof), else ``roof:height``, else ``default_height_m``;
optional ``min_height``; within the ranges of :mod:`synthua_usd.importers.limits`. Each building's height
and its source are in the report (``heights``). Coordinates are
WGS84 lon/lat (RFC 7946) and are projected to a local transverse Mercator, or, when the file names a
projected CRS in a legacy ``crs`` member, used as metres. A footprint must be a valid polygon (no
self-intersections, holes inside their shell) of at least 0.01 m², and have an area in the file's own coordinates
too (a ring whose lon/lat positions lie on one line has none, though projecting it curves it into a sliver of some
square metres): invalid footprints are refused with the reason and place, never silently repaired. Each building is one ``building`` instance with ``Walls``
and ``Roof`` parts, in the palette's materials.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import read_json, type_name
from synthua_usd.importers.crs import local_tmerc, lonlat_to, require_projected_metres
from synthua_usd.importers.heights import BuildingHeight, building_height, heights_report
from synthua_usd.importers.limits import (DEFAULT_HEIGHT, DEFAULT_HEIGHT_M, DEFAULT_STOREY_HEIGHT_M, MAX_EXTENT_M,
                                          MIN_FOOTPRINT_AREA_M2, STOREY_HEIGHT)
from synthua_usd.model.materials import class_material, subset
from synthua_usd.model.ranges import COORDINATE, number_field
from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart, prim_name, unique_paths

#: Palette keys of the two parts of every block.
WALL_MATERIAL = class_material("building").key
ROOF_MATERIAL = class_material("roof").key


def _position(value, where: str) -> tuple[float, float]:
    if not isinstance(value, list) or len(value) < 2:
        found = f"{len(value)} numbers" if isinstance(value, list) else type_name(value)
        raise InputError(f"{where}: a position of {found}; expected [x, y] (or [x, y, z]) numbers")
    return (number_field(value[0], where + "[0]", COORDINATE), number_field(value[1], where + "[1]", COORDINATE))


def _rings(geometry, where: str) -> list[list[np.ndarray]]:
    """Polygons as lists of (n, 2) float64 rings (shell first), checked for structure and finite numbers."""
    kind = geometry.get("type") if isinstance(geometry, dict) else None
    if kind == "Polygon":
        polygons, base = [geometry.get("coordinates")], f"{where}: geometry.coordinates"
    elif kind == "MultiPolygon":
        polygons, base = geometry.get("coordinates"), f"{where}: geometry.coordinates"
    else:
        found = echo(kind) if isinstance(kind, str) else (type_name(geometry) if not isinstance(geometry, dict)
                                                          else "None")
        raise InputError(f"{where}: geometry type '{found}' is not a footprint; expected Polygon or MultiPolygon")
    if not isinstance(polygons, list):
        raise InputError(f"{base}: {type_name(polygons)}; expected an array of {'polygons' if kind == 'MultiPolygon' else 'rings'}")
    out = []
    for p, poly in enumerate(polygons):
        pw = base if kind == "Polygon" else f"{base}[{p}]"
        if not isinstance(poly, list) or not poly:
            raise InputError(f"{pw}: {type_name(poly) if poly != [] else 'no rings'}; expected an array of rings, "
                             f"the shell first")
        rings = []
        for r, ring in enumerate(poly):
            if not isinstance(ring, list):
                raise InputError(f"{pw}[{r}]: {type_name(ring)}; expected a ring: an array of [x, y] positions")
            xy = np.array([_position(v, f"{pw}[{r}][{i}]") for i, v in enumerate(ring)], float).reshape(-1, 2)
            if len(xy) < 4:
                raise InputError(f"{where}: polygon has {len(xy)} vertices; a closed ring needs at least 4")
            if not np.array_equal(xy[0], xy[-1]):  # RFC 7946 3.1.6: the first and last positions are equivalent
                raise InputError(f"{pw}[{r}]: the ring is not closed (it ends at {xy[-1].tolist()}, not at its first "
                                 f"position {xy[0].tolist()}); expected a closed ring, its last position its first")
            rings.append(xy)
        out.append(rings)
    if not out:
        raise InputError(f"{where}: empty geometry; expected at least one polygon")
    return out


#: A ring whose positions spread less than this share of their length across it, in the file's own coordinates,
#: lies on one line (a real footprint, even a 0.1 m x 1 km sliver, spreads 1e-4; rounding of decimal degrees 1e-13).
FLAT_RING = 1e-9


def flat_ring(ring: np.ndarray) -> bool:
    """Whether the positions of a ring (n, 2) of the file's own coordinates (lon/lat or projected) lie on one line
    (or one point): its second singular value against its first."""
    points = np.unique(np.asarray(ring, np.float64).reshape(-1, 2), axis=0)
    if len(points) < 3:
        return True
    spread = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    return bool(spread[1] <= FLAT_RING * spread[0])


def footprint_polygon(rings: list[np.ndarray], where: str, source: list[np.ndarray] | None = None):
    """The shapely polygon of projected rings (metres), refused unless valid and of some area, each hole too;
    ``source``, the same rings as the file gives them (lon/lat), must enclose an area too (:func:`flat_ring`)."""
    from shapely.geometry import Polygon
    from shapely.validation import explain_validity

    try:
        poly = Polygon(rings[0], rings[1:])
    except (ValueError, TypeError) as exc:
        raise InputError(f"{where}: not a polygon ({echo(exc)}); expected closed rings of at least 4 positions") from None
    if not poly.is_valid:
        reason = explain_validity(poly)
        kind = "self-intersects" if "Self-intersection" in reason else "is not a valid polygon"
        raise InputError(f"{where}: the footprint {kind} ({echo(reason)} in projected metres; signed area "
                         f"{poly.area:.3g} m²); expected a simple ring with holes inside it (fix the geometry, e.g. "
                         f"QGIS 'Fix geometries')")
    if poly.area < MIN_FOOTPRINT_AREA_M2:
        raise InputError(f"{where}: area {poly.area:.3g} m²; expected a footprint of at least "
                         f"{MIN_FOOTPRINT_AREA_M2:g} m² (a degenerate or zero-area ring)")
    for k, hole in enumerate(poly.interiors, start=1):
        area = Polygon(hole).area
        if area < MIN_FOOTPRINT_AREA_M2:  # a courtyard of no area: a digitising slip that cuts nothing
            raise InputError(f"{where}: ring {k} (a hole) has area {area:.3g} m²; expected holes of at least "
                             f"{MIN_FOOTPRINT_AREA_M2:g} m², or none")
    for k, ring in enumerate(source or []):  # a line in lon/lat that projecting curved into a sliver
        if flat_ring(ring):
            what = "the footprint's ring" if k == 0 else f"ring {k} (a hole)"
            raise InputError(f"{where}: {what} has area 0 in the file's coordinates (its positions lie on one line); "
                             f"expected a footprint of at least {MIN_FOOTPRINT_AREA_M2:g} m² (a degenerate or "
                             f"zero-area ring)")
    return poly


def _extrude(poly, base: float, top: float):
    mesh = trimesh.creation.extrude_polygon(poly, height=top - base)
    mesh.apply_translation((0, 0, base))
    normals = mesh.face_normals
    roof = normals[:, 2] > 0.5
    wall = np.abs(normals[:, 2]) <= 0.5  # the downward base is never seen from the street: dropped
    return mesh, roof, wall


def _part(name: str, mesh: trimesh.Trimesh, mask: np.ndarray, surface: str) -> TwinPart:
    sub = mesh.submesh([np.flatnonzero(mask)], append=True)
    return TwinPart(name, np.asarray(sub.vertices, float), np.asarray(sub.faces, np.int64),
                    ROOF_MATERIAL if surface == "roof" else WALL_MATERIAL, {"surface": surface})


def _crs_member(doc: dict, where: str) -> str | None:
    crs = doc.get("crs")
    if crs is None:
        return None
    name = crs.get("properties", {}).get("name") if isinstance(crs, dict) and isinstance(crs.get("properties"),
                                                                                           dict) else None
    if not isinstance(name, str) or not name:
        raise InputError(f"{where}: crs: {type_name(crs) if not isinstance(crs, dict) else 'no properties.name text'}; "
                         f"expected {{\"type\": \"name\", \"properties\": {{\"name\": \"EPSG:...\"}}}} or no crs member "
                         f"(lon/lat)")
    return name


@dataclass(frozen=True)
class Footprint:
    """One building to extrude: its prim ``name``, ``polygons`` (valid shapely polygons in local metres, see
    :func:`footprint_polygon`), its ``height``, the ``attributes`` its object keeps and ``where`` it came from
    (for messages)."""

    name: str
    polygons: list
    height: BuildingHeight
    attributes: dict
    where: str


def extruded_model(footprints: list[Footprint], source: str, where: str, origin_offset_m: tuple, crs: str,
                   storey_height_m: float, default_height_m: float, report: dict) -> TwinModel:
    """The blocks of ``footprints`` as a :class:`TwinModel` whose report holds ``report``, the buildings'
    ``heights`` (:func:`synthua_usd.importers.heights.heights_report`) and their findings."""
    objects = []
    for fp in footprints:
        parts = []
        for k, polygon in enumerate(fp.polygons):
            mesh, roof, wall = _extrude(polygon, fp.height.base_m, fp.height.top_m)
            suffix = f"_{k}" if len(fp.polygons) > 1 else ""
            parts += [_part(f"Walls{suffix}", mesh, wall, "wall"), _part(f"Roof{suffix}", mesh, roof, "roof")]
        objects.append(TwinObject(f"Buildings/{fp.name}", "building", tuple(parts),
                                  {**fp.attributes, "height_m": fp.height.top_m, "min_height_m": fp.height.base_m,
                                   "height_source": fp.height.source}))
    objects = unique_paths(objects)
    heights, findings = heights_report({o.path: fp.height for o, fp in zip(objects, footprints)}, where,
                                       storey_height_m, default_height_m)
    findings = report.get("findings", []) + findings
    return TwinModel(objects=tuple(objects), materials=subset([WALL_MATERIAL, ROOF_MATERIAL]), source=source,
                     origin_offset_m=origin_offset_m, crs=crs,
                     report={"buildings": len(objects), **report, "heights": heights, "findings": findings})


def import_footprints(path: str | Path, storey_height_m: float = DEFAULT_STOREY_HEIGHT_M,
                      default_height_m: float = DEFAULT_HEIGHT_M, strict: bool = False, **_ignored) -> TwinModel:
    """Extrude every footprint polygon of a GeoJSON FeatureCollection into a labelled building; heights as the
    module says, every building's source in the report. With ``strict``, a footprint without a usable height
    is refused instead of taking the next source or ``default_height_m`` (metres)."""
    path = Path(path)
    where = shown(path)
    STOREY_HEIGHT.check(storey_height_m, "storey_height_m")
    DEFAULT_HEIGHT.check(default_height_m, "default_height_m")
    doc = read_json(path, "a GeoJSON FeatureCollection")
    if not isinstance(doc, dict) or doc.get("type") != "FeatureCollection":
        found = (f"\"type\": {echo(doc.get('type'))}" if isinstance(doc, dict) else type_name(doc))
        raise InputError(f"{where}: {found}; expected a GeoJSON object with \"type\": \"FeatureCollection\"")
    features = doc.get("features")
    if features is not None and not isinstance(features, list):
        raise InputError(f"{where}: features: {type_name(features)}; expected an array of features")
    if not features:
        raise InputError(f"{where}: the FeatureCollection has no features")
    parsed = []
    for i, feat in enumerate(features):
        if not isinstance(feat, dict):
            raise InputError(f"{where}: features[{i}]: {type_name(feat)}; expected a Feature object")
        props = feat.get("properties") or {}
        if not isinstance(props, dict):
            raise InputError(f"{where}: features[{i}].properties: {type_name(props)}; expected an object or null")
        label = props.get("name")
        fw = f"{where}: features[{i}]" + (f" ({echo(label)})" if isinstance(label, str) and label else "")
        parsed.append((i, props, fw, _rings(feat.get("geometry"), fw),
                       building_height(props, fw, storey_height_m, default_height_m, strict=strict)))
    all_xy = np.concatenate([r for *_, polys, _ in parsed for rings in polys for r in rings])
    crs_member = _crs_member(doc, where)
    if crs_member:
        crs = require_projected_metres(crs_member, where)
        origin = (all_xy.min(axis=0) + all_xy.max(axis=0)) / 2
        crs_text = crs.to_string()
        project = lambda xy: xy - origin
    else:
        if np.abs(all_xy[:, 0]).max() > 180 or np.abs(all_xy[:, 1]).max() > 90:
            raise InputError(f"{where}: coordinates exceed lon/lat ranges but the file names no CRS; add a 'crs' "
                             f"member for projected coordinates")
        crs_text = local_tmerc(all_xy)
        origin = np.zeros(2)
        project = lambda xy: lonlat_to(crs_text, xy)
    projected = [[[project(r) for r in rings] for rings in polys] for *_, polys, _ in parsed]
    check_projected(np.concatenate([r for polys in projected for rings in polys for r in rings]), where)
    footprints = []
    for (i, props, fw, polys, height), rings_m in zip(parsed, projected):
        polygons = [footprint_polygon(rings, f"{fw}: polygon {k}" if len(rings_m) > 1 else fw, source)
                    for k, (rings, source) in enumerate(zip(rings_m, polys))]
        footprints.append(Footprint(prim_name(props.get("name") or props.get("id") or f"Building_{i:04d}", "Building"),
                                    polygons, height, {"source_feature": i}, fw))
    return extruded_model(footprints, str(path), where, (float(origin[0]), float(origin[1]), 0.0), crs_text,
                          storey_height_m, default_height_m, {})


def check_projected(flat: np.ndarray, where: str) -> None:
    """Refuse projected coordinates (n, 2) metres that are not finite or span more than one import may."""
    if not np.all(np.isfinite(flat)):
        raise InputError(f"{where}: coordinates cannot be projected to metres (non-finite results); expected lon/lat "
                         f"degrees or a projected CRS")
    extent = float((flat.max(axis=0) - flat.min(axis=0)).max())
    if extent > MAX_EXTENT_M:
        raise InputError(f"{where}: footprints span {extent:.3g} m; expected at most {MAX_EXTENT_M:g} m (split the file)")
