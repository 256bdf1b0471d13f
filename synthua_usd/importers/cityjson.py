"""CityJSON 1.1 / 2.0 city models → labelled twin objects.

Vertices are decoded with the file's ``transform`` (scale, translate) and moved to a local origin (the
centre of the model's horizontal extent, its lowest point at z = 0); the CRS and the offset are kept as
stage metadata. Surfaces are triangulated (holes included) with earcut. Classes come from the city
object's type, or from semantic surfaces where the geometry has them (RoofSurface, WallSurface, Window,
Door, ...); a rules file can override by ``type`` or ``object`` (the city object id).
"""

from __future__ import annotations

import logging
from collections import defaultdict
from pathlib import Path

import numpy as np
from tqdm import tqdm

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import read_json, type_name
from synthua_usd.importers.crs import crs_units, parse_crs, resolve_units
from synthua_usd.importers.limits import MAX_EXTENT_M, TRANSFORM_SCALE
from synthua_usd.model.class_assignment import AssignmentRules
from synthua_usd.model.materials import class_material, subset
from synthua_usd.model.ranges import COORDINATE, number_field
from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart, prim_name, unique_paths

log = logging.getLogger(__name__)

VERSIONS = ("1.1", "2.0")

#: City object type → class when no rule matches. Types not listed are labelled 'unlabelled' and reported.
TYPE_CLASSES = {
    "Building": "building", "BuildingPart": "building", "BuildingInstallation": "building",
    "BuildingConstructiveElement": "building",
    "Road": "road", "Railway": "road", "TransportSquare": "road",
    "PlantCover": "vegetation", "SolitaryVegetationObject": "vegetation",
    "LandUse": "grass",
    "CityFurniture": "furniture",
}
#: Semantic surface type → class (overrides the object's class for that surface).
SURFACE_CLASSES = {"Window": "window", "Door": "door", "TrafficArea": "road", "AuxiliaryTrafficArea": "sidewalk"}

#: Geometry type → nesting depth of its boundaries down to vertex indices (surfaces hold rings hold indices).
BOUNDARY_DEPTH = {"MultiSurface": 3, "CompositeSurface": 3, "Solid": 4, "MultiSolid": 5, "CompositeSolid": 5}
_LEVELS = {3: ("surface", "ring", "vertex index"), 4: ("shell", "surface", "ring", "vertex index"),
           5: ("solid", "shell", "surface", "ring", "vertex index")}


class _Malformed(ValueError):
    """A structural fault in one geometry: (where below the geometry, what was found; what was expected)."""


def _index_path(path: tuple) -> str:
    return "".join(f"[{i}]" for i in path)


def check_boundaries(boundaries, depth: int, vertex_count: int) -> None:
    """Raise :class:`_Malformed` unless ``boundaries`` nests arrays exactly ``depth`` deep with integer
    vertex indices in [0, vertex_count) at the bottom and every surface has an outer ring."""
    levels = _LEVELS[depth]
    stack = [(boundaries, 0, ())]
    while stack:
        node, level, path = stack.pop()
        if level == depth:
            if isinstance(node, bool) or not isinstance(node, int):
                raise _Malformed(f"boundaries{_index_path(path)}: {_value(node)}; expected a vertex index (an "
                                 f"integer in [0, {vertex_count - 1}])")
            if not 0 <= node < vertex_count:
                raise _Malformed(f"boundaries{_index_path(path)}: vertex index {node}; expected an integer in "
                                 f"[0, {vertex_count - 1}] (the file has {vertex_count} vertices)")
            continue
        if not isinstance(node, list):
            what = "the boundaries" if level == 0 else f"a {levels[level - 1]}"
            raise _Malformed(f"boundaries{_index_path(path)}: {_value(node)}; expected {what} to be an array of "
                             f"{levels[level]}s ({depth} levels of arrays for this geometry type)")
        if levels[level] == "ring" and not node:
            raise _Malformed(f"boundaries{_index_path(path)}: a surface with no rings; expected an outer ring")
        stack.extend((child, level + 1, path + (i,)) for i, child in reversed(list(enumerate(node))))


def _value(node) -> str:
    if isinstance(node, (list, dict)) or node is None:
        return type_name(node)
    return f"{echo(repr(node))} ({type_name(node)})"


def check_semantics(geometry: dict, depth: int) -> list[str]:
    """The surface types of a geometry's ``semantics``, after checking that every value is null or an index
    of ``semantics.surfaces`` and that ``values`` nests like the (checked) boundaries, one entry per shell,
    solid and surface; raises :class:`_Malformed`."""
    semantics = geometry.get("semantics")
    if semantics is None:
        return []
    if not isinstance(semantics, dict):
        raise _Malformed(f"semantics: {_value(semantics)}; expected an object with surfaces and values")
    surfaces = semantics.get("surfaces", [])
    if not isinstance(surfaces, list):
        raise _Malformed(f"semantics.surfaces: {_value(surfaces)}; expected an array of semantic surfaces")
    types = []
    for i, surface in enumerate(surfaces):
        if not isinstance(surface, dict) or not isinstance(surface.get("type"), str):
            raise _Malformed(f"semantics.surfaces[{i}]: {_value(surface)}; expected an object with a \"type\" string")
        types.append(surface["type"])
    levels = _LEVELS[depth]
    stack = [(semantics.get("values"), geometry.get("boundaries"), 0, ())]
    while stack:
        node, bounds, level, path = stack.pop()
        if node is None:
            continue
        if isinstance(node, list) and level < depth - 2:
            # values mirror the boundaries: one per shell, solid or surface (a shorter array would leave the
            # surfaces past its end without the semantics the file means them to have)
            if len(node) != len(bounds):
                raise _Malformed(f"semantics.values{_index_path(path)}: {len(node)} values for {len(bounds)} "
                                 f"{levels[level]}s; expected one value (or null) per {levels[level]}")
            stack.extend((child, bounds[i], level + 1, path + (i,)) for i, child in enumerate(node))
            continue
        if isinstance(node, bool) or not isinstance(node, int) or not 0 <= node < len(types):
            raise _Malformed(f"semantics.values{_index_path(path)}: {_value(node)}; expected null or an index of "
                             f"semantics.surfaces (0 to {len(types) - 1})")
    return types


def _surfaces(geometry: dict):
    """Yield (surface rings, semantic value) for every surface of a checked geometry."""
    kind = geometry["type"]
    b = geometry["boundaries"]
    values = (geometry.get("semantics") or {}).get("values")
    if kind in ("MultiSurface", "CompositeSurface"):
        for i, s in enumerate(b):
            yield s, _pick(values, i)
    elif kind == "Solid":
        for i, shell in enumerate(b):
            for j, s in enumerate(shell):
                yield s, _pick(_pick(values, i), j)
    else:
        for k, solid in enumerate(b):
            for i, shell in enumerate(solid):
                for j, s in enumerate(shell):
                    yield s, _pick(_pick(_pick(values, k), i), j)


def _pick(values, i):
    if values is None or isinstance(values, int):
        return values
    return values[i] if i < len(values) else None


def _triangulate(rings: list[list[int]], vertices: np.ndarray) -> np.ndarray:
    """(k, 3) vertex-index triangles of one planar surface with holes."""
    import mapbox_earcut

    rings = [ring for ring in rings if len(ring) >= 3]  # a ring of fewer than 3 vertices bounds nothing
    if not rings:
        return np.zeros((0, 3), np.int64)
    outer = rings[0]
    if len(rings) == 1 and len(outer) == 3:
        return np.array([outer], np.int64)
    idx = np.array([v for ring in rings for v in ring], np.int64)
    pts = vertices[idx]
    # Newell's normal of the outer ring, then drop its dominant axis to project to 2-D.
    o = vertices[np.asarray(outer)]
    normal = np.cross(o, np.roll(o, -1, axis=0)).sum(axis=0)
    if not np.any(normal):
        return np.zeros((0, 3), np.int64)
    axis = int(np.argmax(np.abs(normal)))
    pts2 = np.delete(pts, axis, axis=1)
    ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
    tri = np.asarray(mapbox_earcut.triangulate_float64(pts2, ends), np.int64).reshape(-1, 3)
    tri = idx[tri]
    # earcut's winding follows the 2-D projection: restore the ring's own orientation.
    if len(tri):
        n = np.cross(vertices[tri[0, 1]] - vertices[tri[0, 0]], vertices[tri[0, 2]] - vertices[tri[0, 0]])
        if np.dot(n, normal) < 0:
            tri = tri[:, ::-1]
    return tri


def _transform(transform, where: str, version: str) -> tuple[np.ndarray, np.ndarray]:
    """(scale, translate) of the CityJSON ``transform``, each (3,) float64, checked."""
    if transform is None:
        raise InputError(f"{where}: 'transform' is missing; CityJSON {version} stores integer vertices with a "
                         f"transform")
    if not isinstance(transform, dict):
        raise InputError(f"{where}: transform: {_value(transform)}; expected an object with scale and translate")
    out = []
    for key, allowed in (("scale", TRANSFORM_SCALE), ("translate", COORDINATE)):
        value = transform.get(key)
        if not isinstance(value, list) or len(value) != 3:
            raise InputError(f"{where}: transform.{key}: {_value(value)}"
                             f"{f' of {len(value)} numbers' if isinstance(value, list) else ''}; expected 3 numbers "
                             f"(x, y, z)")
        out.append(np.array([number_field(v, f"{where}: transform.{key}[{i}]", allowed) for i, v in enumerate(value)]))
    return out[0], out[1]


def _vertices(vertices, scale: np.ndarray, translate: np.ndarray, where: str) -> np.ndarray:
    """(n, 3) float64 world coordinates (metres) of the integer ``vertices``, checked."""
    if not isinstance(vertices, list) or not vertices:
        raise InputError(f"{where}: vertices: {_value(vertices) if vertices != [] else 'an empty array'}; expected a "
                         f"non-empty array of [x, y, z]")
    try:
        raw = np.array(vertices)
    except (ValueError, TypeError, OverflowError):
        raw = None
    if raw is None or raw.ndim != 2 or raw.shape[1] != 3 or raw.dtype.kind not in "iuf":
        for i, v in enumerate(vertices):
            if not (isinstance(v, list) and len(v) == 3
                    and all(isinstance(c, (int, float)) and not isinstance(c, bool) and abs(c) < 2**63 for c in v)):
                found = f"{len(v)} coordinates" if isinstance(v, list) and len(v) != 3 else _value(v)
                raise InputError(f"{where}: vertices[{i}]: {found}; expected 3 numbers [x, y, z]")
        raise InputError(f"{where}: vertices: not an array of [x, y, z] numbers; expected 3 numbers for each vertex")
    world = raw.astype(np.float64) * scale + translate
    bad = ~np.all((np.abs(world) <= COORDINATE.high), axis=1)  # NaN compares false: caught too
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError(f"{where}: vertices[{i}]: {echo(vertices[i])} is {echo(world[i].tolist())} m after the "
                         f"transform; expected coordinates within ±{COORDINATE.high:g} m")
    extent = world.max(axis=0) - world.min(axis=0)
    if extent.max() > MAX_EXTENT_M:
        raise InputError(f"{where}: vertices span {extent.max():.3g} m; expected at most {MAX_EXTENT_M:g} m (tile the "
                         f"model)")
    return world


def _lods(city_objects: dict) -> list[str]:
    """Every LoD any geometry has, as text, sorted numerically where it can be."""
    found = {str(g.get("lod")) for obj in city_objects.values() if isinstance(obj, dict)
             and isinstance(obj.get("geometry"), list) for g in obj["geometry"] if isinstance(g, dict)}
    return sorted(found, key=lambda t: (_lod_number(t), t))


def _lod_number(text) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        return 0.0
    return value if np.isfinite(value) else 0.0


def import_cityjson(path: str | Path, rules: AssignmentRules | None = None, lod: str | None = None,
                    crs: str | None = None, units: str | None = None, show_progress: bool = False,
                    **_ignored) -> TwinModel:
    """Read a CityJSON file into labelled objects grouped by city object type.

    Vertices are converted to metres by the linear units of ``crs`` (EPSG code or WKT; it replaces the
    file's), else of ``units`` ('m', 'ft', 'us-ft'), else of ``metadata.referenceSystem``; a file with none
    of these is refused."""
    path = Path(path)
    where = shown(path)
    doc = read_json(path, "a CityJSON document")
    if not isinstance(doc, dict) or doc.get("type") != "CityJSON":
        found = f"\"type\": {_value(doc.get('type'))}" if isinstance(doc, dict) else _value(doc)
        raise InputError(f"{where}: not a CityJSON document: {found}; expected an object with \"type\": \"CityJSON\"")
    version = doc.get("version")
    if not isinstance(version, str) or version not in VERSIONS:
        raise InputError(f"{where}: CityJSON version {_value(version) if not isinstance(version, str) else echo(version)} "
                         f"is not supported; expected one of {', '.join(VERSIONS)} (a string)")
    metadata = doc.get("metadata") or {}
    if not isinstance(metadata, dict):
        raise InputError(f"{where}: metadata: {_value(metadata)}; expected an object with a referenceSystem")
    crs_text = metadata.get("referenceSystem")
    if crs_text is not None and not isinstance(crs_text, str):
        raise InputError(f"{where}: metadata.referenceSystem: {_value(crs_text)}; expected a CRS URL such as "
                         f"https://www.opengis.net/def/crs/EPSG/0/7415")
    found = crs_units(parse_crs(crs_text, f"{where}: metadata.referenceSystem"), "CRS", where) if crs_text else None
    linear = resolve_units(found, crs, units, where, "metadata.referenceSystem is missing")
    scale, translate = _transform(doc.get("transform"), where, version)
    world = _vertices(doc.get("vertices"), scale * linear.scale, translate * linear.scale, where)
    lo, hi = world.min(axis=0), world.max(axis=0)
    origin = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    local = world - origin

    city_objects = doc.get("CityObjects")
    if not isinstance(city_objects, dict):
        raise InputError(f"{where}: CityObjects: {_value(city_objects)}; expected an object of city objects by id")
    if not city_objects:
        raise InputError(f"{where}: no CityObjects; expected at least one city object")
    present = _lods(city_objects)
    if lod is not None and str(lod) not in present:
        raise InputError(f"{where}: no city object has LoD '{echo(lod)}' (--lod); expected one of the LoDs present: "
                         f"{', '.join(present) or 'none'}")
    objects, unlabelled_types, fallback = [], defaultdict(int), 0
    for oid, obj in tqdm(sorted(city_objects.items()), desc="cityjson", unit="obj", disable=not show_progress):
        ow = f"{where}: CityObjects['{echo(oid)}']"
        if not isinstance(obj, dict):
            raise InputError(f"{ow}: {_value(obj)}; expected a city object")
        kind = obj.get("type", "?")
        if not isinstance(kind, str):
            raise InputError(f"{ow}.type: {_value(kind)}; expected a city object type such as \"Building\"")
        geometries = obj.get("geometry") or []
        if not isinstance(geometries, list):
            raise InputError(f"{ow}.geometry: {_value(geometries)}; expected an array of geometries")
        for k, g in enumerate(geometries):
            if not isinstance(g, dict):
                raise InputError(f"{ow}.geometry[{k}]: {_value(g)}; expected a geometry object")
        if not geometries:
            continue
        k, geom = _choose_lod(geometries, lod)
        fallback += lod is not None and str(geom.get("lod")) != str(lod)
        gw = f"{ow}.geometry[{k}]"
        gtype = geom.get("type")
        if not isinstance(gtype, str) or gtype not in BOUNDARY_DEPTH:
            raise InputError(f"{gw}: geometry type '{echo(gtype)}' is not supported; expected MultiSurface, "
                             f"CompositeSurface, Solid, MultiSolid or CompositeSolid")
        try:
            check_boundaries(geom.get("boundaries"), BOUNDARY_DEPTH[gtype], len(local))
            surface_types = check_semantics(geom, BOUNDARY_DEPTH[gtype])
        except _Malformed as exc:
            raise InputError(f"{gw}.{exc}") from None
        fields = {"type": kind, "object": oid}
        label, rule = rules.classify(fields) if rules else (None, None)
        if rule is None:
            label = TYPE_CLASSES.get(kind, "unlabelled")
            if label == "unlabelled":
                unlabelled_types[kind] += 1
        by_part: dict[tuple[str, str], list[np.ndarray]] = defaultdict(list)
        for rings, value in _surfaces(geom):
            tris = _triangulate(rings, local)
            if not len(tris):
                continue
            surface = surface_types[value] if value is not None else None
            by_part[(surface or _by_normal(tris, local), SURFACE_CLASSES.get(surface, label))].append(tris)
        for cls_name, parts in _split_by_class(by_part, local).items():
            suffix = "" if cls_name == label else f"_{cls_name}"
            objects.append(TwinObject(f"{prim_name(kind)}/{prim_name(oid)}{suffix}", cls_name, tuple(parts),
                                      {"cityjson_id": oid, "cityjson_type": kind, "lod": str(geom.get("lod"))}))
    if not objects:
        raise InputError(f"{where}: none of the {len(city_objects)} city objects has a surface with area; expected "
                         f"at least one city object with geometry")
    if unlabelled_types:
        log.warning("%s: city object types without a class, labelled 'unlabelled': %s", where,
                    echo(dict(unlabelled_types)))
    if fallback:
        log.warning("%s: %d city objects have no LoD %s; their highest LoD was imported", where, fallback, echo(lod))
    materials = subset(p.material for o in objects for p in o.parts)
    return TwinModel(objects=tuple(unique_paths(objects)), materials=materials, source=str(path),
                     double_sided=True,
                     origin_offset_m=tuple(float(v) for v in origin), crs=crs or crs_text,
                     report={"units": linear.as_report(), "file_crs": crs_text, "city_objects": len(city_objects),
                             "objects": len(objects), "lods_present": present,
                             "lod_fallbacks": fallback, "unlabelled_types": dict(unlabelled_types),
                             "version": version})


def _choose_lod(geometries: list[dict], lod: str | None) -> tuple[int, dict]:
    """(index, geometry): the one of LoD ``lod``, else the highest."""
    if lod is not None:
        for k, g in enumerate(geometries):
            if str(g.get("lod")) == str(lod):
                return k, g
    return max(enumerate(geometries), key=lambda kg: _lod_number(kg[1].get("lod")))


def _by_normal(tris: np.ndarray, vertices: np.ndarray) -> str:
    """Surface kind of unlabelled (LoD1) geometry from the mean normal: roof, ground or wall."""
    v = vertices[tris]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]).sum(axis=0)
    nz = n[2] / (np.linalg.norm(n) or 1.0)
    return "RoofSurface" if nz > 0.7 else "GroundSurface" if nz < -0.7 else "WallSurface"


_PART_NAMES = {"RoofSurface": "Roof", "WallSurface": "Walls", "GroundSurface": "Ground"}


def _split_by_class(by_part, vertices: np.ndarray) -> dict[str, list[TwinPart]]:
    out: dict[str, list[TwinPart]] = defaultdict(list)
    for (surface, cls_name), tris_list in sorted(by_part.items()):
        tris = np.concatenate(tris_list)
        used, inverse = np.unique(tris, return_inverse=True)
        material = class_material("roof" if surface == "RoofSurface" and cls_name == "building" else cls_name).key
        out[cls_name].append(TwinPart(prim_name(_PART_NAMES.get(surface, surface)), vertices[used],
                                      inverse.reshape(-1, 3).astype(np.int64), material, {"surface": surface}))
    return out
