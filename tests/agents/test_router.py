"""The router's A* against networkx's: the same path, node for node, for every profile on the demo street and
the demo district (routes are part of the committed stages, so an equally short path is not enough)."""

import math

import networkx as nx
import numpy as np
import pytest

from synthua_usd.agents.profiles import PROFILES
from synthua_usd.agents.walkable import Router, build_grid, walkable_graph
from synthua_usd.model.taxonomy import ClassMap


def reference_cost(profile):
    """The travel time as networkx's weight function, in scalar Python (the formula before the router)."""
    def cost(u, v, data):
        if data["kerb"]:
            if not profile.can_step_kerb:
                return None
            return data["length_m"] / profile.speed_mps + 0.5
        if data["slope"] > profile.max_slope:
            return None
        t = data["length_m"] / profile.speed_mps
        t *= 1.0 + profile.slope_penalty * max(0.0, data["slope"] - 0.02)
        if data["cobbles"]:
            t *= profile.cobble_factor
        return t
    return cost


def reference_path(graph, start, goal, profile):
    def heuristic(a, b):
        return float(np.linalg.norm(graph.nodes[a]["pos"][:2] - graph.nodes[b]["pos"][:2])) / profile.speed_mps

    return nx.astar_path(graph, start, goal, heuristic=heuristic, weight=reference_cost(profile))


def twin_graph(model):
    """The walkable graph of a twin model, as its crowd is populated (float32 points, default class map)."""
    class_map = ClassMap.default()
    vertices, faces, labels = model.labelled_triangles()
    names = np.array([class_map.resolve(label).name for label in labels], object)
    return walkable_graph(build_grid(vertices.astype(np.float32).astype(np.float64), faces, names))


@pytest.fixture(scope="module")
def street_graph():
    from synthua_usd.demo.street import street_twin
    return twin_graph(street_twin())


@pytest.fixture(scope="module")
def district_graph():
    from synthua_usd.demo.district import build_district
    return twin_graph(build_district(0, textures=False))


def same_paths(graph, pairs_per_profile, seed):
    """Route ``pairs_per_profile`` random start and goal nodes (a few the same) for every profile through one
    router and through networkx; returns how many paths were found and how many pairs were unreachable (the
    router must then raise as networkx does)."""
    rng = np.random.default_rng(seed)
    nodes = sorted(graph.nodes)
    router = Router(graph)
    routed = unreachable = 0
    for profile in PROFILES.values():
        for _ in range(pairs_per_profile):
            a, b = (nodes[int(k)] for k in rng.integers(len(nodes), size=2))
            if rng.random() < 0.05:
                b = a
            try:
                expected = reference_path(graph, a, b, profile)
            except nx.NetworkXNoPath:
                with pytest.raises(nx.NetworkXNoPath):
                    router.path(a, b, profile)
                unreachable += 1
                continue
            assert router.path(a, b, profile) == expected, (profile.name, a, b)
            routed += 1
    return routed, unreachable


def test_router_costs_are_the_scalar_formula(street_graph, district_graph):
    """Every edge's travel time for every profile, bit for bit (inf where networkx's weight says None)."""
    for graph in (street_graph, district_graph):
        router = Router(graph)
        for profile in PROFILES.values():
            cost, reference = router.costs(profile), reference_cost(profile)
            entries = [(u, v, data) for u in router.nodes for v, data in graph.adj[u].items()]
            assert len(cost) == len(entries)
            for c, (u, v, data) in zip(cost, entries):
                r = reference(u, v, data)
                assert (c == math.inf) if r is None else c == r, (profile.name, u, v, c, r)


def test_router_paths_equal_networkx_on_the_demo_street(street_graph):
    routed, unreachable = same_paths(street_graph, 40, seed=1)
    assert routed > 250 and unreachable > 0  # wheelchairs and walkers cannot reach every sidewalk


@pytest.mark.slow
def test_router_paths_equal_networkx_on_the_district(district_graph):
    routed, _ = same_paths(district_graph, 8, seed=2)
    assert routed > 60
