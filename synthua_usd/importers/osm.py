"""OpenStreetMap extracts (``.osm`` XML, ``.osm.pbf``) → LoD1 extruded buildings, read with pyosmium.

pyosmium (PyPI ``osmium``, the Python binding of libosmium, the library osmium-tool and most OSM software
build on) reads both encodings and assembles areas: closed ways and ``type=multipolygon`` relations with
their holes, from the node locations. Every area tagged ``building`` or ``building:part`` (not ``=no``) is a
building; an outline that contains ``building:part`` areas is replaced by its parts, as OSM's 3-D renderers
do (Simple 3D Buildings), so that the two never overlap. Tagged ways or relations that do not close into an
area (a way cut at the extract's edge, a broken multipolygon) are counted and named in the report.

Heights come from the tags (:mod:`synthua_usd.importers.heights`); lon/lat (WGS84) is projected to a
transverse Mercator centred on the extract (metres, stated in the report's ``crs``). A self-intersecting
outline (which libosmium does not assemble: its own ring is taken) is repaired (shapely's ``make_valid``, its
polygons kept) and reported, or refused with ``strict``; an outline whose lon/lat positions lie on one line has no
area to repair and is skipped (reported), and an extract whose buildings all are skipped is refused.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import check_input_file, shown
from synthua_usd.importers.crs import local_tmerc, lonlat_to
from synthua_usd.importers.footprints import (Footprint, check_projected, extruded_model, flat_ring,
                                               footprint_polygon)
from synthua_usd.importers.heights import building_height
from synthua_usd.importers.limits import (DEFAULT_HEIGHT, DEFAULT_HEIGHT_M, DEFAULT_STOREY_HEIGHT_M, MAX_OSM_BYTES,
                                          MIN_FOOTPRINT_AREA_M2, STOREY_HEIGHT)
from synthua_usd.model.twin import TwinModel, prim_name

WHAT = "an OpenStreetMap extract (.osm or .osm.pbf)"
#: File names pyosmium reads by their suffix.
SUFFIXES = (".osm", ".osm.pbf", ".pbf", ".osm.gz", ".osm.bz2")
BUILDING_KEYS = ("building", "building:part")
#: How many ids of skipped or repaired buildings the report lists (the counts are complete).
LISTED = 50


@dataclass(frozen=True)
class BuildingArea:
    """One assembled area: ``osm_id`` ('way/12', 'relation/7'), its ``tags``, whether it is a ``part``, and
    ``polygons``: each a list of (n, 2) float64 lon/lat rings, the outer ring first."""

    osm_id: str
    tags: dict
    part: bool
    polygons: list


def read_building_areas(path: Path, where: str) -> tuple[list[BuildingArea], list[str]]:
    """The building areas of an OSM file and the ids of building ways and relations that formed no area.

    libosmium's assembler gives a closed way whose ring crosses itself no rings: such a way becomes an area of its own
    ring here (to be repaired, :func:`_polygons`); ways that do not close, or whose nodes lie outside the
    extract, and broken multipolygons form none."""
    import osmium

    keys = osmium.filter.KeyFilter(*BUILDING_KEYS)
    areas, closed, tagged = [], {}, []
    try:
        for obj in osmium.FileProcessor(str(path)).with_areas().with_filter(keys):
            tags = dict(obj.tags)
            if not any(tags.get(k, "no") != "no" for k in BUILDING_KEYS):
                continue
            part = tags.get("building:part", "no") != "no"
            if obj.is_area():
                polygons = [[_ring(outer)] + [_ring(inner) for inner in obj.inner_rings(outer)]
                            for outer in obj.outer_rings()]
                kind = "way" if obj.from_way() else "relation"
                if polygons:  # an area the assembler gave up on has no rings
                    areas.append(BuildingArea(f"{kind}/{obj.orig_id()}", tags, part, polygons))
            elif obj.is_way():
                tagged.append(f"way/{obj.id}")
                nodes = obj.nodes
                if len(nodes) >= 4 and nodes[0].ref == nodes[-1].ref and all(n.location.valid() for n in nodes):
                    closed[tagged[-1]] = BuildingArea(tagged[-1], tags, part, [[_ring(nodes)]])
            elif obj.is_relation() and tags.get("type") == "multipolygon":
                tagged.append(f"relation/{obj.id}")
    except RuntimeError as exc:  # libosmium's parse errors
        raise InputError(f"{where}: cannot be read as OpenStreetMap data ({echo(str(exc)[:200])}); expected "
                         f"{WHAT}") from None
    built = {a.osm_id for a in areas}
    areas += [a for i, a in closed.items() if i not in built]
    built |= set(closed)
    return areas, [t for t in tagged if t not in built]


def _ring(ring) -> np.ndarray:
    return np.array([(n.lon, n.lat) for n in ring], np.float64).reshape(-1, 2)


def _polygons(rings_m: list[list[np.ndarray]], where: str, strict: bool,
              lonlat: list[list[np.ndarray]]) -> tuple[list, bool]:
    """(valid shapely polygons, whether a repair was needed) of one area's projected polygons (``lonlat``: the same
    as the file gives them); an invalid polygon is repaired by ``make_valid`` unless ``strict`` (then refused), one
    with no area in lon/lat (its positions on one line) is dropped."""
    from shapely import make_valid
    from shapely.geometry import Polygon

    out, repaired = [], False
    for k, (rings, source) in enumerate(zip(rings_m, lonlat)):
        pw = f"{where}: polygon {k}" if len(rings_m) > 1 else where
        try:
            out.append(footprint_polygon(rings, pw, source))
        except InputError:
            if strict:
                raise
            if flat_ring(source[0]):  # nothing to repair: projecting only curved a line into a sliver
                continue
            repaired = True
            fixed = make_valid(Polygon(rings[0], rings[1:])) if len(rings[0]) >= 4 else Polygon()
            pieces = getattr(fixed, "geoms", [fixed])
            out += [p for p in pieces if p.geom_type == "Polygon" and p.area >= MIN_FOOTPRINT_AREA_M2]
    return out, repaired


def import_osm(path: str | Path, storey_height_m: float = DEFAULT_STOREY_HEIGHT_M,
               default_height_m: float = DEFAULT_HEIGHT_M, strict: bool = False, **_ignored) -> TwinModel:
    """Extrude the buildings of an OpenStreetMap extract; heights from their tags (metres), every building's
    source in the report. With ``strict``, a building without a usable height or with an invalid outline is
    refused instead of taking the next source (or ``default_height_m``) or being repaired."""
    from synthua_usd.core.findings import Finding, Severity

    path = Path(path)
    where = shown(path)
    STOREY_HEIGHT.check(storey_height_m, "storey_height_m")
    DEFAULT_HEIGHT.check(default_height_m, "default_height_m")
    check_input_file(path, MAX_OSM_BYTES, WHAT)
    if not path.name.lower().endswith(SUFFIXES):
        raise InputError(f"{where}: the file name ends in '{echo(''.join(path.suffixes[-2:]))}'; expected {WHAT} "
                         f"named {', '.join(SUFFIXES)}")
    areas, unassembled = read_building_areas(path, where)
    if not areas:
        raise InputError(f"{where}: no building areas (closed ways or multipolygons tagged building or "
                         f"building:part){f'; {len(unassembled)} building ways do not close' if unassembled else ''}; "
                         f"expected an extract with buildings")
    lonlat = np.concatenate([r for a in areas for rings in a.polygons for r in rings])
    crs_text = local_tmerc(lonlat)
    projected = [[[lonlat_to(crs_text, r) for r in rings] for rings in a.polygons] for a in areas]
    check_projected(np.concatenate([r for polys in projected for rings in polys for r in rings]), where)
    built, repaired, skipped = [], [], []
    for area, rings_m in zip(areas, projected):
        bw = f"{where}: {area.osm_id}"
        polygons, fixed = _polygons(rings_m, bw, strict, area.polygons)
        if fixed:
            repaired.append(area.osm_id)
        if not polygons:
            skipped.append(area.osm_id)
            continue
        built.append((area, bw, polygons))
    if not built:
        raise InputError(f"{where}: none of its {len(areas)} building areas has an outline of at least "
                         f"{MIN_FOOTPRINT_AREA_M2:g} m² (e.g. {', '.join(skipped[:3])}: zero area, or none left after "
                         f"repair); expected an extract with buildings")
    outlines = _outlines_with_parts(built)
    footprints = [Footprint(prim_name(area.tags.get("name") or area.osm_id.replace("/", "_"), "Building"), polygons,
                            building_height(area.tags, bw, storey_height_m, default_height_m, "tag ", strict),
                            {"osm_id": area.osm_id, **({"osm_building_part": True} if area.part else {})}, bw)
                  for k, (area, bw, polygons) in enumerate(built) if k not in outlines]
    findings = []
    for ids, what in ((unassembled, "building ways or multipolygons form no closed area (cut at the extract's edge, "
                                    "or broken); they are not imported"),
                      (repaired, "building outlines are not valid polygons (self-intersections); repaired with "
                                 "shapely's make_valid"),
                      (skipped, "building outlines have no area of at least 0.01 m² after repair; not imported")):
        if ids:
            findings.append(Finding("osm-building", where, f"{len(ids)} {what} (e.g. {', '.join(ids[:3])})",
                                    Severity.WARNING).to_dict())
    report = {"osm": {"building_areas": len(areas), "outlines_replaced_by_parts": len(outlines),
                      "not_assembled": len(unassembled), "not_assembled_ids": unassembled[:LISTED],
                      "repaired": len(repaired), "repaired_ids": repaired[:LISTED], "skipped": len(skipped),
                      "skipped_ids": skipped[:LISTED]},
              "projection": {"from": "EPSG:4326 (WGS84 lon/lat)", "to": crs_text,
                             "note": "transverse Mercator centred on the extract's mean lon/lat; metres"},
              "findings": findings}
    return extruded_model(footprints, str(path), where, (0.0, 0.0, 0.0), crs_text, storey_height_m, default_height_m,
                          report)


def _outlines_with_parts(built: list) -> set[int]:
    """Indices of ``building`` outlines of ``built`` (area, where, polygons) that contain a ``building:part``'s
    representative point: their parts model them."""
    from shapely import STRtree
    from shapely.geometry import MultiPolygon

    parts = [polygons for area, _, polygons in built if area.part]
    if not parts:
        return set()
    points = [MultiPolygon(p).representative_point() for p in parts]
    tree = STRtree(points)
    return {k for k, (area, _, polygons) in enumerate(built)
            if not area.part and len(tree.query(MultiPolygon(polygons), predicate="contains"))}
