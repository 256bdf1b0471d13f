"""Automatic cameras for a twin that comes without any (imports), framed on what is there.

* ``Overview``: 45 or 60 degrees down, from the side (of 8) and at the least distance from which the boxes of
  the densest cluster of objects fit the frame, heights included (:func:`densest_cluster`,
  :func:`overview_view`). A sparse model spread over kilometres is framed on its biggest cluster, not on
  its whole extent.
* ``Street``: 1.6 m above a walkable or road surface found by casting rays down onto the twin (the first
  surface hit from above must be a street surface, so never under a roof, a tree or a bridge), near the
  cluster's centre, looking along the street there (the main axis of the street surfaces within
  :data:`STREET_RADIUS_M`) in the direction with the longer free view. Without street surfaces it stands on
  the generated ground (:mod:`synthua_usd.geometry.ground`) and looks at the cluster.

Every camera stands in free space outdoors (:mod:`synthua_usd.geometry.free_space`: not inside a closed surface, open
sky above, clear of every surface, a free view of several metres towards what it looks at): the overview
takes the tightest of its directions that does, the street camera the first such spot; when no street
spot is free, spots on rings round the cluster on the generated ground. A camera that finds none keeps the
least enclosed spot, and its report's ``placement`` says why (the import pipeline makes it a finding).

Whether each camera's label pass sees enough of the twin is checked by the import pipeline
(:mod:`synthua_usd.pipeline.twin_import`), which renders it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd.core.errors import InputError
from synthua_usd.geometry.free_space import check_eyes, first_hits
from synthua_usd.geometry.ground import REACH_M, height_at, is_ground
from synthua_usd.model.cameras import CameraSpec
from synthua_usd.model.twin import TwinModel, TwinObject

#: Classes a street-level camera may stand on.
STREET_CLASSES = ("road", "street_road", "sidewalk", "crosswalk", "curb_ramp")
#: Full-frame 24 mm: (focal length, horizontal and vertical aperture), millimetres.
LENS_MM = (24.0, 36.0, 24.0)
#: Half the frame's height over the focal length (12 / 24 mm), less a 5 % margin: the tangent every
#: corner of the framed box must stay within, horizontally and vertically (whatever the image's aspect,
#: between 3:2 and 4:3 the conformed frame is at least this wide and high).
FIT_TAN = 0.5 * 0.95
#: Eye height of the street camera above the surface it stands on (metres).
EYE_HEIGHT_M = 1.6
#: Street surfaces within this distance of the camera set the street's direction (metres).
STREET_RADIUS_M = 20.0
#: A street view whose free line of sight reaches this far is taken at once (metres).
GOOD_VIEW_M = 20.0
#: Street spots tried, nearest the cluster's centre first.
MAX_SPOTS = 64


@dataclass(frozen=True)
class Framing:
    """The automatic cameras and what they were framed on (for the import report)."""

    cameras: tuple[CameraSpec, ...]
    report: dict


def object_boxes(objects: list[TwinObject]) -> np.ndarray:
    """(n, 2, 3) float64: each object's axis-aligned box (min, max corner), local metres."""
    return np.array([[np.min([p.points.min(axis=0) for p in o.parts], axis=0),
                      np.max([p.points.max(axis=0) for p in o.parts], axis=0)] for o in objects])


def densest_cluster(boxes: np.ndarray) -> np.ndarray:
    """Indices of the boxes in the biggest cluster: boxes whose centres lie within a link distance of one
    another, chained (single linkage). The link distance is 3x the median distance from a box centre to its
    nearest neighbour, at least 10 m: neighbours in a block join, a village 1 km away does not."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    centres = boxes.mean(axis=1)[:, :2]
    if len(centres) < 3:
        return np.arange(len(centres))
    tree = cKDTree(centres)
    nearest = tree.query(centres, k=2)[0][:, 1]
    link = max(3.0 * float(np.median(nearest)), 10.0)
    pairs = tree.query_pairs(link, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(centres),) * 2)
    _, labels = connected_components(graph, directed=False)
    return np.flatnonzero(labels == np.bincount(labels).argmax())


def view_axes(forward: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(forward, right, up) unit vectors of a camera looking along ``forward`` with Z up."""
    f = forward / np.linalg.norm(forward)
    r = np.cross(f, [0.0, 0.0, 1.0])
    r /= np.linalg.norm(r)
    return f, r, np.cross(r, f)


def fit_view(points: np.ndarray, forward: np.ndarray, tan_half: float = FIT_TAN) -> tuple[np.ndarray, float]:
    """(target, distance): the point the camera looks at and the least distance back along ``forward`` from
    it at which all ``points`` (n, 3) lie within ``tan_half`` of the optical axis horizontally and vertically.
    The target centres the points' extent across the view (right and up axes)."""
    f, r, u = view_axes(forward)
    x, y = points @ r, points @ u
    target = points.mean(axis=0)
    target = target + r * ((x.max() + x.min()) / 2 - target @ r) + u * ((y.max() + y.min()) / 2 - target @ u)
    rel = points - target
    need = np.maximum(np.abs(rel @ r), np.abs(rel @ u)) / tan_half - rel @ f
    return target, float(max(need.max(), 1.0))


#: Overview directions tried: 8 azimuths at 45 and 60 degrees down; the one that frames the cluster from
#: the least distance (the largest on screen) wins.
OVERVIEW_DIRECTIONS = tuple((az, pitch) for pitch in (45.0, 60.0) for az in range(0, 360, 45))


def overview_views(points: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """(eye, target, distance) of the overview of ``points`` (n, 3) from every one of
    :data:`OVERVIEW_DIRECTIONS`, the tightest (least distance) first."""
    views = []
    for az, pitch in OVERVIEW_DIRECTIONS:
        a, p = np.radians(az), np.radians(pitch)
        forward = np.array([np.cos(p) * np.cos(a), np.cos(p) * np.sin(a), -np.sin(p)])
        target, dist = fit_view(points, forward)
        views.append((target - forward * dist, target, dist))
    best = 0
    for k, view in enumerate(views):  # ties (within 1 nm): the first direction
        if view[2] < views[best][2] - 1e-9:
            best = k
    return [views[best]] + sorted((v for k, v in enumerate(views) if k != best), key=lambda v: v[2])


def overview_view(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(eye, target, distance) of the tightest overview of ``points`` (n, 3) among :data:`OVERVIEW_DIRECTIONS`."""
    return overview_views(points)[0]


def automatic_cameras(model: TwinModel, ground: TwinObject) -> Framing:
    """``Overview`` and ``Street`` cameras for ``model`` standing on ``ground`` (full-frame 24 mm)."""
    objects = [o for o in model.objects if any(len(p.points) for p in o.parts)]
    if not objects:
        raise InputError(f"{model.source}: the import produced no geometry")
    # Framed: labelled objects that stand on the ground (buildings, trees, furniture); unlabelled ones (water,
    # generic objects) are not what the labels are about, and ground surfaces are everywhere.
    standing = ([o for o in objects if not is_ground(o) and o.label != "unlabelled"]
                or [o for o in objects if not is_ground(o)] or objects)
    boxes = object_boxes(standing)
    members = densest_cluster(boxes)
    lo, hi = boxes[members, 0].min(axis=0), boxes[members, 1].max(axis=0)
    corners = np.array([[b[i, 0], b[j, 1], b[k, 2]] for b in boxes[members] for i in (0, 1) for j in (0, 1)
                        for k in (0, 1)])
    mesh, street, paths = _scene(model, ground)
    views = overview_views(corners)
    checks = check_eyes(mesh, np.array([v[0] for v in views]), np.array([v[1] - v[0] for v in views]))
    k = next((i for i, c in enumerate(checks) if c.ok), 0)  # the tightest view from free space
    (eye, target, dist), check = views[k], checks[k]
    overview = CameraSpec("Overview", tuple(eye), tuple(target), *LENS_MM,
                          f"Oblique overview of the densest cluster of objects ({len(members)} of {len(standing)}).",
                          clip_near_m=max(0.05, dist / 1000), clip_far_m=REACH_M * 1.5)
    street, street_report = _street_camera(mesh, street, paths, ground, lo, hi)
    report = {"overview": {"cluster_objects": int(len(members)), "objects": len(standing),
                           "cluster_box_m": [lo.tolist(), hi.tolist()], "distance_m": dist,
                           "placement": check.as_report()},
              "street": street_report}
    return Framing((overview, street), report)


def _scene(model: TwinModel, ground: TwinObject):
    """The twin and its ground as one trimesh, and per face: whether it is a street surface, its object path."""
    import trimesh

    pts, tris, street, paths, n = [], [], [], [], 0
    for obj in (*model.objects, ground):
        for part in obj.parts:
            pts.append(part.points)
            tris.append(part.triangles + n)
            n += len(part.points)
            street.append(np.full(len(part.triangles), obj.label in STREET_CLASSES))
            paths += [obj.path] * len(part.triangles)
    mesh = trimesh.Trimesh(np.concatenate(pts), np.concatenate(tris), process=False)
    return mesh, np.concatenate(street), np.array(paths, dtype=object)


def _street_camera(mesh, street: np.ndarray, paths: np.ndarray, ground: TwinObject, lo: np.ndarray,
                   hi: np.ndarray):
    """The ``Street`` camera (a :class:`CameraSpec`) and its report: the first spot in free space
    (:mod:`synthua_usd.geometry.free_space`) of :func:`_street_spots`, else of :func:`_ground_ring`; when none is, the
    spot least inside geometry, whose report's ``placement`` says why it is not free."""
    centre = (lo + hi) / 2
    small = np.linalg.norm(hi[:2] - lo[:2]) < 2 * GOOD_VIEW_M
    candidates = _street_spots(mesh, street, paths, ground, centre)
    best, invalid, tried = None, None, 0
    for eye, dirs, path, foot in candidates:
        free, _ = first_hits(mesh, np.tile(eye, (len(dirs), 1)), dirs)
        j = int(np.argmax(free))
        view = _street_target(eye, dirs[j]) - eye
        check = check_eyes(mesh, eye[None], view[None])[0]
        tried += 1
        found = (eye, dirs[j], min(free[j], 1e6), path, foot, check)
        if not check.ok:
            invalid = found if invalid is None or check.rank() < invalid[5].rank() else invalid
            continue
        if best is None or found[2] > best[2]:
            best = found
        if best[2] >= GOOD_VIEW_M:
            break
    if best is None:  # nothing free on the street surfaces: ring the cluster on the generated ground
        best, ring_invalid, tried = _ground_ring(mesh, ground, centre, lo, hi, tried)
        if invalid is None or (ring_invalid is not None and ring_invalid[5].rank() < invalid[5].rank()):
            invalid = ring_invalid
    if best is None and invalid is None:  # nothing found by ray casting: the ground under the cluster's centre
        foot = np.array([centre[0], centre[1], float(height_at(ground, centre[None, :2])[0])])
        eye = foot + [0.0, 0.0, EYE_HEIGHT_M]
        d = np.array([1.0, 0.0, 0.0])
        invalid = (eye, d, 0.0, ground.path, foot, check_eyes(mesh, eye[None], d[None])[0])
    eye, d, _, path, foot, check = best if best is not None else invalid
    target = _street_target(eye, d)
    stepped = False
    if small and check.ok:
        # A small model: at eye level on it one sees over it. Step back until its box fits (at most 10 degrees
        # down), stand on the surface there and look at its centre: along the view first, then from 7 other
        # sides, the first spot in free space.
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        heading = np.arctan2(d[1], d[0])
        for turn in np.radians(np.arange(0, 360, 45)):
            horizontal = np.array([np.cos(heading + turn), np.sin(heading + turn), 0.0])
            aim, dist = fit_view(corners, horizontal - [0.0, 0.0, np.tan(np.radians(10.0))])
            back = aim[:2] - horizontal[:2] * dist
            stand = max(float(height_at(ground, back[None])[0]), float(lo[2]))
            back_eye = np.array([back[0], back[1], stand + EYE_HEIGHT_M])
            back_check = check_eyes(mesh, back_eye[None], (aim - back_eye)[None])[0]
            tried += 1
            if back_check.ok:
                eye, target, path, check = back_eye, aim, ground.path, back_check
                foot, stepped = np.array([back[0], back[1], stand]), True
                break
    camera = CameraSpec("Street", tuple(float(v) for v in eye), tuple(float(v) for v in target), *LENS_MM,
                        f"Eye level ({EYE_HEIGHT_M} m) on {path}, looking along it.", clip_near_m=0.05,
                        clip_far_m=REACH_M * 1.5)
    return camera, {"stands_on": str(path), "surface_z_m": float(foot[2]),
                    "free_view_m": float(min(check.free_view_m, 1e6)),
                    "on_street_surface": bool(np.any(street)) and path != ground.path, "stepped_back": stepped,
                    "spots_tried": tried, "placement": check.as_report()}


def _street_target(eye: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The point a street camera at ``eye`` looking along the horizontal ``d`` aims at: 10 m on, 0.5 m down."""
    return eye + 10.0 * d - [0.0, 0.0, 0.5]


def _street_spots(mesh, street: np.ndarray, paths: np.ndarray, ground: TwinObject, centre: np.ndarray):
    """Candidate street-camera spots nearest the cluster's ``centre`` first: (eye, (k, 3) view directions, path
    stood on, foot). On street surfaces whose first surface from above is a street surface, looking both ways
    along the street; without street surfaces, on the generated ground's faces, looking at the centre."""
    tris = mesh.triangles
    candidates = np.flatnonzero(street & (mesh.face_normals[:, 2] > 0.7))
    on_street = len(candidates) > 0
    if not on_street:
        candidates = np.flatnonzero(paths == ground.path)
    spots = tris[candidates].mean(axis=1)
    order = np.argsort(np.linalg.norm(spots[:, :2] - centre[:2], axis=1), kind="stable")[:MAX_SPOTS]
    top = float(mesh.bounds[1][2]) + 10.0
    origins = np.column_stack([spots[order, :2], np.full(len(order), top)])
    down, face = first_hits(mesh, origins, np.tile([0.0, 0.0, -1.0], (len(order), 1)))
    standing = street[face] if on_street else paths[face] == ground.path
    for k in np.flatnonzero((face >= 0) & standing):
        foot = origins[k] - [0.0, 0.0, down[k]]
        if on_street:
            same = candidates[paths[candidates] == paths[face[k]]]
            local = tris[same].mean(axis=1)
            local = local[np.linalg.norm(local[:, :2] - foot[:2], axis=1) <= STREET_RADIUS_M][:, :2]
            axis = (np.linalg.svd(local - local.mean(axis=0), full_matrices=False)[2][0] if len(local) > 2
                    else np.array([1.0, 0.0]))
            dirs = np.array([[axis[0], axis[1], 0.0], [-axis[0], -axis[1], 0.0]])
        else:  # look at the cluster, not away from it
            axis = centre[:2] - foot[:2]
            axis = axis / (np.linalg.norm(axis) or 1.0)
            dirs = np.array([[axis[0], axis[1], 0.0]])
        yield foot + [0.0, 0.0, EYE_HEIGHT_M], dirs, paths[face[k]], foot


#: Distances beyond the cluster's box (metres) and azimuths of the spots on the generated ground tried when no
#: street spot is in free space.
RING_MARGINS_M = (3.0, 8.0, 15.0, 30.0)
RING_AZIMUTHS = 16


def _ground_ring(mesh, ground: TwinObject, centre: np.ndarray, lo: np.ndarray, hi: np.ndarray, tried: int):
    """The first spot in free space on rings round the cluster's box, on the generated ground, looking at the
    cluster's centre, as (eye, direction, free view, path, foot, check), or None; the least enclosed spot that is
    not free (or None); and the spots tried so far."""
    radius = float(np.linalg.norm(hi[:2] - lo[:2])) / 2
    invalid = None
    for margin in RING_MARGINS_M:
        a = np.linspace(0.0, 2 * np.pi, RING_AZIMUTHS, endpoint=False)
        xy = centre[:2] + (radius + margin) * np.column_stack([np.cos(a), np.sin(a)])
        feet = np.column_stack([xy, height_at(ground, xy)])
        eyes = feet + [0.0, 0.0, EYE_HEIGHT_M]
        views = np.column_stack([centre[:2] - xy, np.zeros(len(xy))])
        views /= np.linalg.norm(views, axis=1, keepdims=True)
        checks = check_eyes(mesh, eyes, np.array([_street_target(e, v) for e, v in zip(eyes, views)]) - eyes)
        tried += len(eyes)
        free = [k for k, c in enumerate(checks) if c.ok]
        if free:
            k = max(free, key=lambda i: min(checks[i].free_view_m, 1e6))
            return (eyes[k], views[k], checks[k].free_view_m, ground.path, feet[k], checks[k]), None, tried
        k = min(range(len(checks)), key=lambda i: checks[i].rank())
        if invalid is None or checks[k].rank() < invalid[5].rank():
            invalid = (eyes[k], views[k], checks[k].free_view_m, ground.path, feet[k], checks[k])
    return None, invalid, tried
