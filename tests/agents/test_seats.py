"""Seats found on a twin's benches, and pedestrians seated on them for the whole clip."""

import numpy as np
import pytest

from synthua_usd.agents.motion import simulate
from synthua_usd.agents.population import plan_agents
from synthua_usd.agents.seats import ORIGIN_FROM_BACK_M, find_seat_places
from synthua_usd.agents.walkable import build_grid, walkable_graph
from synthua_usd.demo.street import KERB_HEIGHT, ROAD_HALF_WIDTH, SIDEWALK_WIDTH, street_twin
from synthua_usd.model.taxonomy import ClassMap


@pytest.fixture(scope="module")
def street():
    v, f, labels = street_twin().labelled_triangles()
    names = np.array([ClassMap.default().resolve(label).name for label in labels], object)
    grid = build_grid(v, f, names)
    return v, f, names, grid


def test_the_street_bench_offers_three_places_facing_away_from_its_backrest(street):
    places = find_seat_places(*street)
    # The street's bench (synthua_usd.demo.street): seat 1.8 m long from x = -4.9 to -3.1, 0.4 m deep from
    # y = 5.8 to 6.2 with its top 0.47 m above the kerb-high sidewalk; backrest behind it, at y = 6.2-6.25.
    by = ROAD_HALF_WIDTH + SIDEWALK_WIDTH - 0.5
    assert len(places) == 3
    assert sorted(p.origin[0] for p in places) == pytest.approx([-4.6, -4.0, -3.4])
    for p in places:
        assert p.heading_deg == pytest.approx(-90.0)  # facing -Y, the road
        assert p.origin[1] == pytest.approx(by + 0.2 - ORIGIN_FROM_BACK_M)
        assert p.origin[2] == pytest.approx(KERB_HEIGHT, abs=1e-6)
        assert p.seat_height_m == pytest.approx(0.47, abs=1e-6)


def test_no_furniture_no_places(street):
    v, f, names, grid = street
    assert find_seat_places(v, f, np.where(names == "furniture", "vegetation", names), grid) == []


def test_seated_pedestrians_sit_still_on_free_places_facing_out(street):
    v, f, names, grid = street
    places = find_seat_places(v, f, names, grid)
    rng = np.random.default_rng(3)
    plans = plan_agents(rng, walkable_graph(grid), grid, 12, aid_share=0.0, min_route_m=3.0, rest_share=1.0,
                        seats=tuple(places))
    seated = [p for p in plans if p.seat is not None]
    assert len(seated) == 3  # every other resting pedestrian, while places are free
    assert len({p.seat for p in seated}) == 3
    trajectories, _ = simulate(plans, 24, 24.0)
    sitters = [t for t in trajectories if t.plan.seat is not None]
    assert sitters
    for t in sitters:
        assert np.allclose(t.positions, np.array(t.plan.seat.origin)[None])
        assert np.allclose(t.headings_deg, t.plan.seat.heading_deg)
        assert np.all(t.distance_m == 0.0)
