"""The road graph a dashcam drives on: the centreline of the road surfaces, room for a car, and drives."""

import math

import numpy as np
import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.geometry.roads import VEHICLE_HALF_WIDTH_M, drive, longest_route, road_network, route_length_m
from synthua_usd.model import meshes as geo


def soup(*parts):
    """(vertices, faces, face classes) of (class, mesh) parts."""
    verts, faces, classes, offset = [], [], [], 0
    for cls, (p, t) in parts:
        verts.append(p)
        faces.append(t + offset)
        classes += [cls] * len(t)
        offset += len(p)
    return np.concatenate(verts), np.concatenate(faces), np.array(classes, object)


def street(road_half_width=4.0, parked_car=True):
    parts = [("road", geo.box((-20, -road_half_width, -0.3), (20, road_half_width, 0.0))),
             ("sidewalk", geo.box((-20, road_half_width, -0.3), (20, road_half_width + 3, 0.15))),
             ("sidewalk", geo.box((-20, -road_half_width - 3, -0.3), (20, -road_half_width, 0.15)))]
    if parked_car:  # blocks its cells: the route goes round it
        parts.append(("car", geo.box((-2, road_half_width - 2.0, 0.0), (2, road_half_width, 1.5))))
    return soup(*parts)


def test_the_longest_route_runs_along_the_centre_with_room_for_a_car():
    net = road_network(*street())
    route = longest_route(net)
    assert route_length_m(route) > 35.0
    assert net.on_road(route[:, :2], VEHICLE_HALF_WIDTH_M).all()
    assert np.abs(route[:, 2]).max() < 1e-6  # on the asphalt, not the sidewalks
    ends = route[[0, -1]]
    assert np.abs(ends[:, 1]).max() < 0.8  # it starts and ends on the centreline
    # the parked car takes the north 2 m between x = -2 and 2: the route keeps clear of it
    beside = np.abs(route[:, 0]) < 2.5
    assert np.all(route[beside, 1] < 2.0 - VEHICLE_HALF_WIDTH_M + 0.5)


def test_a_drive_moves_at_its_speed_and_stops_at_the_end():
    route = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 1.0], [10.0, 10.0, 1.0]])
    pos, heading, grade = drive(route, 2.0, np.array([0.0, 3.0, 100.0]))
    assert pos[0] == pytest.approx([2.0, 0.0, 0.2]) and pos[1] == pytest.approx([5.0, 0.0, 0.5])
    assert pos[2] == pytest.approx([10.0, 10.0, 1.0])  # 102 m asked, 20 m of route: stopped at its end
    assert heading[0] == pytest.approx(0.0) and heading[2] == pytest.approx(math.pi / 2)
    assert grade[0] == pytest.approx(math.atan2(0.4, 4.0))


def test_a_twin_without_roads_is_refused():
    v, f, c = street()
    with pytest.raises(InputError, match="twin.usdc: has no road surfaces .* expected a twin with roads"):
        road_network(v, f, np.where(c == "road", "sidewalk", c), source="twin.usdc")


def test_a_road_too_narrow_for_a_car_is_refused():
    with pytest.raises(InputError, match="leave no room for a car"):
        road_network(*street(road_half_width=0.6, parked_car=False))
