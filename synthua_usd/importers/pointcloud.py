"""Point clouds (LAS, LAZ, PLY) → labelled, simplified surface meshes.

1. Segments: the LAS classification when the file has one (ground, vegetation, building, ...); the
   points it leaves unclassified go through RANSAC plane detection, each plane refitted by least
   squares (min Σ(n·Xᵢ + d)², the smallest singular vector of the centred inliers) and named by its
   normal: ground (horizontal, lowest), roof (horizontal above ground, or sloped) or façade (vertical).
2. Surfaces: a plane's inliers are projected onto it (the model is the fitted plane, bounded by its
   points); other segments (LAS ground, trees, what no plane explains) keep their points. Either way the
   points are triangulated as a height field over the segment's least-squares plane (2-D Delaunay in
   plane coordinates, long edges dropped).
3. Simplification: MeshLab's quadric edge collapse (pymeshlab), halving the face count while the
   symmetric Hausdorff distance between the reconstructed and the simplified mesh (MeshLab's own
   sampling filter, both ways) stays within ``max_deviation_m`` (default 5 mm, the paper's ε).
   Reported per segment: that simplification deviation, and the residual from the input points to the
   final mesh (max, mean, RMS), which also holds the sensor noise the plane fit removed.
"""

from __future__ import annotations

import contextlib
import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import numpy as np
from tqdm import tqdm

from synthua_usd.class_assignment import AssignmentRules
from synthua_usd.errors import InputError, echo
from synthua_usd.findings import Finding, Severity
from synthua_usd.importers.crs import (PROJECTED_CRS, USER_DEFINED, LinearUnits, crs_units, geotiff_units,
                                       resolve_units)
from synthua_usd.importers.limits import (MAX_DEVIATION, MAX_EXTENT_M, MAX_POINTCLOUD_BYTES, MAX_POINTS,
                                          MAX_RESIDUAL, PLANE_THRESHOLD)
from synthua_usd.input_files import check_input_file, shown
from synthua_usd.materials import class_material, subset
from synthua_usd.ranges import COORDINATE
from synthua_usd.twin import TwinModel, TwinObject, TwinPart

log = logging.getLogger(__name__)

SUFFIXES = (".las", ".laz", ".ply")

#: ASPRS LAS 1.4 classification codes → classes. 1 (unclassified) and 0 (never classified) go through
#: plane detection instead.
LAS_CLASSES = {2: "road", 3: "vegetation", 4: "vegetation", 5: "vegetation", 6: "building", 9: "unlabelled",
               11: "road", 17: "road"}
LAS_NAMES = {0: "never_classified", 1: "unclassified", 2: "ground", 3: "low_vegetation", 4: "medium_vegetation",
             5: "high_vegetation", 6: "building", 7: "noise", 9: "water", 11: "road_surface", 17: "bridge_deck"}
PLANE_CLASSES = {"ground": "road", "roof": "building", "facade": "building"}
#: Largest point data a LAS/LAZ header may announce (points x record length), decompressed in memory.
MAX_POINT_DATA_BYTES = 2 * 2**30


@dataclass(frozen=True)
class Segment:
    name: str
    label: str
    points: np.ndarray  # (n, 3) local metres
    source: str         # "las:<code>", "plane" or "rest"
    plane: tuple[np.ndarray, float] | None = None  # (unit normal, d) of a detected plane

    def surface_points(self) -> np.ndarray:
        """The points the surface goes through: projected onto the plane for plane segments."""
        if self.plane is None:
            return self.points
        normal, d = self.plane
        return self.points - np.outer(self.points @ normal + d, normal)


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


def _check_las_header(header, size: int, where: str) -> None:
    """Refuse a LAS/LAZ header whose point count, record size, scales or offsets cannot be true of this file
    (before any point is read, so that a lying header cannot make us allocate what it claims)."""
    count, record = int(header.point_count), int(header.point_format.size)
    if count > MAX_POINTS:
        raise InputError(f"{where}: the header announces {count} points; expected at most {MAX_POINTS} (thin or tile "
                         f"the cloud)")
    if count * record > MAX_POINT_DATA_BYTES:
        raise InputError(f"{where}: the header announces {count} points of {record} bytes ({count * record} bytes); "
                         f"expected at most {MAX_POINT_DATA_BYTES} bytes of point data")
    if not header.are_points_compressed and int(header.offset_to_point_data) + count * record > size:
        held = max(size - int(header.offset_to_point_data), 0) // max(record, 1)
        raise InputError(f"{where}: the header announces {count} points but the file holds {held}; expected a "
                         f"complete LAS file")
    scales, offsets = np.asarray(header.scales, float), np.asarray(header.offsets, float)
    if not (np.all(np.isfinite(scales)) and np.all(scales > 0) and np.all(scales <= 1e3)):
        raise InputError(f"{where}: header scale factors {echo(scales.tolist())}; expected numbers in (0, 1000]")
    if not np.all(np.abs(offsets) <= COORDINATE.high):  # NaN fails too
        raise InputError(f"{where}: header offsets {echo(offsets.tolist())}; expected numbers within "
                         f"±{COORDINATE.high:g} m")


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

    try:
        with _quiet("laspy"), laspy.open(str(path)) as reader:
            _check_las_header(reader.header, size, where)
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


def fit_plane(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares plane: unit normal n and offset d minimising Σ(n·Xᵢ + d)²."""
    centroid = points.mean(axis=0)
    normal = np.linalg.svd(points - centroid, full_matrices=False)[2][-1]
    if normal[2] < 0:
        normal = -normal
    return normal, -float(normal @ centroid)


def ransac_planes(points: np.ndarray, rng: np.random.Generator, threshold_m: float, min_points: int,
                  max_planes: int = 8, iterations: int = 300) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """Planes as (inlier indices, normal, d), biggest first. Each RANSAC winner is refitted by least squares
    on its inliers and its inliers recomputed."""
    remaining = np.arange(len(points))
    planes = []
    while len(remaining) >= max(min_points, 3) and len(planes) < max_planes:
        pts = points[remaining]
        best = None
        for _ in range(iterations):
            a, b, c = pts[rng.choice(len(pts), 3, replace=False)]
            n = np.cross(b - a, c - a)
            norm = np.linalg.norm(n)
            if norm < 1e-12:
                continue
            n /= norm
            inliers = np.abs((pts - a) @ n) <= threshold_m
            count = int(inliers.sum())
            if best is None or count > best[0]:
                best = (count, inliers)
        if best is None or best[0] < min_points:
            break
        normal, d = fit_plane(pts[best[1]])
        inliers = np.abs(pts @ normal + d) <= threshold_m
        if inliers.sum() < min_points:
            break
        planes.append((remaining[inliers], normal, d))
        remaining = remaining[~inliers]
    return planes


def _plane_kind(normal: np.ndarray, points: np.ndarray, ground_z: float) -> str:
    nz = abs(normal[2])
    if nz >= 0.9:
        return "ground" if points[:, 2].mean() - ground_z < 1.0 else "roof"
    return "facade" if nz < 0.3 else "roof"


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

    best_id, best_dev = 1, 0.0
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
            break
        best_id, best_dev = trial, dev
    # Every input point is sampled (MeshLab keeps the per-sample distances in a mesh of its own).
    ms.get_hausdorff_distance(sampledmesh=0, targetmesh=best_id, samplevert=True, sampleface=False,
                              samplenum=len(cloud), maxdist=pymeshlab.PercentageValue(100), savesample=True)
    residuals = np.abs(np.asarray(ms.mesh(ms.mesh_number() - 1).vertex_scalar_array(), float))
    mesh = ms.mesh(best_id)
    return Simplified(np.asarray(mesh.vertex_matrix(), float), np.asarray(mesh.face_matrix(), np.int64),
                      len(triangles), float(best_dev), residuals)


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
                      max_residual_m: float = 0.10, crs: str | None = None, units: str | None = None,
                      show_progress: bool = False, **_ignored) -> TwinModel:
    """Segment, reconstruct and simplify a point cloud; the report holds the measured deviations.

    Coordinates are converted to metres before anything is measured: by ``crs`` (EPSG code or WKT; it
    replaces the file's), else ``units`` ('m', 'ft', 'us-ft'), else the file's own CRS (LAS WKT or GeoTIFF
    keys). A file whose unit none of these gives is refused.

    Every segment's point-to-surface distances are summarised in the report; a segment whose 95th percentile
    exceeds ``max_residual_m`` is a finding (``report['findings']``)."""
    path = Path(path)
    where = shown(path)
    MAX_DEVIATION.check(max_deviation_m, "max_deviation_m")
    PLANE_THRESHOLD.check(plane_threshold_m, "plane_threshold_m")
    MAX_RESIDUAL.check(max_residual_m, "max_residual_m")
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
    rng = np.random.default_rng(seed)

    segments: list[Segment] = []
    unclassified = np.arange(len(local))
    if classes is not None:
        unclassified = np.flatnonzero(classes <= 1)
        for code in sorted(set(classes.tolist()) - {0, 1, 7}):
            label = _rule_or(rules, {"las_class": str(code)}, LAS_CLASSES.get(code, "unlabelled"))
            segments.append(Segment(f"LAS_{LAS_NAMES.get(code, code)}", label, local[classes == code], f"las:{code}"))
    if len(unclassified) >= 3:
        pts = local[unclassified]
        ground_z = float(np.percentile(local[:, 2], 2))
        planes = ransac_planes(pts, rng, plane_threshold_m, min_plane_points)
        used = np.zeros(len(pts), bool)
        for k, (idx, normal, d) in enumerate(planes):
            kind = _plane_kind(normal, pts[idx], ground_z)
            label = _rule_or(rules, {"type": kind}, PLANE_CLASSES[kind])
            segments.append(Segment(f"Plane_{k:02d}_{kind}", label, pts[idx], "plane", (normal, d)))
            used[idx] = True
        rest = pts[~used]
        if len(rest) >= 3:
            segments.append(Segment("Unsegmented", _rule_or(rules, {"type": "unsegmented"}, "unlabelled"), rest, "rest"))
    objects, findings = [], []
    report = {"points": int(len(xyz)), "units": linear.as_report(), "file_crs": file_crs,
              "max_deviation_m": max_deviation_m, "max_residual_m": max_residual_m, "segments": [],
              "findings": findings}
    for seg in tqdm(segments, desc="surfaces", unit="segment", disable=not show_progress):
        surface = seg.surface_points()
        tris = triangulate_height_field(surface)
        if len(tris) == 0:
            log.warning("%s: segment %s (%d points) could not be triangulated; skipped", where, seg.name, len(seg.points))
            report["segments"].append({"name": seg.name, "points": int(len(seg.points)), "skipped": True})
            continue
        simple = simplify_within(surface, tris, seg.points, max_deviation_m)
        material = class_material(seg.label).key
        residual = residual_summary(simple.residuals_m, max_residual_m)
        objects.append(TwinObject(seg.name, seg.label, (TwinPart("Surface", simple.points, simple.triangles, material),),
                                  {"segment_source": seg.source, "simplification_deviation_m": simple.deviation_m,
                                   "residual_p95_m": residual["residual_p95_m"]}))
        report["segments"].append({"name": seg.name, "label": seg.label, "source": seg.source,
                                   "points": int(len(seg.points)), "faces_reconstructed": simple.faces_before,
                                   "faces": int(len(simple.triangles)), "simplification_deviation_m": simple.deviation_m,
                                   **residual})
        if residual["residual_p95_m"] > max_residual_m:
            findings.append(Finding("residual-bound", f"{where}: segment {seg.name}",
                                    f"95 % of its {len(seg.points)} points lie within "
                                    f"{residual['residual_p95_m']:.3f} m "
                                    f"of its surface (max {residual['residual_max_m']:.3f} m); expected within "
                                    f"{max_residual_m:g} m (--max-residual-m): the surface does not explain these "
                                    f"points", Severity.WARNING).to_dict())
    if not objects:
        raise InputError(f"{where}: no surface could be reconstructed from {len(xyz)} points; expected points that "
                         f"sample surfaces (at least 3 not on one line)")
    return TwinModel(objects=tuple(objects), materials=subset(p.material for o in objects for p in o.parts),
                     source=str(path), double_sided=True,
                     origin_offset_m=tuple(float(v) for v in origin), crs=crs or file_crs, report=report)


def _rule_or(rules: AssignmentRules | None, fields: dict, default: str) -> str:
    if rules is None:
        return default
    label, rule = rules.classify(fields)
    return label if rule is not None else default
