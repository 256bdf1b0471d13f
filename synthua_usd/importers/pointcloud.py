"""Point clouds (LAS, LAZ, PLY) → labelled, simplified surface meshes.

0. Units: coordinates are converted to metres first (:mod:`synthua_usd.importers.crs`).
1. Segments (:mod:`synthua_usd.importers.segmentation`): ground (LAS classes or a morphological ground
   filter), connected planar regions named by normal and height above the local ground (roof, façade,
   ground-level plane), trees as connected clusters, and the points that fit nothing (reported).
2. Surfaces: a plane's points are projected onto it and the ground's smoothed (moving least squares), then
   triangulated as a height field over their least-squares plane (2-D Delaunay in plane coordinates, long
   edges dropped); a tree is its convex hull.
3. Simplification: MeshLab's quadric edge collapse (pymeshlab), halving the face count while the
   symmetric Hausdorff distance between the reconstructed and the simplified mesh (MeshLab's own
   sampling filter, both ways) stays within ``max_deviation_m`` (default 5 mm, the paper's ε); faces
   before and after are reported, and why when nothing could be collapsed.
4. Residuals: every input point's distance to its segment's final surface, summarised per segment; over
   its bound (95th percentile) a finding. The bound of a surface is ``max_residual_m``; a tree's hull
   encloses its points (trunk, branches, the far side of the crown lie inside it), so its bound is the
   looser ``max_hull_residual_m`` (default 1 m): past it the hull wraps mostly empty space (trees merged
   into one cluster, or a cluster that is no tree).
"""

from __future__ import annotations

import contextlib
import logging
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import numpy as np
from tqdm import tqdm

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.findings import Finding, Severity
from synthua_usd.core.input_files import check_input_file, shown
from synthua_usd.importers.crs import (PROJECTED_CRS, USER_DEFINED, LinearUnits, crs_units, geotiff_units,
                                       resolve_units)
from synthua_usd.importers.las_header import check_las_header, check_las_layout
from synthua_usd.importers.limits import (MAX_DEVIATION, MAX_EXTENT_M, MAX_HULL_RESIDUAL, MAX_POINTCLOUD_BYTES,
                                          MAX_POINTS, MAX_RESIDUAL, PLANE_THRESHOLD)
from synthua_usd.importers.segmentation import Region, Segmentation, fit_plane, segment, smoothed_heights
from synthua_usd.model.class_assignment import AssignmentRules
from synthua_usd.model.materials import class_material, subset
from synthua_usd.model.ranges import COORDINATE
from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart

log = logging.getLogger(__name__)

SUFFIXES = (".las", ".laz", ".ply")

@contextlib.contextmanager
def _quiet(logger: str) -> Iterator[None]:
    """Silence a library's own error log while we read (we report the failure ourselves, in one line)."""
    log_ = logging.getLogger(logger)
    level = log_.level
    log_.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        log_.setLevel(level)


def read_points(path: Path) -> tuple[np.ndarray, np.ndarray | None, str | None, LinearUnits | None]:
    """(n, 3) float64 coordinates in the file's units, (n,) uint8 LAS classification or None, CRS text or None,
    and the linear units the file states (LAS: WKT or GeoTIFF keys) or None (PLY never states any)."""
    where = shown(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise InputError(f"{where}: unsupported point cloud format '{echo(path.suffix)}'; expected {', '.join(SUFFIXES)}")
    size = check_input_file(path, MAX_POINTCLOUD_BYTES, f"a {suffix[1:].upper()} point cloud")
    if suffix == ".ply":
        import trimesh

        try:
            cloud = trimesh.load(str(path))
        except Exception as exc:  # malformed files raise many types (MemoryError included)
            raise InputError(f"{where}: cannot read as PLY: {echo(exc) or type(exc).__name__}") from None
        vertices = np.asarray(getattr(cloud, "vertices", np.zeros((0, 3))), float).reshape(-1, 3)
        if len(vertices) > MAX_POINTS:
            raise InputError(f"{where}: {len(vertices)} points; expected at most {MAX_POINTS}")
        return vertices, None, None, None
    import laspy

    check_las_layout(path, size, where)
    try:
        with _quiet("laspy"), laspy.open(str(path)) as reader:
            check_las_header(reader.header, where)
            las = reader.read()
    except InputError:
        raise
    except Exception as exc:  # corrupt headers and bodies raise LaspyException, ValueError, struct and lazrs errors
        raise InputError(f"{where}: cannot read as LAS/LAZ: {echo(exc) or type(exc).__name__}") from None
    if len(las.points) != las.header.point_count:
        raise InputError(f"{where}: {len(las.points)} of the {las.header.point_count} points the header announces "
                         f"could be read; expected a complete file")
    xyz = np.column_stack([np.asarray(las.x, float), np.asarray(las.y, float), np.asarray(las.z, float)])
    classes = np.asarray(las.classification, np.uint8)
    crs_text, units = las_crs_units(las.header, where)
    return xyz, (classes if np.any(classes > 1) else None), crs_text, units


def las_crs_units(header, where: str) -> tuple[str | None, LinearUnits | None]:
    """(CRS text, linear units) of a LAS header: its OGC WKT (VLR or EVLR) when it has one, else its GeoTIFF
    keys; (None, None) when it has neither."""
    from pyproj.exceptions import CRSError

    records = list(header.vlrs) + list(getattr(header, "evlrs", None) or [])
    for vlr in records:
        wkt = getattr(vlr, "string", None)
        if type(vlr).__name__ == "WktCoordinateSystemVlr" and wkt and wkt.strip("\x00 "):
            text = wkt.strip("\x00 ")
            try:
                from pyproj import CRS

                crs = CRS.from_wkt(text)
            except CRSError as exc:
                raise InputError(f"{where}: the WKT CRS record cannot be read ({echo(str(exc)[:160])}); expected OGC "
                                 f"WKT (or give --crs)") from None
            return crs.to_string(), crs_units(crs, "WKT", where)
    for vlr in records:
        if type(vlr).__name__ == "GeoKeyDirectoryVlr":
            keys = {int(k.id): int(k.value_offset) for k in vlr.geo_keys if int(k.tiff_tag_location) == 0}
            units = geotiff_units(keys, where)
            code = keys.get(PROJECTED_CRS)
            return (f"EPSG:{code}" if code and code != USER_DEFINED else "GeoTIFF keys (user-defined CRS)"), units
    return None, None


def triangulate_height_field(points: np.ndarray, max_edge_factor: float = 8.0) -> np.ndarray:
    """(m, 3) int64 triangles over the points' least-squares plane; edges longer than ``max_edge_factor``
    times the median edge are dropped so that gaps are not bridged."""
    from scipy.spatial import Delaunay, QhullError

    normal, _ = fit_plane(points)
    u = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    uv = np.column_stack([points @ u, points @ v])
    try:
        tri = Delaunay(uv).simplices.astype(np.int64)
    except QhullError:
        return np.zeros((0, 3), np.int64)
    edges = np.stack([np.linalg.norm(uv[tri[:, i]] - uv[tri[:, (i + 1) % 3]], axis=1) for i in range(3)], axis=1)
    longest = edges.max(axis=1)
    keep = longest <= max_edge_factor * np.median(edges)
    tri = tri[keep]
    # Face the plane's normal (up for ground and roofs).
    if len(tri):
        n = np.cross(points[tri[:, 1]] - points[tri[:, 0]], points[tri[:, 2]] - points[tri[:, 0]])
        flip = n @ normal < 0
        tri[flip] = tri[flip][:, ::-1]
    return tri


@dataclass(frozen=True)
class Simplified:
    """A simplified surface and what was measured on it (metres)."""

    points: np.ndarray
    triangles: np.ndarray
    faces_before: int
    deviation_m: float          # symmetric Hausdorff, reconstructed ↔ simplified
    residuals_m: np.ndarray     # (n,) float64: distance of every input point to the simplified mesh
    note: str = ""              # why it was not simplified, when it was not


def simplify_within(points: np.ndarray, triangles: np.ndarray, cloud: np.ndarray, max_deviation_m: float) -> Simplified:
    """Halve the face count with quadric edge collapse while the symmetric Hausdorff distance between the
    reconstructed mesh (``points``, ``triangles``) and the simplified one stays within ``max_deviation_m``;
    return the last mesh that did, with its measured deviation and the residual of ``cloud`` to it."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=cloud), "cloud")  # id 0
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, face_matrix=triangles.astype(np.int32)), "reconstructed")  # id 1
    # Faces are sampled too, so that a simplified triangle bulging away from the surface is caught.
    samples = max(4 * len(triangles), 1000)

    def hausdorff(a: int, b: int, faces: bool) -> dict:
        return ms.get_hausdorff_distance(sampledmesh=a, targetmesh=b, samplevert=True, sampleface=faces,
                                         samplenum=samples, maxdist=pymeshlab.PercentageValue(100))

    best_id, best_dev, note = 1, 0.0, ""
    target = len(triangles)
    while target > 2:
        target //= 2
        ms.set_current_mesh(best_id)
        ms.generate_copy_of_current_mesh()
        trial = ms.current_mesh_id()
        ms.meshing_decimation_quadric_edge_collapse(targetfacenum=target, preserveboundary=True, boundaryweight=2.0,
                                                    preservenormal=True, planarquadric=True, qualitythr=0.3)
        dev = max(hausdorff(1, trial, True)["max"], hausdorff(trial, 1, True)["max"])
        if dev > max_deviation_m:
            if best_id == 1:
                note = (f"not simplified: halving to {target} faces deviated {dev:.4g} m, more than "
                        f"--max-deviation-m {max_deviation_m:g} m (the surface follows noisy points)")
            break
        best_id, best_dev = trial, dev
    # Every input point is sampled (MeshLab keeps the per-sample distances in a mesh of its own).
    ms.get_hausdorff_distance(sampledmesh=0, targetmesh=best_id, samplevert=True, sampleface=False,
                              samplenum=len(cloud), maxdist=pymeshlab.PercentageValue(100), savesample=True)
    residuals = np.abs(np.asarray(ms.mesh(ms.mesh_number() - 1).vertex_scalar_array(), float))
    mesh = ms.mesh(best_id)
    return Simplified(np.asarray(mesh.vertex_matrix(), float), np.asarray(mesh.face_matrix(), np.int64),
                      len(triangles), float(best_dev), residuals, note)


def residual_summary(residuals_m: np.ndarray, bound_m: float) -> dict:
    """The distribution of point-to-surface distances (metres): mean, RMS, percentiles 50/90/95/99, max, and
    how many points lie farther than ``bound_m``."""
    r = np.asarray(residuals_m, float)
    p50, p90, p95, p99 = (float(v) for v in np.percentile(r, [50, 90, 95, 99]))
    return {"residual_mean_m": float(r.mean()), "residual_rms_m": float(np.sqrt(np.mean(r * r))),
            "residual_p50_m": p50, "residual_p90_m": p90, "residual_p95_m": p95, "residual_p99_m": p99,
            "residual_max_m": float(r.max()), "points_beyond_bound": int((r > bound_m).sum())}


def import_pointcloud(path: str | Path, rules: AssignmentRules | None = None, max_deviation_m: float = 0.005,
                      plane_threshold_m: float = 0.02, min_plane_points: int = 50, seed: int = 0,
                      max_residual_m: float = 0.10, max_hull_residual_m: float = 1.0, crs: str | None = None,
                      units: str | None = None, show_progress: bool = False, **_ignored) -> TwinModel:
    """Segment, reconstruct and simplify a point cloud; the report holds the measured deviations.

    Coordinates are converted to metres before anything is measured: by ``crs`` (EPSG code or WKT; it
    replaces the file's), else ``units`` ('m', 'ft', 'us-ft'), else the file's own CRS (LAS WKT or GeoTIFF
    keys). A file whose unit none of these gives is refused.

    Every segment's point-to-surface distances are summarised in the report; a segment whose 95th percentile
    exceeds its bound (``max_residual_m``, for a tree's hull ``max_hull_residual_m``; metres) is a finding
    (``report['findings']``)."""
    path = Path(path)
    where = shown(path)
    MAX_DEVIATION.check(max_deviation_m, "max_deviation_m")
    PLANE_THRESHOLD.check(plane_threshold_m, "plane_threshold_m")
    MAX_RESIDUAL.check(max_residual_m, "max_residual_m")
    MAX_HULL_RESIDUAL.check(max_hull_residual_m, "max_hull_residual_m")
    xyz, classes, file_crs, found_units = read_points(path)
    if len(xyz) == 0:
        raise InputError(f"{where}: the point cloud has no points; expected at least 3")
    if not np.all(np.isfinite(xyz)):
        raise InputError(f"{where}: {int((~np.isfinite(xyz)).any(axis=1).sum())} points have NaN or infinite "
                         f"coordinates; expected finite coordinates")
    linear = resolve_units(found_units, crs, units, where,
                           "the file states no CRS" if file_crs is None else f"its CRS {echo(file_crs)} names no unit")
    xyz = xyz * linear.scale
    if np.abs(xyz).max() > COORDINATE.high:
        raise InputError(f"{where}: coordinates up to {np.abs(xyz).max():.3g} m; expected coordinates within "
                         f"±{COORDINATE.high:g} m")
    lo, hi = xyz.min(axis=0), xyz.max(axis=0)
    if (hi - lo).max() > MAX_EXTENT_M:
        raise InputError(f"{where}: points span {(hi - lo).max():.3g} m; expected at most {MAX_EXTENT_M:g} m (tile the "
                         f"cloud)")
    origin = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    local = xyz - origin
    found = segment(local, classes, np.random.default_rng(seed), plane_threshold_m, min_plane_points)
    objects, findings = [], []
    report = {"points": int(len(xyz)), "units": linear.as_report(), "file_crs": file_crs,
              "max_deviation_m": max_deviation_m, "max_residual_m": max_residual_m,
              "max_hull_residual_m": max_hull_residual_m,
              "segmentation": segmentation_report(found, len(xyz)), "segments": [], "findings": findings}
    counts: dict[str, int] = defaultdict(int)
    for region in tqdm(found.regions, desc="surfaces", unit="segment", disable=not show_progress):
        counts[region.kind] += 1
        name = f"{KIND_NAMES[region.kind]}_{counts[region.kind]:02d}"
        fields = {"type": region.kind} if region.las_class is None else {"las_class": str(region.las_class)}
        label = _rule_or(rules, fields, KIND_CLASSES[region.kind])
        points = local[region.indices]
        surface, tris = _surface(region, points)
        source = f"las:{region.las_class}" if region.las_class is not None else region.kind
        if len(tris) == 0:
            log.warning("%s: segment %s (%d points) could not be triangulated; skipped", where, name, len(points))
            report["segments"].append({"name": name, "points": int(len(points)), "skipped": True})
            continue
        simple = simplify_within(surface, tris, points, max_deviation_m)
        material = class_material(label).key
        hull = region.kind == "tree"
        bound, option = (max_hull_residual_m, "--max-hull-residual-m") if hull else (max_residual_m, "--max-residual-m")
        residual = residual_summary(simple.residuals_m, bound)
        objects.append(TwinObject(name, label, (TwinPart("Surface", simple.points, simple.triangles, material),),
                                  {"segment_source": source, "simplification_deviation_m": simple.deviation_m,
                                   "residual_p95_m": residual["residual_p95_m"]}))
        report["segments"].append({"name": name, "label": label, "source": source, "kind": region.kind,
                                   "points": int(len(points)), "faces_reconstructed": simple.faces_before,
                                   "faces": int(len(simple.triangles)),
                                   "simplification_deviation_m": simple.deviation_m,
                                   **({"simplification_note": simple.note} if simple.note else {}),
                                   **residual, "residual_bound_m": bound,
                                   "surface": "convex hull" if hull else "surface"})
        if residual["residual_p95_m"] > bound:
            what = ("its convex hull wraps mostly empty space (trees merged into one cluster, or no tree)" if hull
                    else "the surface does not explain these points")
            findings.append(Finding("residual-bound", f"{where}: segment {name}",
                                    f"95 % of its {len(points)} points lie within "
                                    f"{residual['residual_p95_m']:.3f} m of its {'convex hull' if hull else 'surface'} "
                                    f"(max {residual['residual_max_m']:.3f} m); expected within {bound:g} m "
                                    f"({option}): {what}", Severity.WARNING).to_dict())
    if not objects:
        raise InputError(f"{where}: no surface could be reconstructed from {len(xyz)} points; expected points that "
                         f"sample surfaces (at least 3 not on one line)")
    return TwinModel(objects=tuple(objects), materials=subset(p.material for o in objects for p in o.parts),
                     source=str(path), double_sided=True,
                     origin_offset_m=tuple(float(v) for v in origin), crs=crs or file_crs, report=report)


#: Region kind → segment name and default class (a rules file may override by ``type`` or ``las_class``).
KIND_NAMES = {"ground": "Ground", "ground_plane": "GroundPlane", "roof": "Roof", "facade": "Facade", "tree": "Tree"}
KIND_CLASSES = {"ground": "road", "ground_plane": "road", "roof": "building", "facade": "building",
                "tree": "vegetation"}


def _surface(region: Region, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(points, triangles) of a region's surface: a tree's convex hull (outward faces); a plane's inliers
    projected onto it, or the ground's points smoothed (moving least squares), triangulated as a height field."""
    if region.kind == "tree":
        import trimesh

        try:
            hull = trimesh.convex.convex_hull(points)
        except Exception:  # qhull refuses flat or degenerate clusters  # noqa: BLE001
            return points, np.zeros((0, 3), np.int64)
        return np.asarray(hull.vertices, float), np.asarray(hull.faces, np.int64)
    if region.plane is not None:
        normal, d = region.plane
        surface = points - np.outer(points @ normal + d, normal)
    else:
        surface = smoothed_heights(points)
    return surface, triangulate_height_field(surface)


def segmentation_report(found: Segmentation, total: int) -> dict:
    """Counts of the segmentation: regions by kind, points by kind, the unfit points and their share."""
    by_kind: dict[str, int] = defaultdict(int)
    regions: dict[str, int] = defaultdict(int)
    for region in found.regions:
        by_kind[region.kind] += len(region.indices)
        regions[region.kind] += 1
    return {"ground_from": found.ground_source, "regions": dict(regions), "points_by_kind": dict(by_kind),
            "unfit_points": int(len(found.unfit)), "unfit_share": len(found.unfit) / max(total, 1)}


def _rule_or(rules: AssignmentRules | None, fields: dict, default: str) -> str:
    if rules is None:
        return default
    label, rule = rules.classify(fields)
    return label if rule is not None else default
