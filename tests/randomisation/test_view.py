"""A randomised view: the crowd placed anew on the walkable surfaces of the demo street (apart, on cells its
profiles may stand on, aid users where the camera sees them) and the camera moved within its rig's envelope."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import SCENARIO
from synthua_usd.agents.motion import MARGIN_M
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.agents.walkable import edge_cost
from synthua_usd.composition.rigs import RIG_TYPES
from synthua_usd.randomisation.config import CameraRandomisation, RandomisationConfig
from synthua_usd.randomisation.scene import draw_cast
from synthua_usd.randomisation.view import PERSON_HEIGHT_M, WalkArea, draw_camera, place_cast
from synthua_usd.usd.agents_writer import AGENTS_ROOT
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.stage_io import open_stage


@pytest.fixture(scope="module")
def street(class_map):
    stage = open_stage(SCENARIO)
    snapshot = read_snapshot(stage, 24.0, class_map)
    twin = [m for m in snapshot.meshes if not m.prim_path.startswith(AGENTS_ROOT)]
    vertices, faces, owner = snapshot.world_triangles(twin)
    names = np.array([class_map.by_id(m.class_id).name for m in twin], object)
    return stage, WalkArea.build(vertices, faces, names[owner])


def test_choices_are_the_cells_and_headings_the_graph_lets_each_profile_travel(street):
    # Independently: every node's neighbours in the graph's sorted order, each edge asked of edge_cost as A* asks.
    _, area = street
    ok = area.grid.walkable
    for profile in PROFILES.values():
        wide = profile.radius_m > 0.5 * area.grid.cell_m
        cost = edge_cost(profile)
        keep, headings = [], []
        for k, (i, j) in enumerate(area.nodes):
            if wide and not all(0 <= i + di < ok.shape[0] and 0 <= j + dj < ok.shape[1] and ok[i + di, j + dj]
                                for di in (-1, 0, 1) for dj in (-1, 0, 1)):
                continue
            dirs = [np.array([b - j, a - i], float) for a, b in sorted(area.graph.neighbors((int(i), int(j))))
                    if cost(None, None, area.graph.edges[(int(i), int(j)), (a, b)]) is not None]
            if dirs:
                keep.append(k)
                headings.append(np.array([d / math.hypot(*d) for d in dirs]))
        cells, got = area.choices(profile)
        assert cells.dtype == np.int64 and cells.tolist() == keep, profile.name
        assert len(got) == len(headings) and all(np.array_equal(g, h) for g, h in zip(got, headings)), profile.name
    assert len({len(area.choices(p)[0]) for p in PROFILES.values()}) > 1  # the profiles do differ here


def test_people_stand_apart_on_walkable_cells(street):
    stage, area = street
    config = RandomisationConfig()
    camera = read_camera(stage, "/World/Cameras/CCTV", 24.0)
    for seed in range(4):
        rng = np.random.default_rng(seed)
        _, _, cast, _ = draw_cast(rng, config, area.area_m2(), list(area.seats))
        placements = place_cast(rng, cast, area, camera, (320, 240), config.crowd)
        assert len(placements) == len(cast) > 0
        xy = np.array([p.position[:2] for p in placements])
        radii = np.array([PROFILES[m.profile].radius_m for m in cast])
        gap = np.linalg.norm(xy[:, None] - xy[None], axis=-1) - radii[:, None] - radii[None]
        np.fill_diagonal(gap, np.inf)
        for k, m in enumerate(cast):  # a pusher holds its chair's handles: their bodies, not discs, are kept apart
            if m.pushes is not None:  # (tests/assets/test_bodies.py)
                gap[k, m.pushes] = gap[m.pushes, k] = np.inf
        assert gap.min() >= MARGIN_M - 1e-9
        for p, m in zip(placements, cast):
            if m.seat is not None:
                assert p.position == tuple(m.seat.origin)
                continue
            i, j = area.grid.cell_of(p.position[0], p.position[1])
            assert area.grid.walkable[i, j], p
            assert abs(p.position[2] - area.grid.z[i, j]) < 0.2  # feet on the surface
            assert PROFILES[m.profile].device is None or area.grid.surface[i, j] != "", m.profile


def test_aid_users_are_placed_where_the_camera_sees_them(street):
    """The aid users placed for the camera project inside its image (the camera's own projection), nothing of the
    twin between (a ray from the camera to their chest), spanning the asked share of the image height. That
    the renderer's label pass then sees them is checked on rendered images (tests/pipeline/test_randomiser.py)."""
    import trimesh

    stage, area = street
    config = RandomisationConfig()
    camera = read_camera(stage, "/World/Cameras/CCTV", 24.0)
    width, height = 320, 240
    seen = 0
    for seed in range(6):
        rng = np.random.default_rng(100 + seed)
        _, _, cast, _ = draw_cast(rng, config, area.area_m2(), list(area.seats))
        for p in place_cast(rng, cast, area, camera, (width, height), config.crowd):
            if not p.in_view:
                continue
            seen += 1
            point = np.array(p.position) + [0.0, 0.0, 1.0]
            px, z = camera.project(point[None], width, height)
            assert 0 <= px[0, 0] < width and 0 <= px[0, 1] < height
            share = camera.intrinsics(width, height)[1, 1] * PERSON_HEIGHT_M / z[0] / height
            lo, hi = config.crowd.view_height_share
            assert lo - 0.02 <= share <= hi + 0.02  # the cell's centre was checked; the person stands within it
            direction = (point - camera.origin) / np.linalg.norm(point - camera.origin)
            hits, _, _ = trimesh.ray.ray_pyembree.RayMeshIntersector(area.occluders).intersects_location(
                camera.origin[None], direction[None], multiple_hits=False)
            assert not len(hits) or np.linalg.norm(hits[0] - camera.origin) >= np.linalg.norm(point - camera.origin) - 0.6
    assert seen >= 3  # some of the asked-for aid users found a free place in view


def test_placement_is_a_function_of_its_stream(street):
    stage, area = street
    config = RandomisationConfig()
    camera = read_camera(stage, "/World/Cameras/CCTV", 24.0)
    rng = np.random.default_rng(7)
    _, _, cast, _ = draw_cast(rng, config, area.area_m2(), list(area.seats))
    a = place_cast(np.random.default_rng(1), cast, area, camera, (320, 240), config.crowd)
    b = place_cast(np.random.default_rng(1), cast, area, camera, (320, 240), config.crowd)
    c = place_cast(np.random.default_rng(2), cast, area, camera, (320, 240), config.crowd)
    assert a == b and a != c


@pytest.mark.parametrize("path", ["/World/Cameras/CCTV", "/World/Cameras/PedestrianEye"])
def test_camera_moves_within_its_envelope(street, path):
    stage, area = street
    camera = read_camera(stage, path, 24.0)
    from synthua_usd.usd.cameras import camera_rig_type

    rig = RIG_TYPES.get(camera_rig_type(stage, path) or "")
    ground = area.height_below(camera.origin)
    config = CameraRandomisation()
    for seed in range(40):
        jitter = draw_camera(np.random.default_rng(seed), camera, camera_rig_type(stage, path), ground, config)
        moved = jitter.camera(camera)
        assert abs(jitter.height_change_m) <= config.height_m + 1e-12
        assert np.allclose(moved.origin[:2], camera.origin[:2])
        if rig is not None:
            height = moved.origin[2] - ground
            now = camera.origin[2] - ground
            assert min(rig.height_range_m[0], now) - 1e-9 <= height <= max(rig.height_range_m[1], now) + 1e-9
        _, _, f0 = camera.axes()
        _, up1, f1 = moved.axes()
        angle = math.degrees(math.acos(np.clip(f0 @ f1, -1, 1)))
        assert angle <= math.hypot(config.yaw_deg, config.pitch_deg) + 1e-6
        assert np.allclose(np.linalg.det(moved.camera_to_world[:3, :3]), np.linalg.det(camera.camera_to_world[:3, :3]))
        assert config.focal_length_factor[0] * camera.focal_length_mm - 1e-9 <= moved.focal_length_mm
        assert moved.focal_length_mm <= config.focal_length_factor[1] * camera.focal_length_mm + 1e-9


def test_companions_walk_behind_or_beside_their_aid_user(street):
    """A pusher stands PUSH_DISTANCE_M behind its chair's origin along the chair's heading; an accompanying
    companion beside its aid user (left or right, or in line behind where the side is not walkable), its disc
    clear of the user's; both at the user's heading, pace and stride (moving or standing with it)."""
    from synthua_usd.assets.postures import PUSH_DISTANCE_M
    from synthua_usd.randomisation.config import CrowdRandomisation

    stage, area = street
    config = RandomisationConfig(crowd=CrowdRandomisation(
        density_per_m2=(0.1, 0.1), aid_share=(0.6, 0.6), pushed_share=(0.8, 0.8), accompanied_share=(0.8, 0.8),
        aids=("manual_wheelchair", "walker", "crutch")))
    camera = read_camera(stage, "/World/Cameras/CCTV", 24.0)
    pushed = accompanied = 0
    for seed in range(4):
        rng = np.random.default_rng(seed)
        _, _, cast, _ = draw_cast(rng, config, area.area_m2(), list(area.seats))
        placements = place_cast(rng, cast, area, camera, (320, 240), config.crowd)
        for k, (m, p) in enumerate(zip(cast, placements)):
            user = m.pushes if m.pushes is not None else m.accompanies
            if user is None:
                continue
            lead = placements[user]
            assert cast[user].aid is not None and cast[user].group == m.group is not None
            assert (p.heading_deg, p.speed_mps, p.amplitude) == (lead.heading_deg, lead.speed_mps, lead.amplitude)
            h = math.radians(lead.heading_deg)
            ahead, left = np.array([math.cos(h), math.sin(h)]), np.array([-math.sin(h), math.cos(h)])
            d = np.array(p.position[:2]) - np.array(lead.position[:2])
            if m.pushes is not None:
                pushed += 1
                assert cast[user].aid == "manual_wheelchair" and cast[user].pushed_by == k
                assert np.allclose([d @ ahead, d @ left], [-PUSH_DISTANCE_M, 0.0], atol=1e-9)
            else:
                accompanied += 1
                clear = PROFILES[m.profile].radius_m + PROFILES[cast[user].profile].radius_m + MARGIN_M
                assert abs(d @ ahead) < 1e-9 or abs(d @ left) < 1e-9  # beside, or in line behind
                assert np.linalg.norm(d) >= clear - 1e-9
    assert pushed >= 3 and accompanied >= 3


def test_a_unit_aimed_into_view_without_a_free_place_is_not_in_view_as_a_python_bool(street):
    """Issue 39: an aid user aimed into view with its companions, all on walkable cells but crowded by others, got
    ``in_view`` as a ``numpy.bool_`` (its gaps are NumPy floats), which a record's JSON refused halfway through a
    dataset. Here every place is taken: the unit is placed, not free, and ``in_view`` is a plain False."""
    from synthua_usd.randomisation.config import CrowdRandomisation
    from synthua_usd.randomisation.view import _place_unit, companion_offsets

    stage, area = street
    config = RandomisationConfig(crowd=CrowdRandomisation(
        density_per_m2=(0.1, 0.1), aid_share=(0.8, 0.8), pushed_share=(1.0, 1.0), aids=("manual_wheelchair",)))
    rng = np.random.default_rng(0)
    _, _, cast, _ = draw_cast(rng, config, area.area_m2(), list(area.seats))
    k = next(k for k, m in enumerate(cast) if m.aid is not None and m.pushed_by is not None)
    unit = companion_offsets(cast, k)
    cells, headings = area.choices(PROFILES[cast[k].profile])
    # a person on every walkable cell centre: no arrangement of the unit is free
    taken = [(float(x), float(y), 0.3) for x, y in (area.grid.centre(i, j)[:2] for i, j in area.nodes)]
    placements = [None] * len(cast)
    _place_unit(rng, cast, unit, area, cells, headings, cells, taken, placements, 0.0, 1.0, 1.0, aimed=True)
    placed = [placements[member] for member, _, _ in unit]
    assert all(p is not None for p in placed)
    assert [type(p.in_view) for p in placed] == [bool] * len(unit) and not any(p.in_view for p in placed)

