"""The demo district's geometry leaves no first hit ambiguous.

Two instances whose faces lie in one plane, facing the same way and overlapping, give pixels whose label
depends on the ray caster's rounding; solids that run into each other are modelling faults that end the
same way when their faces meet. So: no two instances share visible area in a face plane, no object runs
into another beyond planting in the ground, and CCTV_Largo's labels agree with an independent Embree cast.
The first two are checked on the twin model, without rendering; the third renders the committed stage.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
import shapely
from scipy.optimize import linprog
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from conftest import STAGES
from reference_raycast import edge_distance, reference_labels
from synthua_usd.demo.district import build_district
from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinObject, TwinPart

#: Faces whose planes are this close (metres) count as coplanar: far more than float32 rounding of
#: district coordinates (~1e-5 m), far less than the 5 cm by which doors and windows stand proud.
PLANE_TOL_M = 1e-3
#: Shared area (m²) below which two faces merely touch along an edge.
AREA_TOL_M2 = 1e-6
#: Two solids overlap when a ball this large (radius, metres) fits inside both.
DEPTH_TOL_M = 1e-3
#: Ground the district stands on, and what may stand planted in it (foundations, posts, trunks, steps).
TERRAIN = frozenset({"grass", "road", "street_road", "sidewalk", "curb_ramp"})
PLANTED = TERRAIN | {"building", "vegetation", "light_pole", "signage", "railing"}


# --- coplanar faces ---------------------------------------------------------------------------------------

def _faces(objects: list[TwinObject]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Corners (m, 3, 3), owning object index (m,) and unit normal (m, 3) of every non-degenerate triangle."""
    corners = np.concatenate([p.points[p.triangles] for o in objects for p in o.parts])
    owner = np.concatenate([np.full(len(p.triangles), k) for k, o in enumerate(objects) for p in o.parts])
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(normal, axis=1)
    keep = length > 1e-12
    return corners[keep], owner[keep], normal[keep] / length[keep, None]


def coplanar_overlaps(objects: list[TwinObject]) -> dict[tuple[str, str], float]:
    """Pairs of objects with faces in one plane, facing the same way, that share visible area: area (m²)
    by pair of paths. Area pressed against an opposite-facing face in that plane (two solids touching, a
    window's back on its wall) is hidden and not counted."""
    corners, owner, normal = _faces(objects)
    # One orientation per plane: the first clearly non-zero component positive; ``facing`` keeps the sign.
    lead = np.select([np.abs(normal[:, 0]) > 1e-9, np.abs(normal[:, 1]) > 1e-9], [normal[:, 0], normal[:, 1]], normal[:, 2])
    facing = np.sign(lead).astype(np.int64)
    axis = normal * facing[:, None]
    offset = np.einsum("ij,ij->i", axis, corners[:, 0])
    key = np.round(axis * 1e4).astype(np.int64)
    order = np.lexsort((offset, key[:, 2], key[:, 1], key[:, 0]))
    new_plane = np.ones(len(order), bool)
    new_plane[1:] = np.any(key[order][1:] != key[order][:-1], axis=1) | (np.diff(offset[order]) > PLANE_TOL_M)
    starts = np.flatnonzero(new_plane)
    found: dict[tuple[str, str], float] = {}
    for idx in np.split(order, starts[1:]):
        own, face = owner[idx], facing[idx]
        sides = [f for f in (1, -1) if len(np.unique(own[face == f])) > 1]
        if not sides:
            continue
        n = axis[idx[0]]
        u = np.cross(n, (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0))
        u /= np.linalg.norm(u)
        v = np.cross(n, u)
        flat = np.stack([corners[idx] @ u, corners[idx] @ v], axis=-1)
        polygons = shapely.polygons(np.concatenate([flat, flat[:, :1]], axis=1))
        for f in sides:
            mine = face == f
            union = {k: shapely.union_all(polygons[mine & (own == k)]) for k in np.unique(own[mine])}
            pressed = polygons[face == -f]
            keys = sorted(union)
            for i, a in enumerate(keys):
                for b in keys[i + 1:]:
                    shared = shapely.intersection(union[a], union[b])
                    if shared.area > AREA_TOL_M2 and len(pressed):
                        against = pressed[shapely.intersects(pressed, shared)]
                        if len(against):
                            shared = shapely.difference(shared, shapely.union_all(against))
                    if shared.area > AREA_TOL_M2:
                        pair = (objects[a].path, objects[b].path)
                        found[pair] = found.get(pair, 0.0) + float(shared.area)
    return found


# --- interpenetrating solids ------------------------------------------------------------------------------

class _ConvexPieces:
    """An object's connected pieces (our builders merge boxes, cylinders, ellipsoids and hulls: all convex):
    ``lo``, ``hi`` (k, 3) bounding boxes of all, and each one's half-spaces when asked for."""

    def __init__(self, obj: TwinObject) -> None:
        self._faces, lo, hi = [], [], []
        for part in obj.parts:
            tris = part.triangles
            n_points = len(part.points)
            links = coo_matrix((np.ones(2 * len(tris)), (tris[:, :2].ravel(), tris[:, 1:].ravel())),
                               shape=(n_points, n_points))
            _, piece_of_point = connected_components(links, directed=False)
            order = np.argsort(piece_of_point[tris[:, 0]], kind="stable")
            starts = np.flatnonzero(np.diff(piece_of_point[tris[order, 0]], prepend=-1))
            corners = part.points[tris[order]]
            lo.append(np.minimum.reduceat(corners.min(axis=1), starts))
            hi.append(np.maximum.reduceat(corners.max(axis=1), starts))
            self._faces += [(part, f) for f in np.split(corners, starts[1:])]
        self.lo, self.hi = np.concatenate(lo), np.concatenate(hi)
        self._half_spaces: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def half_spaces(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Unit normals (f, 3) and offsets (f,) of piece ``k``: inside is n·x <= d."""
        if k not in self._half_spaces:
            part, corners = self._faces[k]
            normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
            length = np.linalg.norm(normal, axis=1)
            keep = length > 1e-12
            normal = normal[keep] / length[keep, None]
            offset = np.einsum("ij,ij->i", normal, corners[keep, 0])
            assert np.all(corners.reshape(-1, 3) @ normal.T <= offset + 1e-6), \
                f"part {part.name}: a piece is not convex; split it into convex pieces for this check"
            self._half_spaces[k] = normal, offset
        return self._half_spaces[k]


def _shared_depth_m(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> float:
    """Radius (metres) of the largest ball inside both convex pieces; <= 0 when they are apart or touch."""
    normal = np.concatenate([a[0], b[0]])
    offset = np.concatenate([a[1], b[1]])
    result = linprog(c=[0.0, 0.0, 0.0, -1.0], A_ub=np.column_stack([normal, np.ones(len(normal))]), b_ub=offset,
                     bounds=[(None, None)] * 3 + [(None, 1.0)], method="highs")
    return -result.fun if result.status == 0 else 0.0


def _boxes_overlap(lo_a, hi_a, lo_b, hi_b) -> np.ndarray:
    """Whether boxes overlap by more than DEPTH_TOL_M on every axis (broadcasting over leading axes)."""
    return np.all((lo_a < hi_b - DEPTH_TOL_M) & (lo_b < hi_a - DEPTH_TOL_M), axis=-1)


def interpenetrations(objects: list[TwinObject]) -> dict[tuple[str, str], float]:
    """Pairs of objects whose solids overlap by more than DEPTH_TOL_M, except terrain with what is planted
    in it: depth (radius of the largest common ball, metres) by pair of paths."""
    pieces = [_ConvexPieces(o) for o in objects]
    lo = np.array([p.lo.min(axis=0) for p in pieces])
    hi = np.array([p.hi.max(axis=0) for p in pieces])
    found = {}
    for a, obj in enumerate(objects):
        for b in np.flatnonzero(_boxes_overlap(lo[a], hi[a], lo, hi)):
            labels = {obj.label, objects[b].label}
            if b <= a or (labels & TERRAIN and labels <= PLANTED):
                continue
            pa, pb = pieces[a], pieces[b]
            near_a = np.flatnonzero(_boxes_overlap(pa.lo, pa.hi, lo[b], hi[b]))
            near_b = np.flatnonzero(_boxes_overlap(pb.lo, pb.hi, lo[a], hi[a]))
            i, j = np.nonzero(_boxes_overlap(pa.lo[near_a, None], pa.hi[near_a, None], pb.lo[near_b], pb.hi[near_b]))
            depth = max((_shared_depth_m(pa.half_spaces(near_a[m]), pb.half_spaces(near_b[n])) for m, n in zip(i, j)),
                        default=0.0)
            if depth > DEPTH_TOL_M:
                found[(obj.path, objects[b].path)] = depth
    return found


# --- the checks on hand-made cases ------------------------------------------------------------------------

def _box_object(path: str, label: str, lo, hi) -> TwinObject:
    return TwinObject(path, label, (TwinPart.of("Box", geo.box(lo, hi), "Glass"),))


def test_coplanar_check_finds_overlapping_windows_but_not_a_window_on_its_wall():
    wall = _box_object("Wall", "building", (-5.0, -1.0, 0.0), (0.0, 1.0, 3.0))
    window_a = _box_object("WindowA", "window", (0.0, -0.7, 1.0), (0.06, 0.0, 2.0))
    window_b = _box_object("WindowB", "window", (0.0, -0.1, 1.0), (0.06, 0.6, 2.0))
    found = coplanar_overlaps([wall, window_a, window_b])
    assert set(found) == {("WindowA", "WindowB")}
    # 0.1 m x 1 m of their fronts and 0.1 m x 6 cm of their tops and of their bottoms; their backs are
    # pressed against the wall, hidden.
    assert found[("WindowA", "WindowB")] == pytest.approx(0.1 + 2 * 0.1 * 0.06)


def test_interpenetration_check_finds_overlapping_bicycles_but_allows_a_planted_post():
    ground = _box_object("Ground", "grass", (-5.0, -5.0, -1.0), (5.0, 5.0, 0.0))
    post = _box_object("Post", "light_pole", (-0.05, -0.05, -0.3), (0.05, 0.05, 3.0))
    bike_a = _box_object("BikeA", "bicycle", (1.0, 0.0, 0.0), (2.8, 0.5, 1.0))
    bike_b = _box_object("BikeB", "bicycle", (1.0, 0.3, 0.0), (2.8, 0.8, 1.0))
    bike_c = _box_object("BikeC", "bicycle", (1.0, 0.8, 0.0), (2.8, 1.3, 1.0))  # touches B only
    found = interpenetrations([ground, post, bike_a, bike_b, bike_c])
    assert set(found) == {("BikeA", "BikeB")}
    assert found[("BikeA", "BikeB")] == pytest.approx(0.1)


# --- the district -----------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def district_objects() -> list[TwinObject]:
    # Untextured: texture seams split points (uv.box_uvs), which would cut the pieces apart, and texturing
    # moves no triangle (tests/demo/test_district_textures.py), so the geometry checked is the same.
    return list(build_district(0, textures=False).objects)


@pytest.mark.slow
def test_no_two_district_instances_share_visible_area_in_a_face_plane(district_objects):
    found = coplanar_overlaps(district_objects)
    assert not found, "coplanar faces of two instances (m²): " + \
        "; ".join(f"{a} & {b}: {area:.4f}" for (a, b), area in sorted(found.items()))


@pytest.mark.slow
def test_no_district_object_runs_into_another_but_for_planting_in_the_ground(district_objects):
    found = interpenetrations(district_objects)
    assert not found, "solids overlapping by more than 1 mm (depth, m): " + \
        "; ".join(f"{a} & {b}: {depth:.4f}" for (a, b), depth in sorted(found.items()))


@pytest.mark.slow
def test_cctv_largo_labels_agree_with_embree_on_every_pixel():
    """The committed district without its agents (their geometry is checked with the agents), 640x480.

    A failure lists the disagreeing instance pairs; ``tools/bench_label_agreement.py`` shows the gap
    between the two hits: ~0 is two surfaces on top of each other, a clear gap a ray grazing an edge."""
    from pxr import Usd

    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(STAGES / "district" / "scenario.usda")
    stage.SetEditTarget(Usd.EditTarget(stage.GetSessionLayer()))
    stage.GetPrimAtPath("/World/Agents").SetActive(False)
    snapshot = StageReader(stage, ClassMap.default()).snapshot(24.0)
    camera = read_camera(stage, "/World/Cameras/CCTV_Largo", 24.0)
    frame = RenderSession(RenderConfig(width=640, height=480, spp=1)).render(snapshot, camera, rgb=False)
    _, ref_instances = reference_labels(snapshot, camera, 640, 480)
    differ = frame.instance_ids != ref_instances
    # A ray within 10 µm of an edge of either instance is a float edge case (the casts' rays differ by float32
    # rounding; either answer is right); anywhere else the two must agree. At most a few such grazing rays.
    origins, dirs = camera.pixel_center_rays(640, 480)
    grazing = [k for k in np.flatnonzero(differ.ravel())
               if min(edge_distance(snapshot, int(frame.instance_ids.flat[k]), origins[k], dirs[k]),
                      edge_distance(snapshot, int(ref_instances.flat[k]), origins[k], dirs[k])) < 1e-5]
    assert len(grazing) <= 3, f"{len(grazing)} grazing rays differ"
    differ.flat[grazing] = False
    path = {i.id: i.prim_path for i in snapshot.instances} | {0: "(nothing)"}
    pairs = Counter((path[int(a)], path[int(b)]) for a, b in zip(frame.instance_ids[differ], ref_instances[differ]))
    assert not pairs, f"{differ.sum()} pixels differ (mitsuba, embree) off any edge: {pairs.most_common(10)}"
