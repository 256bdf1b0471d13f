"""Candidate camera places from geometry alone: where CCTVs and people stand, UAV poses, focal lengths
that keep the target in frame, and cameras riding with an agent."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from synthua_usd.composition.rigs import RigSpec
from synthua_usd.geometry.placement import (FRAME_MARGIN, RIDE_AHEAD_M, Terrain, fit_focal, fixed_candidates,
                                   riding_placement)
from synthua_usd.model import meshes as geo
from test_roads import soup

W, H = 640, 480
TARGET = np.array([0.0, 0.0, 0.9])
CORNERS = np.array([[x, y, z] for x in (-0.4, 0.4) for y in (-0.6, 0.6) for z in (0.15, 1.45)])


@pytest.fixture(scope="module")
def terrain():
    """A 40 m street: road, sidewalks, a building on the north sidewalk's far half, a tree over the south one."""
    v, f, c = soup(("road", geo.box((-20, -4, -0.3), (20, 4, 0.0))),
                   ("sidewalk", geo.box((-20, 4, -0.3), (20, 12, 0.15))),
                   ("sidewalk", geo.box((-20, -12, -0.3), (20, -4, 0.15))),
                   ("building", geo.box((-20, 8, 0.15), (20, 12, 10.0))),
                   ("vegetation", geo.ellipsoid((6, -7, 6.5), (2.5, 2.5, 1.5))))  # crown 5-8 m up
    return Terrain(v, f, c, "street")


def test_facade_cctvs_hang_beside_the_building_at_their_height(terrain):
    spec = RigSpec.parse("cctv:mount=facade,height_m=5")
    places = fixed_candidates(spec, terrain, TARGET, CORNERS, W, H)
    assert places and all("façade" in p.where for p in places)
    for p in places:
        eye = p.pose[:3, 3]
        assert 8.0 - 1.5 <= eye[1] < 8.0 and eye[2] == pytest.approx(0.15 + 5.0)  # within a cell of the wall


def test_pole_cctvs_stand_under_open_sky_within_their_ring(terrain):
    spec = RigSpec.parse("cctv:mount=pole,distance_m=15")
    places = fixed_candidates(spec, terrain, TARGET, CORNERS, W, H)
    eyes = np.array([p.pose[:3, 3] for p in places])
    assert len(eyes) >= 8 and np.all(eyes[:, 1] < 8.0)  # never inside the building
    assert not np.any(np.hypot(eyes[:, 0] - 6, eyes[:, 1] + 7) < 2.5)  # nor in the tree's crown
    dist = np.hypot(eyes[:, 0], eyes[:, 1])
    assert np.all((dist >= 3.6 - 0.8) & (dist <= 15 + 0.8))  # ring: 0.6 x height to distance_m (cells are 1 m)
    for p in places:  # each looks at the target
        forward = -p.pose[:3, 2]
        to = TARGET - p.pose[:3, 3]
        assert forward @ to / np.linalg.norm(to) == pytest.approx(1.0)


def test_focal_length_keeps_every_corner_inside_the_margin(terrain):
    spec = RigSpec.parse("cctv")
    pose = geo.look_at((2.5, -2.5, 3.5), TARGET)
    focal = fit_focal(pose, CORNERS, spec, W, H)
    lo, hi = spec.kind.lens.focal_range_mm
    assert lo < focal < hi
    from synthua_usd.model.cameras import PinholeCamera

    uv, _ = PinholeCamera("/c", focal, 4.8, 3.6, 0.1, 100.0, pose).project(CORNERS, W, H)
    off = np.abs(uv - [W / 2, H / 2]) / [W / 2, H / 2]
    assert off.max() == pytest.approx(FRAME_MARGIN, abs=1e-6)  # the tightest corner sits on the margin
    assert fit_focal(geo.look_at((0.5, -2.0, 6.0), TARGET), CORNERS * 20, spec, W, H) == lo  # too big: widest


def test_uav_nadir_looks_straight_down_with_north_up(terrain):
    spec = RigSpec.parse("uav_nadir:height_m=50")
    (above, *beside) = fixed_candidates(spec, terrain, TARGET, CORNERS, W, H)
    m = above.pose
    assert np.allclose(m[:3, 3], [0.0, 0.0, 0.15 + 50.0]) and np.allclose(-m[:3, 2], [0, 0, -1])
    assert np.allclose(m[:3, 1], [0, 1, 0])  # image up is +Y
    assert len(beside) == 4


def test_a_riding_camera_follows_its_agent_ahead_of_the_face():
    headings = {1.0: 0.0, 2.0: 90.0}
    transforms = {}
    for t, h in headings.items():
        m = np.eye(4)
        c, s = math.cos(math.radians(h)), math.sin(math.radians(h))
        m[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
        m[:3, 3] = [t, 2.0, 0.15]
        transforms[t] = m
    rider = SimpleNamespace(prim_path="/World/Agents/Agent_0003", profile="manual_wheelchair", transforms=transforms)
    place = riding_placement(RigSpec.parse("wheelchair_eye:ride=auto"), rider, [1.0, 2.0])
    assert place.rides_with == "/World/Agents/Agent_0003"
    ahead = RIDE_AHEAD_M["wheelchair_eye"]
    assert np.allclose(place.track[1.0][:3, 3], [1.0 + ahead, 2.0, 0.15 + 1.2])
    assert np.allclose(place.track[2.0][:3, 3], [2.0, 2.0 + ahead, 0.15 + 1.2])
    forward = -place.track[2.0][:3, 2]
    assert forward[1] > 0.99 and forward[2] == pytest.approx(-math.sin(math.radians(5.0)))  # pitched 5 degrees down
