"""One randomised view as plain data: the camera moved within its rig's envelope, and the scene's crowd placed
anew on the walkable surfaces, some aid users where that camera sees them.

:class:`WalkArea` is what placement needs of a twin, built once per twin: the walkable grid and graph
(:mod:`synthua_usd.agents.walkable`), the seats, and Embree ray casters over the twin's triangles (what
occludes a view) and over its walkable faces (the ground height under a person). Frames: world metres, Z up.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from synthua_usd.agents.motion import MARGIN_M
from synthua_usd.agents.profiles import PROFILES, AgentProfile
from synthua_usd.agents.seats import SeatPlace, find_seat_places
from synthua_usd.agents.walkable import WALKABLE, WalkableGrid, build_grid, walkable_graph
from synthua_usd.assets.postures import PUSH_DISTANCE_M
from synthua_usd.composition.rigs import RIG_TYPES
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.randomisation.config import CameraRandomisation, CrowdRandomisation
from synthua_usd.randomisation.scene import CastMember

if TYPE_CHECKING:  # imported where used (with scipy.spatial, ~0.6 s that most processes never need)
    import trimesh

#: A person is "seen" when this point above its feet projects inside the image (a margin of 5 % of each side
#: left free) with nothing of the twin in front of it, and a person of PERSON_HEIGHT_M standing there would
#: span the share of the image's height the config asks.
SEEN_HEIGHT_M = 1.0
PERSON_HEIGHT_M = 1.7
IMAGE_MARGIN = 0.05
#: Tries to find a free place for one person before any walkable cell will do.
PLACE_TRIES = 60
#: Share of placed people standing still (waiting, talking); the rest are caught mid-stride.
STANDING_SHARE = 0.15
#: Side-by-side spacing of a group walking together, metres.
GROUP_SPACING_M = 0.9
#: The eight neighbours of a walkable cell (di, dj), sorted as the graph's node tuples sort, and the unit heading
#: (x, y) = (dj, di) / |(dj, di)| towards each.
NEIGHBOURS = tuple((di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1) if (di, dj) != (0, 0))
_HEADINGS = np.array([np.array([dj, di], float) / np.linalg.norm([dj, di]) for di, dj in NEIGHBOURS])


@dataclass(frozen=True, eq=False)
class WalkArea:
    """Where people can be placed in one twin. ``grid`` and its ``graph``; ``nodes`` (k, 2) int64 grid cells
    of the graph's nodes, sorted, and their ``centres`` (k, 3) world metres; ``seats`` its bench places;
    ``occluders`` and ``ground`` ray casters over all its triangles and over its walkable faces."""

    grid: WalkableGrid
    graph: object = field(repr=False)
    nodes: np.ndarray = field(repr=False)
    centres: np.ndarray = field(repr=False)
    seats: tuple[SeatPlace, ...]
    occluders: trimesh.Trimesh = field(repr=False)
    ground: trimesh.Trimesh = field(repr=False)
    _by_profile: dict = field(default_factory=dict, repr=False)
    _edges: dict = field(default_factory=dict, repr=False)

    @classmethod
    def build(cls, vertices: np.ndarray, faces: np.ndarray, face_class: np.ndarray,
              walkable: tuple[str, ...] = WALKABLE, cell_m: float = 0.5) -> "WalkArea":
        """From the twin's triangles: ``vertices`` (n, 3) float64 world metres Z up, ``faces`` (m, 3) int64,
        ``face_class`` (m,) object class names."""
        import trimesh
        grid = build_grid(vertices, faces, face_class, cell_m, walkable)
        graph = walkable_graph(grid)
        nodes = np.array(sorted(graph.nodes), np.int64).reshape(-1, 2)
        seats = tuple(find_seat_places(vertices, faces, face_class, grid))
        walk = np.isin(np.asarray(face_class, object), list(walkable) + ["road"])
        occluders = trimesh.Trimesh(vertices, faces, process=False, validate=False)
        ground = trimesh.Trimesh(vertices, faces[walk] if walk.any() else faces, process=False, validate=False)
        centres = np.array([grid.centre(i, j) for i, j in nodes]).reshape(-1, 3)
        return cls(grid, graph, nodes, centres, seats, occluders, ground)

    def area_m2(self) -> float:
        return self.grid.area_m2()

    def with_occluders(self, meshes) -> "WalkArea":
        """The same area whose occluders also hold ``meshes`` ((points (n, 3), triangles (m, 3)) world metres: a
        scene's distractors), which then hide people from a camera; the walkable grid is the twin's."""
        import trimesh

        meshes = list(meshes)
        if not meshes:
            return self
        vertices, faces = [self.occluders.vertices], [self.occluders.faces]
        offset = len(self.occluders.vertices)
        for points, triangles in meshes:
            vertices.append(np.asarray(points, float))
            faces.append(np.asarray(triangles, np.int64) + offset)
            offset += len(points)
        mesh = trimesh.Trimesh(np.concatenate(vertices), np.concatenate(faces), process=False, validate=False)
        return replace(self, occluders=mesh)

    def choices(self, profile: AgentProfile) -> tuple[np.ndarray, list[np.ndarray]]:
        """For ``profile``: indices into :attr:`nodes` of the cells it may stand on (at least one edge it can
        travel, and for a wide agent all eight neighbours walkable), and per such cell the unit directions
        (d, 2) of the edges it can travel (its possible headings), in the order of the neighbours' cells."""
        key = (profile.can_step_kerb, profile.max_slope, profile.radius_m > 0.5 * self.grid.cell_m)
        if key not in self._by_profile:
            ok = self.grid.walkable
            interior = ok.copy()
            if key[2]:
                padded = np.pad(ok, 1)
                for di in (-1, 0, 1):
                    for dj in (-1, 0, 1):
                        interior &= padded[1 + di:1 + di + ok.shape[0], 1 + dj:1 + dj + ok.shape[1]]
            has, kerb, slope = self._neighbour_edges()
            # What edge_cost(profile) lets pass: a kerb only for those who step kerbs, else a slope within reach.
            passable = has & np.where(kerb, profile.can_step_kerb, slope <= profile.max_slope)
            keep = np.flatnonzero(interior[self.nodes[:, 0], self.nodes[:, 1]] & passable.any(axis=1))
            self._by_profile[key] = (keep.astype(np.int64), [_HEADINGS[passable[k]] for k in keep])
        return self._by_profile[key]

    def _neighbour_edges(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(k, 8) arrays over :attr:`nodes` and :data:`NEIGHBOURS`: whether the graph has that edge, whether it
        is a kerb, and its slope (0 where there is no edge). Built once; every profile reads them."""
        if not self._edges:
            index = {(int(i), int(j)): k for k, (i, j) in enumerate(self.nodes)}
            offset = {o: n for n, o in enumerate(NEIGHBOURS)}
            has = np.zeros((len(self.nodes), len(NEIGHBOURS)), bool)
            kerb, slope = has.copy(), np.zeros(has.shape)
            for u, v, data in self.graph.edges(data=True):
                for a, b in ((u, v), (v, u)):
                    k, n = index[a], offset[(b[0] - a[0], b[1] - a[1])]
                    has[k, n], kerb[k, n], slope[k, n] = True, bool(data["kerb"]), data["slope"]
            self._edges.update(has=has, kerb=kerb, slope=slope)
        return self._edges["has"], self._edges["kerb"], self._edges["slope"]

    def ground_z(self, xy: np.ndarray, near_z: np.ndarray) -> np.ndarray:
        """(n,) heights of the walkable surface under points ``xy`` (n, 2), each the hit nearest below
        ``near_z`` + 0.5 m (the cell's height when a ray finds none within 0.3 m of it)."""
        origins = np.column_stack([xy, near_z + 0.5])
        dirs = np.tile([0.0, 0.0, -1.0], (len(xy), 1))
        out = np.asarray(near_z, float).copy()
        if len(xy):
            locations, ray, _ = self.ground.ray.intersects_location(origins, dirs, multiple_hits=False)
            close = np.abs(locations[:, 2] - out[ray]) < 0.3
            out[ray[close]] = locations[close, 2]
        return out

    def height_below(self, point: np.ndarray) -> float | None:
        """The height of the walkable surface (else of any surface) straight below ``point`` (3,), or None."""
        for mesh in (self.ground, self.occluders):
            locations, _, _ = mesh.ray.intersects_location(np.asarray(point, float)[None], np.array([[0.0, 0.0, -1.0]]),
                                                           multiple_hits=False)
            if len(locations):
                return float(locations[0, 2])
        return None

    def seen(self, points: np.ndarray, camera: PinholeCamera, width: int, height: int,
             height_share: tuple[float, float]) -> np.ndarray:
        """(n,) bool: which ``points`` (n, 3) ``camera`` sees inside its image (less the margin), where a person
        of :data:`PERSON_HEIGHT_M` would span a share of the image's height within ``height_share``, with no
        twin triangle nearer along the ray (0.3 m of slack)."""
        if not len(points):
            return np.zeros(0, bool)
        px, z = camera.project(points, width, height)
        mx, my = IMAGE_MARGIN * width, IMAGE_MARGIN * height
        inside = ((z > 0) & (px[:, 0] >= mx) & (px[:, 0] <= width - mx) & (px[:, 1] >= my)
                  & (px[:, 1] <= height - my))
        fy = camera.intrinsics(width, height)[1, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            share = np.where(z > 0, fy * PERSON_HEIGHT_M / z / height, 0.0)
        inside &= (share >= height_share[0]) & (share <= height_share[1])
        dist = np.linalg.norm(points - camera.origin, axis=1)
        index = np.flatnonzero(inside)
        if len(index):
            dirs = (points[index] - camera.origin) / dist[index, None]
            origins = np.broadcast_to(camera.origin, dirs.shape)
            locations, ray, _ = self.occluders.ray.intersects_location(origins, dirs, multiple_hits=False)
            hit = np.full(len(index), np.inf)
            hit[ray] = np.linalg.norm(locations - camera.origin, axis=1)
            inside[index[hit < dist[index] - 0.3]] = False
        return inside


@dataclass(frozen=True)
class Placement:
    """Where one person stands in a view: ``position`` (3,) world metres (feet on the ground), ``heading_deg``
    about Z (0 = +X), the gait or push cycle's ``phase`` (radians), its ``amplitude`` (0 still .. 1 full
    stride), ``speed_mps`` (sets the stride), and whether it was placed for the camera to see (``in_view``)."""

    position: tuple[float, float, float]
    heading_deg: float
    phase: float
    amplitude: float
    speed_mps: float
    in_view: bool = False


@dataclass(frozen=True)
class CameraJitter:
    """The camera of one view: its moved pose (``camera_to_world`` 4x4 column-vector, world metres) and focal
    length (mm), and the draws that made them."""

    camera_to_world: tuple
    focal_length_mm: float
    height_change_m: float
    yaw_deg: float
    pitch_deg: float
    focal_factor: float
    #: Above the surface under the camera after the move (None when nothing is below it).
    height_m: float | None = None

    def camera(self, base: PinholeCamera) -> PinholeCamera:
        """``base`` moved to this pose and focal length."""
        return replace(base, camera_to_world=np.array(self.camera_to_world, float),
                       focal_length_mm=self.focal_length_mm)


@dataclass(frozen=True)
class ViewDraw:
    """Everything one view drew: the camera (None when not randomised), one placement per cast member, and the
    framing that moved the camera to an aid user (None: the rig's view; :mod:`synthua_usd.randomisation.framing`)."""

    camera: CameraJitter | None
    placements: tuple[Placement, ...]
    framing: object = None

    def to_dict(self) -> dict:
        out = {"camera": None if self.camera is None else asdict(self.camera),
               "placements": [asdict(p) for p in self.placements]}
        if self.framing is not None:  # absent, not null, where the part is off: records as before it existed
            out["framing"] = self.framing.to_dict()
        return out


def _rotation(axis: np.ndarray, degrees: float) -> np.ndarray:
    """(3, 3) rotation by ``degrees`` about the unit ``axis`` (Rodrigues)."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    t = math.radians(degrees)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * k @ k


def draw_camera(rng: np.random.Generator, camera: PinholeCamera, rig_type: str | None, ground_z: float | None,
                config: CameraRandomisation) -> CameraJitter:
    """Move ``camera``: up or down by U(±height_m), kept within its rig type's heights above ``ground_z`` (the
    ground under it; the range widened to include where it stands now); turned by U(±yaw_deg) about the world's
    up axis and U(±pitch_deg) about its own right axis; focal length scaled by U(focal_length_factor), kept
    within its rig type's lens (widened likewise). Z up."""
    rig = RIG_TYPES.get(rig_type or "")
    origin = camera.origin
    dh = float(rng.uniform(-config.height_m, config.height_m))
    if rig is not None and ground_z is not None:
        now = origin[2] - ground_z
        lo, hi = min(rig.height_range_m[0], now), max(rig.height_range_m[1], now)
        dh = float(np.clip(now + dh, lo, hi) - now)
    yaw = float(rng.uniform(-config.yaw_deg, config.yaw_deg))
    pitch = float(rng.uniform(-config.pitch_deg, config.pitch_deg))
    factor = float(rng.uniform(*config.focal_length_factor))
    focal = camera.focal_length_mm * factor
    if rig is not None:
        f_lo, f_hi = rig.lens.focal_range_mm
        focal = float(np.clip(focal, min(f_lo, camera.focal_length_mm), max(f_hi, camera.focal_length_mm)))
    right, _, _ = camera.axes()
    rot = _rotation([0.0, 0.0, 1.0], yaw) @ _rotation(right, pitch) @ camera.camera_to_world[:3, :3]
    m = np.eye(4)
    m[:3, :3] = rot
    m[:3, 3] = origin + np.array([0.0, 0.0, dh])
    height = None if ground_z is None else float(origin[2] + dh - ground_z)
    return CameraJitter(tuple(map(tuple, m.tolist())), float(focal), dh, yaw, pitch, factor, height)


def _free(xy: np.ndarray, radius: float, taken: list[tuple[float, float, float]]) -> bool:
    return all((xy[0] - x) ** 2 + (xy[1] - y) ** 2 >= (radius + r + MARGIN_M) ** 2 for x, y, r in taken)


def companion_offsets(cast: tuple[CastMember, ...], k: int) -> list[tuple[int, float, float]]:
    """The members placed with aid user ``k`` as (cast index, metres ahead, metres to the left) in its frame:
    itself at the origin, its pusher :data:`PUSH_DISTANCE_M` behind, its companions beside it (left, then
    right, then in line behind), each far enough from it for their discs to keep :data:`MARGIN_M` apart."""
    user = PROFILES[cast[k].profile].radius_m
    out = [(k, 0.0, 0.0)]
    side = 0
    for j, member in enumerate(cast):
        if member.pushes == k:
            out.append((j, -PUSH_DISTANCE_M, 0.0))
        elif member.accompanies == k:
            gap = max(GROUP_SPACING_M, user + PROFILES[member.profile].radius_m + MARGIN_M)
            out.append((j, 0.0, gap) if side == 0 else (j, 0.0, -gap) if side == 1 else (j, -gap * (side - 1), 0.0))
            side += 1
    return out


def place_cast(rng: np.random.Generator, cast: tuple[CastMember, ...], area: WalkArea, camera: PinholeCamera,
               size: tuple[int, int], config: CrowdRandomisation,
               blocked: tuple[tuple[float, float, float], ...] = ()) -> tuple[Placement, ...]:
    """A placement for every member of ``cast``, no two discs (profile radii) within 0.1 m.

    First U{aid_users_in_view} of the aid users (a random choice of them) go where ``camera`` (at render
    ``size``) sees them at a projected height within ``view_height_share``; then everyone else anywhere on the cells their profile may
    stand on, groups side by side, bench sitters on their seats. Each takes a heading along an edge it can
    travel, a random phase, and stands still with probability :data:`STANDING_SHARE`. A person for whom no
    free place turns up in :data:`PLACE_TRIES` tries takes the freest of them; ``in_view`` says who was placed
    free in view. An aid user with companions is placed with them as one unit (:func:`companion_offsets`: its
    pusher behind it, the others beside it, all at its heading and pace, every one of them on a walkable
    cell), each companion with a phase of its own. ``blocked`` (x, y, radius) discs are kept clear as people's are
    (the scene's distractors on the ground)."""
    taken: list[tuple[float, float, float]] = list(blocked)
    placements: list[Placement | None] = [None] * len(cast)
    aid_users = [k for k, m in enumerate(cast) if m.aid is not None]
    lo, hi = config.aid_users_in_view
    wanted = min(len(aid_users), int(rng.integers(lo, hi + 1)))
    in_view = set(int(k) for k in rng.choice(aid_users, size=wanted, replace=False)) if wanted else set()
    group_lead: dict[int, Placement] = {}
    seen = None  # which nodes the camera sees, computed once when someone is to be seen
    order = sorted(range(len(cast)), key=lambda k: (k not in in_view, k))
    cell = area.grid.cell_m
    for k in order:
        member = cast[k]
        profile = PROFILES[member.profile]
        speed = float(np.clip(rng.normal(profile.speed_mps, profile.speed_sd_mps), 0.5 * profile.speed_mps,
                              1.5 * profile.speed_mps))
        phase = float(rng.uniform(0.0, 2 * np.pi))
        amplitude = 0.0 if rng.random() < STANDING_SHARE else 1.0
        if placements[k] is not None:  # a companion, placed with its aid user
            continue
        if member.seat is not None:
            seat = member.seat
            taken.append((seat.origin[0], seat.origin[1], profile.radius_m))
            placements[k] = Placement(tuple(seat.origin), seat.heading_deg, 0.0, 0.0, 0.0)
            continue
        if member.group is not None and member.group in group_lead:
            lead = group_lead[member.group]
            h = math.radians(lead.heading_deg)
            side = np.array([-math.sin(h), math.cos(h)]) * GROUP_SPACING_M * sum(
                1 for j in range(k) if cast[j].group == member.group)
            xy = np.array(lead.position[:2]) + side
            i, j = area.grid.cell_of(float(xy[0]), float(xy[1]))
            if (0 <= i < area.grid.z.shape[0] and 0 <= j < area.grid.z.shape[1] and area.grid.walkable[i, j]
                    and _free(xy, profile.radius_m, taken)):
                z = float(area.ground_z(xy[None], np.array([area.grid.z[i, j]]))[0])
                taken.append((float(xy[0]), float(xy[1]), profile.radius_m))
                placements[k] = Placement((float(xy[0]), float(xy[1]), z), lead.heading_deg, phase, lead.amplitude,
                                          lead.speed_mps)
                continue
        cells, headings = area.choices(profile)
        if not len(cells):
            raise ValueError(f"no walkable cell holds a {profile.name} (radius {profile.radius_m:g} m)")
        pool, aimed = cells, False
        if k in in_view:
            if seen is None:
                seen = area.seen(area.centres + [0.0, 0.0, SEEN_HEIGHT_M], camera, *size, config.view_height_share)
            visible = cells[seen[cells]]
            pool, aimed = (visible, True) if len(visible) else (cells, False)
        unit = companion_offsets(cast, k) if member.aid is not None else [(k, 0.0, 0.0)]
        if len(unit) > 1:
            _place_unit(rng, cast, unit, area, cells, headings, pool, taken, placements, phase, amplitude, speed,
                        aimed)
            continue
        best, best_gap = None, -np.inf
        for _ in range(PLACE_TRIES):
            c = int(pool[int(rng.integers(len(pool)))])
            i, j = area.nodes[c]
            xy = area.grid.centre(i, j)[:2] + rng.uniform(-0.3 * cell, 0.3 * cell, 2)
            gap = min((math.hypot(xy[0] - x, xy[1] - y) - r - profile.radius_m for x, y, r in taken), default=np.inf)
            if gap > best_gap:
                best, best_gap = (c, xy), gap
            if gap >= MARGIN_M:
                break
        c, xy = best
        i, j = area.nodes[c]
        position = np.searchsorted(cells, c)
        dirs = headings[int(position)]
        d = dirs[int(rng.integers(len(dirs)))]
        heading = float(np.degrees(np.arctan2(d[1], d[0])))
        z = float(area.ground_z(np.asarray(xy)[None], np.array([area.grid.z[i, j]]))[0])
        taken.append((float(xy[0]), float(xy[1]), profile.radius_m))
        placements[k] = Placement((float(xy[0]), float(xy[1]), z), heading, phase, amplitude, speed,
                                  in_view=bool(aimed and best_gap >= MARGIN_M))
        if member.group is not None:
            group_lead[member.group] = placements[k]
    return tuple(placements)


def _place_unit(rng: np.random.Generator, cast: tuple[CastMember, ...], unit: list[tuple[int, float, float]],
                area: WalkArea, cells: np.ndarray, headings: list[np.ndarray], pool: np.ndarray, taken: list,
                placements: list, phase: float, amplitude: float, speed: float, aimed: bool) -> None:
    """Place an aid user and its companions (``unit``, :func:`companion_offsets`) as :func:`place_cast` places one
    person, trying a cell, a jitter and a heading together: the freest of :data:`PLACE_TRIES` arrangements
    whose every member stands on a walkable cell (any arrangement when none is)."""
    cell = area.grid.cell_m
    radii = np.array([PROFILES[cast[j].profile].radius_m for j, _, _ in unit])
    offsets = np.array([(ahead, left) for _, ahead, left in unit])
    best, best_key = None, (-1, -np.inf)
    for _ in range(PLACE_TRIES):
        c = int(pool[int(rng.integers(len(pool)))])
        i, j = area.nodes[c]
        xy = area.grid.centre(i, j)[:2] + rng.uniform(-0.3 * cell, 0.3 * cell, 2)
        dirs = headings[int(np.searchsorted(cells, c))]
        d = dirs[int(rng.integers(len(dirs)))]
        spots = xy + offsets[:, :1] * d + offsets[:, 1:] * np.array([-d[1], d[0]])
        index = [area.grid.cell_of(float(x), float(y)) for x, y in spots]
        rows, cols = area.grid.z.shape
        walkable = sum(0 <= a < rows and 0 <= b < cols and bool(area.grid.walkable[a, b]) for a, b in index)
        gap = min((math.hypot(p[0] - x, p[1] - y) - r - rr for p, rr in zip(spots, radii) for x, y, r in taken),
                  default=np.inf)
        key = (walkable, gap)
        if key > best_key:
            best, best_key = (spots, index, d), key
        if walkable == len(unit) and gap >= MARGIN_M:
            break
    spots, index, d = best
    heading = float(np.degrees(np.arctan2(d[1], d[0])))
    near = np.array([area.grid.z[min(max(a, 0), area.grid.z.shape[0] - 1), min(max(b, 0), area.grid.z.shape[1] - 1)]
                     for a, b in index])
    z = area.ground_z(spots, near)
    # the gaps are NumPy floats (the radii are an array): the comparison is a numpy.bool_, which a record refuses
    free = bool(best_key[0] == len(unit) and best_key[1] >= MARGIN_M)
    for n, ((member, _, _), spot, r) in enumerate(zip(unit, spots, radii)):
        taken.append((float(spot[0]), float(spot[1]), float(r)))
        own_phase = phase if n == 0 else float(rng.uniform(0.0, 2 * np.pi))
        placements[member] = Placement((float(spot[0]), float(spot[1]), float(z[n])), heading, own_phase, amplitude,
                                       speed, in_view=aimed and free and n == 0)
