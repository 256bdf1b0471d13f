"""Candidate placements of camera rigs, from geometry alone; which candidate sees its target best is
decided by rendering labels (:mod:`synthua_usd.pipeline.camera_rigs`).

Frames: world metres, Z up; every pose is a (4, 4) camera-to-world matrix (column vectors, camera looking
down its local -Z with +Y up, as :class:`synthua_usd.model.cameras.PinholeCamera`).

Where rigs stand:

* CCTV on a ``pole``: a sidewalk or grass cell with open sky above the camera; on a ``facade``: a cell
  beside a building (the wall carries the camera). Candidates ring the target at several azimuths and
  distances; the camera looks at the target's mean position over the animation.
* Eye level, standing: a walkable cell (sidewalk, crosswalk, curb ramp, cobbled street) around the
  target, open above; riding: :data:`RIDE_AHEAD_M` ahead of an agent's face, turning with the agent.
* UAV nadir: above the target (and four offsets of :data:`UAV_NADIR_OFFSET_M`), looking straight down;
  oblique: on a ring at ``height * tan(tilt)``, looking at the target.
* Dashcam: on the road's centreline (:mod:`synthua_usd.geometry.roads`), starting at points along the longest
  drive, in both directions.

A fixed camera's focal length, unless given, is the longest of its lens's range that keeps every corner
of the target's boxes (over the report's time codes) within :data:`FRAME_MARGIN` of the frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from synthua_usd.agents.walkable import WALKABLE, WalkableGrid, build_grid
from synthua_usd.composition.rigs import RigSpec
from synthua_usd.core.errors import InputError
from synthua_usd.geometry import roads
from synthua_usd.model import meshes as geo
from synthua_usd.model.cameras import PinholeCamera

FRAME_MARGIN = 0.8
MOUNT_CELL_M = 1.0
MOUNT_CLASSES = ("sidewalk", "grass", "crosswalk", "curb_ramp", "street_road", "road")
POLE_SURFACES = ("sidewalk", "grass")
#: Where a person stands to watch: walkable surfaces, but not in the middle of a crossing.
STANDING_SURFACES = tuple(c for c in WALKABLE if c != "crosswalk")
AZIMUTH_BINS = 12
RIDE_AHEAD_M = {"wheelchair_eye": 0.3, "pedestrian_eye": 0.2}
DEFAULT_PITCH_DEG = {"dashcam": -3.0, "wheelchair_eye": -5.0, "pedestrian_eye": -5.0}
DEFAULT_DISTANCE_M = {"cctv": 18.0, "pedestrian_eye": 12.0, "wheelchair_eye": 12.0}
UAV_NADIR_OFFSET_M = 5.0
DASHCAM_START_STEP_M = 8.0
OPEN_SKY_M = 200.0
HEADROOM_M = 0.5
CLIP_M = {"cctv": (0.1, 2000.0), "dashcam": (0.05, 2000.0), "uav_nadir": (1.0, 3000.0), "uav_oblique": (1.0, 3000.0),
          "pedestrian_eye": (0.05, 2000.0), "wheelchair_eye": (0.05, 2000.0)}


@dataclass(frozen=True, eq=False)
class Placement:
    """One way to place a rig's camera: a fixed ``pose`` or a ``track`` {time code: pose} (a moving rig),
    a focal length (mm) and a sentence saying where it is."""

    focal_length_mm: float
    where: str
    pose: np.ndarray | None = field(default=None, repr=False)
    track: dict | None = field(default=None, repr=False)
    rides_with: str | None = None

    def camera_to_world(self, time_code: float) -> np.ndarray:
        return self.pose if self.track is None else self.track[time_code]

    def camera(self, spec: RigSpec, path: str, time_code: float) -> PinholeCamera:
        h_ap, v_ap = spec.apertures_mm
        near, far = CLIP_M[spec.type]
        return PinholeCamera(path=path, focal_length_mm=self.focal_length_mm, horizontal_aperture_mm=h_ap,
                             vertical_aperture_mm=v_ap, clip_near_m=near, clip_far_m=far,
                             camera_to_world=self.camera_to_world(time_code), distortion=spec.distortion)


class Terrain:
    """The static twin for placement: its triangles with class names (Embree through trimesh for rays) and,
    built on first use, a 1 m grid of the surfaces rigs stand on and the road network."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, face_class: np.ndarray, source: str) -> None:
        import trimesh
        if len(faces) == 0:
            raise InputError(f"{source}: has no static geometry to place cameras in")
        self.vertices, self.faces, self.face_class, self.source = vertices, faces, np.asarray(face_class, object), source
        self.mesh = trimesh.Trimesh(vertices, faces, process=False, validate=False)
        self._grid: WalkableGrid | None = None
        self._roads: roads.RoadNetwork | None = None

    @property
    def grid(self) -> WalkableGrid:
        if self._grid is None:
            self._grid = build_grid(self.vertices, self.faces, self.face_class, MOUNT_CELL_M, MOUNT_CLASSES)
        return self._grid

    @property
    def roads(self) -> roads.RoadNetwork:
        if self._roads is None:
            self._roads = roads.road_network(self.vertices, self.faces, self.face_class, source=self.source)
        return self._roads

    def open_above(self, points: np.ndarray, clearance_m: float) -> np.ndarray:
        """(n,) bool: nothing within ``clearance_m`` above each (n, 3) point (outdoors, not under a roof)."""
        if len(points) == 0:
            return np.zeros(0, bool)
        dirs = np.tile([0.0, 0.0, 1.0], (len(points), 1))
        locations, ray_idx, _ = self.mesh.ray.intersects_location(points, dirs, multiple_hits=False)
        blocked = np.zeros(len(points), bool)
        blocked[ray_idx[locations[:, 2] - points[ray_idx, 2] < clearance_m]] = True
        return ~blocked

    def ground_z(self, xy: np.ndarray) -> float:
        """Height of the highest surface below (x, y) (from 1 km up), metres; NaN where there is none."""
        origin = np.array([[xy[0], xy[1], self.vertices[:, 2].max() + 1000.0]])
        locations, _, _ = self.mesh.ray.intersects_location(origin, np.array([[0.0, 0.0, -1.0]]), multiple_hits=False)
        return float(locations[0, 2]) if len(locations) else math.nan

    def cells(self, surfaces: tuple[str, ...], facade: bool = False) -> np.ndarray:
        """(n, 3) centres of grid cells on ``surfaces``; with ``facade``, only those next to (8-neighbours
        of) a cell whose first surface seen from above is a building's."""
        g = self.grid
        mask = np.isin(g.surface, surfaces) & g.walkable
        if facade:
            mask &= ndimage.binary_dilation(self._covered_by("building"), np.ones((3, 3), bool))
        return np.array([g.centre(i, j) for i, j in zip(*np.nonzero(mask))], np.float64).reshape(-1, 3)

    def _covered_by(self, class_name: str) -> np.ndarray:
        """(ny, nx) bool: the first surface a ray straight down through the cell's centre meets is ``class_name``."""
        g = self.grid
        ny, nx_ = g.z.shape
        gx, gy = np.meshgrid(g.x0 + (np.arange(nx_) + 0.5) * g.cell_m, g.y0 + (np.arange(ny) + 0.5) * g.cell_m)
        top = self.vertices[:, 2].max() + 10.0
        origins = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, top)])
        tri = self.mesh.ray.intersects_first(origins, np.tile([0.0, 0.0, -1.0], (len(origins), 1)))
        covered = (tri >= 0) & (self.face_class[np.maximum(tri, 0)] == class_name)
        return covered.reshape(ny, nx_)


def fit_focal(pose: np.ndarray, corners: np.ndarray, spec: RigSpec, width: int, height: int) -> float:
    """The longest focal length (mm) in the rig's lens range that keeps every corner (n, 3) within
    FRAME_MARGIN of a W×H frame (the shortest when a corner is behind the camera)."""
    lo, hi = spec.kind.lens.focal_range_mm
    if spec.focal_length_mm is not None:
        return spec.focal_length_mm
    h_ap, v_ap = spec.apertures_mm
    probe = PinholeCamera("/probe", lo, h_ap, v_ap, 0.01, 10.0, pose)
    ext = probe.world_to_camera_opencv()
    pc = corners @ ext[:3, :3].T + ext[:3, 3]
    if np.any(pc[:, 2] <= 1e-6):
        return lo
    ch, cv = probe.conformed_aperture_mm(width, height)
    x, y = np.abs(pc[:, 0] / pc[:, 2]).max(), np.abs(pc[:, 1] / pc[:, 2]).max()
    limit = min(FRAME_MARGIN * ch / 2 / max(x, 1e-9), FRAME_MARGIN * cv / 2 / max(y, 1e-9))
    return float(np.clip(limit, lo, hi))


def _look(eye, target) -> np.ndarray:
    return geo.look_at(eye, target) if np.linalg.norm(np.subtract(target, eye)[:2]) > 1e-6 else _nadir(eye)


def _nadir(eye) -> np.ndarray:
    """Straight down, image top towards +Y."""
    eye = np.asarray(eye, float)
    return geo.look_at(eye, eye - [0.0, 0.0, 1.0], up=(0.0, 1.0, 0.0))


def _ring(points: np.ndarray, centre: np.ndarray, d_lo: float, d_hi: float) -> list[np.ndarray]:
    """Up to two points per azimuth bin around ``centre`` with horizontal distance in [d_lo, d_hi], nearest
    to 35 % and 75 % of the way out."""
    if len(points) == 0:
        return []
    off = points[:, :2] - centre[:2]
    dist = np.linalg.norm(off, axis=1)
    inside = (dist >= d_lo) & (dist <= d_hi)
    azimuth = np.floor((np.arctan2(off[:, 1], off[:, 0]) + math.pi) / (2 * math.pi) * AZIMUTH_BINS).astype(int)
    out = []
    for b in range(AZIMUTH_BINS):
        idx = np.flatnonzero(inside & (azimuth == b))
        for frac in (0.35, 0.75):
            if len(idx):
                want = d_lo + frac * (d_hi - d_lo)
                k = idx[np.argmin(np.abs(dist[idx] - want))]
                if not any(np.array_equal(points[k], p) for p in out):
                    out.append(points[k])
    return out


def fixed_candidates(spec: RigSpec, terrain: Terrain, anchor: np.ndarray, corners: np.ndarray | None,
                     width: int, height: int) -> list[Placement]:
    """Placements of a fixed rig (CCTV, standing eye level, UAV) aimed at ``anchor`` (3,); ``corners`` (n, 3)
    of the target's boxes fit the focal length (None: the lens's default)."""
    h = spec.height_m

    def placement(eye, look_at_point, where):
        pose = _nadir(eye) if look_at_point is None else _look(eye, look_at_point)
        focal = fit_focal(pose, corners, spec, width, height) if corners is not None else (
            spec.focal_length_mm or spec.kind.lens.default_focal_mm)
        return Placement(focal, where, pose=pose)

    if spec.type in ("uav_nadir", "uav_oblique"):
        ground = float(corners[:, 2].min()) if corners is not None else anchor[2]
        if spec.type == "uav_nadir":
            offsets = [(0.0, 0.0)] + [(dx * UAV_NADIR_OFFSET_M, dy * UAV_NADIR_OFFSET_M)
                                      for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1))]
            return [placement((anchor[0] + dx, anchor[1] + dy, ground + h), None,
                              f"{h:g} m above ({anchor[0] + dx:.1f}, {anchor[1] + dy:.1f}), looking straight down")
                    for dx, dy in offsets]
        reach = h * math.tan(math.radians(spec.tilt_deg))
        out = []
        for k in range(AZIMUTH_BINS):
            a = 2 * math.pi * k / AZIMUTH_BINS
            eye = (anchor[0] + reach * math.cos(a), anchor[1] + reach * math.sin(a), ground + h)
            out.append(placement(eye, anchor, f"{h:g} m up, {reach:.1f} m from the target at "
                                              f"{math.degrees(a):.0f} degrees, {spec.tilt_deg:g} degrees off nadir"))
        return out
    if spec.type == "cctv":
        d_lo, d_hi = max(3.0, 0.6 * h), spec.distance_m or DEFAULT_DISTANCE_M["cctv"]
        mounts = []
        if spec.mount in ("any", "pole"):
            mounts += [("pole on " + terrain.grid.surface[terrain.grid.cell_of(*p[:2])], p)
                       for p in _ring(terrain.cells(POLE_SURFACES), anchor, d_lo, d_hi)]
        if spec.mount in ("any", "facade"):
            mounts += [("façade", p) for p in _ring(terrain.cells(MOUNT_CLASSES, facade=True), anchor, d_lo, d_hi)]
    else:  # standing at eye level
        d_lo, d_hi = 3.0, spec.distance_m or DEFAULT_DISTANCE_M[spec.type]
        mounts = [("standing on " + terrain.grid.surface[terrain.grid.cell_of(*p[:2])], p)
                  for p in _ring(terrain.cells(STANDING_SURFACES), anchor, d_lo, d_hi)]
    if not mounts:
        return []
    eyes = np.array([p + [0.0, 0.0, h] for _, p in mounts])
    # A façade camera hangs under the eaves; a pole stands under open sky (not in a building or a tree) and a
    # person needs headroom.
    open_air = terrain.open_above(eyes + [0.0, 0.0, 0.05], OPEN_SKY_M if spec.type == "cctv" else HEADROOM_M)
    out = []
    for (what, ground), eye, free in zip(mounts, eyes, open_air):
        if free or what == "façade":
            dist = float(np.linalg.norm(eye[:2] - anchor[:2]))
            out.append(placement(eye, anchor, f"{what} at ({ground[0]:.1f}, {ground[1]:.1f}), {h:g} m up, "
                                              f"{dist:.1f} m from the target"))
    return out


def riding_placement(spec: RigSpec, rider, time_codes: list[float]) -> Placement:
    """A camera at the rig's eye height RIDE_AHEAD_M ahead of ``rider``'s face (an
    :class:`synthua_usd.usd.targets.AgentTrack`), looking where the rider heads, pitched by pitch_deg."""
    pitch = math.radians(spec.pitch_deg if spec.pitch_deg is not None else DEFAULT_PITCH_DEG[spec.type])
    local = geo.look_at((RIDE_AHEAD_M[spec.type], 0.0, spec.height_m),
                        (RIDE_AHEAD_M[spec.type] + math.cos(pitch), 0.0, spec.height_m + math.sin(pitch)))
    track = {t: rider.transforms[t] @ local for t in time_codes}
    focal = spec.focal_length_mm or spec.kind.lens.default_focal_mm
    return Placement(focal, f"riding with {rider.prim_path} ({rider.profile}), {spec.height_m:g} m up",
                     track=track, rides_with=rider.prim_path)


def dashcam_candidates(spec: RigSpec, terrain: Terrain, time_codes: list[float], fps: float,
                       aimed: bool) -> list[Placement]:
    """Drives along the centre of the longest road route at speed_kmh from starts every
    DASHCAM_START_STEP_M in both directions (one start, the route's beginning, when not ``aimed``)."""
    route = roads.longest_route(terrain.roads)
    speed = spec.speed_kmh / 3.6
    t0 = min(time_codes)
    travelled = speed * (np.array(time_codes) - t0) / fps
    length = roads.route_length_m(route)
    span = float(travelled.max()) if len(travelled) else 0.0
    starts = np.arange(0.0, max(length - span, 0.0) + 1e-9, DASHCAM_START_STEP_M) if aimed else np.array([0.0])
    pitch = math.radians(spec.pitch_deg if spec.pitch_deg is not None else DEFAULT_PITCH_DEG["dashcam"])
    out = []
    for direction, path in (("forward", route), ("back", route[::-1])):
        for start in starts:
            pos, heading, grade = roads.drive(path, float(start), travelled)
            track = {}
            for t, p, hd, g in zip(time_codes, pos, heading, grade):
                eye = p + [0.0, 0.0, spec.height_m]
                ahead = np.array([math.cos(hd) * math.cos(g + pitch), math.sin(hd) * math.cos(g + pitch),
                                  math.sin(g + pitch)])
                track[t] = geo.look_at(eye, eye + ahead)
            out.append(Placement(spec.focal_length_mm or spec.kind.lens.default_focal_mm,
                                 f"driving {direction} along the road centreline from {start:.0f} m of "
                                 f"{length:.0f} m at {spec.speed_kmh:g} km/h, {spec.height_m:g} m up", track=track))
        if not aimed:
            break
    return out
