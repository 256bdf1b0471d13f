"""The walkable grid and graph, and the routes each profile may take over it."""

import networkx as nx
import pytest

from crossing import crossing_network, route
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.agents.walkable import edge_cost, shortest_path


@pytest.fixture(scope="module")
def crossing():
    return crossing_network()


def test_grid_surfaces(crossing):
    grid, graph = crossing
    kinds = set(grid.surface[grid.walkable])
    assert kinds == {"sidewalk", "crosswalk", "curb_ramp"}
    i, j = grid.cell_of(0.0, 0.0)  # the middle of the road, away from crosswalks
    assert not grid.walkable[i, j]
    i, j = grid.cell_of(-6.0, 0.25)  # a gap between zebra bars still counts as crosswalk
    assert grid.surface[i, j] == "crosswalk"


def test_pedestrian_steps_the_kerb_but_wheelchair_uses_ramps(crossing):
    grid, graph = crossing
    a, b = (-6.0, -5.0), (-6.0, 5.0)  # across crosswalk A: ramp only on the north side
    walk = route(graph, grid, "pedestrian", a, b)
    kerbs = [graph.edges[u, v]["kerb"] for u, v in zip(walk, walk[1:])]
    assert any(kerbs)  # stepped up or down a kerb
    assert max(abs(graph.nodes[n]["pos"][0] + 6.0) for n in walk) < 2.5  # straight over crosswalk A
    for profile in ("manual_wheelchair", "electric_wheelchair", "walker"):
        roll = route(graph, grid, profile, a, b)
        edges = [graph.edges[u, v] for u, v in zip(roll, roll[1:])]
        assert not any(e["kerb"] for e in edges), profile
        assert max(e["slope"] for e in edges) <= PROFILES[profile].max_slope
        surfaces = [graph.nodes[n]["surface"] for n in roll]
        assert surfaces.count("curb_ramp") >= 4  # down one ramp, up the other
        # It detours to crosswalk B, the only one with ramps on both sides.
        crossing_x = [graph.nodes[n]["pos"][0] for n in roll if graph.nodes[n]["surface"] == "crosswalk"]
        assert min(crossing_x) > 6.0


def test_no_route_without_ramps(crossing):
    grid, graph = crossing
    sub = graph.subgraph([n for n in graph.nodes if graph.nodes[n]["pos"][0] < 2.0])  # only crosswalk A
    with pytest.raises(nx.NetworkXNoPath):
        shortest_path(sub, grid.cell_of(-10, -5), grid.cell_of(-10, 5), PROFILES["manual_wheelchair"])


def test_slopes_and_cobbles_cost_more_for_wheelchairs():
    flat = {"kerb": False, "slope": 0.0, "length_m": 1.0, "cobbles": False}
    ramp = dict(flat, slope=0.08)
    cobbles = dict(flat, cobbles=True)
    for name in ("pedestrian", "manual_wheelchair"):
        cost = edge_cost(PROFILES[name])
        assert cost(0, 1, ramp) > cost(0, 1, flat) and cost(0, 1, cobbles) > cost(0, 1, flat)
    ped, chair = edge_cost(PROFILES["pedestrian"]), edge_cost(PROFILES["manual_wheelchair"])
    assert chair(0, 1, ramp) / chair(0, 1, flat) > ped(0, 1, ramp) / ped(0, 1, flat)
    assert chair(0, 1, dict(flat, slope=0.12)) is None and chair(0, 1, dict(flat, kerb=True)) is None

