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

from synthua_usd.errors import InputError
from synthua_usd.importers.crs import require_projected_metres
from synthua_usd.scene import Material
from synthua_usd.schemas import read_json
from synthua_usd.class_assignment import AssignmentRules
from synthua_usd.twin import TwinModel, TwinObject, TwinPart, prim_name, unique_paths

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

MATERIALS = {
    "building": Material("building", (0.55, 0.5, 0.45), 0.9), "roof": Material("roof", (0.35, 0.15, 0.1), 0.8),
    "road": Material("road", (0.06, 0.06, 0.065), 0.9), "vegetation": Material("vegetation", (0.08, 0.22, 0.05), 0.8),
    "grass": Material("grass", (0.12, 0.3, 0.07), 0.9), "window": Material("window", (0.05, 0.07, 0.09), 0.2),
    "door": Material("door", (0.3, 0.15, 0.06), 0.7), "sidewalk": Material("sidewalk", (0.36, 0.35, 0.33), 0.85),
    "furniture": Material("furniture", (0.3, 0.3, 0.3), 0.6), "other": Material("other", (0.3, 0.3, 0.3), 0.8),
}


def _surfaces(geometry: dict):
    """Yield (surface rings, semantic value) for every surface of a geometry, whatever its nesting."""
    kind = geometry.get("type")
    b = geometry.get("boundaries")
    values = (geometry.get("semantics") or {}).get("values")
    if kind in ("MultiSurface", "CompositeSurface"):
        for i, s in enumerate(b):
            yield s, _pick(values, i)
    elif kind == "Solid":
        for i, shell in enumerate(b):
            for j, s in enumerate(shell):
                yield s, _pick(_pick(values, i), j)
    elif kind in ("MultiSolid", "CompositeSolid"):
        for k, solid in enumerate(b):
            for i, shell in enumerate(solid):
                for j, s in enumerate(shell):
                    yield s, _pick(_pick(_pick(values, k), i), j)
    else:
        raise InputError(f"geometry type '{kind}' is not supported; expected MultiSurface, CompositeSurface, "
                         f"Solid, MultiSolid or CompositeSolid")


def _pick(values, i):
    if values is None or isinstance(values, int):
        return values
    return values[i] if i < len(values) else None


def _triangulate(rings: list[list[int]], vertices: np.ndarray) -> np.ndarray:
    """(k, 3) vertex-index triangles of one planar surface with holes."""
    import mapbox_earcut

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


def import_cityjson(path: str | Path, rules: AssignmentRules | None = None, lod: str | None = None,
                    show_progress: bool = False, **_ignored) -> TwinModel:
    """Read a CityJSON file into labelled objects grouped by city object type."""
    path = Path(path)
    doc = read_json(path)
    if not isinstance(doc, dict) or doc.get("type") != "CityJSON":
        raise InputError(f"{path}: not a CityJSON document (expected \"type\": \"CityJSON\")")
    version = str(doc.get("version"))
    if version not in VERSIONS:
        raise InputError(f"{path}: CityJSON version {version} is not supported; expected one of {', '.join(VERSIONS)}")
    crs_text = (doc.get("metadata") or {}).get("referenceSystem")
    if not crs_text:
        raise InputError(f"{path}: metadata.referenceSystem is missing; a CRS is needed to place the model in metres")
    require_projected_metres(crs_text, str(path))
    transform = doc.get("transform")
    if not transform:
        raise InputError(f"{path}: 'transform' is missing; CityJSON {version} stores integer vertices with a transform")
    raw = np.asarray(doc.get("vertices") or [], float)
    if raw.ndim != 2 or raw.shape[1] != 3 or len(raw) == 0:
        raise InputError(f"{path}: 'vertices' should be a non-empty list of [x, y, z], found shape {raw.shape}")
    world = raw * np.asarray(transform["scale"], float) + np.asarray(transform["translate"], float)
    if not np.all(np.isfinite(world)):
        raise InputError(f"{path}: vertices contain NaN or infinite values")
    lo, hi = world.min(axis=0), world.max(axis=0)
    origin = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    local = world - origin

    city_objects = doc.get("CityObjects") or {}
    if not city_objects:
        raise InputError(f"{path}: no CityObjects")
    objects, unlabelled_types = [], defaultdict(int)
    for oid, obj in tqdm(sorted(city_objects.items()), desc="cityjson", unit="obj", disable=not show_progress):
        kind = obj.get("type", "?")
        geometries = obj.get("geometry") or []
        if not geometries:
            continue
        geom = _choose_lod(geometries, lod)
        fields = {"type": kind, "object": oid}
        label, rule = rules.classify(fields) if rules else (None, None)
        if rule is None:
            label = TYPE_CLASSES.get(kind, "unlabelled")
            if label == "unlabelled":
                unlabelled_types[kind] += 1
        surface_types = [s.get("type") for s in (geom.get("semantics") or {}).get("surfaces", [])]
        by_part: dict[tuple[str, str], list[np.ndarray]] = defaultdict(list)
        try:
            for rings, value in _surfaces(geom):
                tris = _triangulate(rings, local)
                if not len(tris):
                    continue
                surface = surface_types[value] if value is not None and value < len(surface_types) else None
                by_part[(surface or _by_normal(tris, local), SURFACE_CLASSES.get(surface, label))].append(tris)
        except (IndexError, TypeError, ValueError) as exc:
            raise InputError(f"{path}: CityObjects['{oid}']: malformed geometry boundaries ({exc})") from None
        except InputError as exc:
            raise InputError(f"{path}: CityObjects['{oid}']: {exc}") from None
        for cls_name, parts in _split_by_class(by_part, local).items():
            suffix = "" if cls_name == label else f"_{cls_name}"
            objects.append(TwinObject(f"{prim_name(kind)}/{prim_name(oid)}{suffix}", cls_name, tuple(parts),
                                      {"cityjson_id": oid, "cityjson_type": kind, "lod": str(geom.get("lod"))}))
    if unlabelled_types:
        log.warning("%s: city object types without a class, labelled 'unlabelled': %s", path, dict(unlabelled_types))
    materials = {k: v for k, v in MATERIALS.items()}
    return TwinModel(objects=tuple(unique_paths(objects)), materials=materials, source=str(path),
                     origin_offset_m=tuple(float(v) for v in origin), crs=crs_text,
                     report={"city_objects": len(city_objects), "objects": len(objects),
                             "unlabelled_types": dict(unlabelled_types), "version": version})


def _choose_lod(geometries: list[dict], lod: str | None) -> dict:
    def key(g):
        try:
            return float(g.get("lod", 0))
        except (TypeError, ValueError):
            return 0.0

    if lod is not None:
        chosen = [g for g in geometries if str(g.get("lod")) == str(lod)]
        if chosen:
            return chosen[0]
    return max(geometries, key=key)


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
        material = "roof" if surface == "RoofSurface" and cls_name == "building" else \
            cls_name if cls_name in MATERIALS else "other"
        out[cls_name].append(TwinPart(prim_name(_PART_NAMES.get(surface, surface)), vertices[used],
                                      inverse.reshape(-1, 3).astype(np.int64), material, {"surface": surface}))
    return out
