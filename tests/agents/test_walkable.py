"""Agents: walkable graph and profiles, Poisson populations, collision-free motion, the agents layer."""

import logging

import networkx as nx
import numpy as np
import pytest
from scipy import stats

from conftest import SCENARIO, STAGES
from synthua_usd import geometry as geo
from synthua_usd.agents.motion import MARGIN_M, simulate
from synthua_usd.agents.population import Plan, check_density, plan_agents, sample_count
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.agents.walkable import build_grid, edge_cost, shortest_path, walkable_graph
from synthua_usd.errors import InputError


def crossing_scene():
    """A 7 m road between two 3 m sidewalks (15 cm kerbs). Crosswalk A at x = -6 has a curb ramp only on
    the north side; crosswalk B at x = 8 has ramps on both sides."""
    parts, classes = [], []

    def add(mesh, cls):
        parts.append(mesh)
        classes.extend([cls] * len(mesh[1]))

    add(geo.box((-20, -3.5, -0.3), (20, 3.5, 0.0)), "road")
    for x in (-6.0, 8.0):
        add(geo.merge(*[geo.box((x - 1.5, y, 0.0), (x + 1.5, y + 0.5, 0.01)) for y in np.arange(-3.25, 3.25, 1.0)]),
            "crosswalk")
    ramps = {"north": [-6.0, 8.0], "south": [8.0]}
    for side, y_kerb, y_back in (("north", 3.5, 6.5), ("south", -3.5, -6.5)):
        sgn = 1 if y_back > y_kerb else -1
        cuts = sorted(ramps[side])
        start = -20.0
        for g in cuts + [None]:
            end = 20.0 if g is None else g - 1.0
            add(geo.box((start, *sorted((y_kerb, y_back))[:1], -0.3), (end, sorted((y_kerb, y_back))[1], 0.15)),
                "sidewalk")
            if g is not None:
                lo, hi = sorted((y_kerb + sgn * 1.8, y_back))
                add(geo.box((g - 1.0, lo, -0.3), (g + 1.0, hi, 0.15)), "sidewalk")
                low, high = (y_kerb, y_kerb + sgn * 1.8)
                add(geo.ramp(g - 1.0, g + 1.0, low, high, 0.005, 0.15, -0.3), "curb_ramp")
                start = g + 1.0
    verts, faces = geo.merge(*parts)
    return verts, faces, np.array(classes, object)


@pytest.fixture(scope="module")
def crossing():
    grid = build_grid(*crossing_scene(), cell_m=0.5)
    return grid, walkable_graph(grid)


def route(graph, grid, profile, a, b):
    return shortest_path(graph, grid.cell_of(*a), grid.cell_of(*b), PROFILES[profile])


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


def test_density_bounds(caplog):
    with pytest.raises(InputError, match="15 persons/m² is physically impossible.*crowd crush"):
        check_density(15.0)
    with pytest.raises(InputError, match="density should be > 0"):
        check_density(0.0)
    with caplog.at_level(logging.WARNING):
        check_density(1.0)
    assert "beyond level of service D" in caplog.text
    caplog.clear()
    check_density(0.1)
    assert caplog.text == ""


def test_poisson_counts_match_the_requested_mean():
    lam_density, area = 0.02, 600.0  # λ = 12
    lam = lam_density * area
    counts = np.array([sample_count(np.random.default_rng(seed), lam_density, area) for seed in range(3000)])
    # Mean within 4 standard errors, and the whole distribution against Poisson(12) by chi-square.
    assert abs(counts.mean() - lam) < 4 * np.sqrt(lam / len(counts))
    edges = np.arange(4, 22)  # bins: <=4, 5..20 each, >=21
    observed = np.array([(counts <= 4).sum()] + [(counts == k).sum() for k in edges[1:-1]] + [(counts >= 21).sum()])
    pmf = stats.poisson(lam)
    expected = np.array([pmf.cdf(4)] + [pmf.pmf(k) for k in edges[1:-1]] + [pmf.sf(20)]) * len(counts)
    assert observed.sum() == len(counts)
    _, p = stats.chisquare(observed, expected)
    assert p > 0.001, p


def corridor_plans(rng, graph, grid, n):
    return plan_agents(rng, graph, grid, n, aid_share=0.4, min_route_m=5.0)


def test_no_two_agents_overlap_at_any_frame(crossing):
    grid, graph = crossing
    plans = corridor_plans(np.random.default_rng(5), graph, grid, 60)
    trajs, dropped = simulate(plans, frames=72, fps=24.0)
    assert len(trajs) + dropped == 60 and len(trajs) >= 30
    from scipy.spatial.distance import cdist

    radii = np.array([t.plan.profile.radius_m for t in trajs])
    worst = np.inf
    for f in range(72):
        p = np.array([t.positions[f, :2] for t in trajs])
        gap = cdist(p, p) - radii[:, None] - radii[None, :]
        np.fill_diagonal(gap, np.inf)
        worst = min(worst, gap.min())
    assert worst >= MARGIN_M - 1e-9, worst


def test_agents_stay_on_walkable_cells(crossing):
    grid, graph = crossing
    trajs, _ = simulate(corridor_plans(np.random.default_rng(6), graph, grid, 30), frames=48, fps=24.0)
    for t in trajs:
        for x, y, z in t.positions:
            i, j = grid.cell_of(x, y)
            assert grid.walkable[i, j], (t.plan.profile.name, x, y)
            assert abs(z - grid.z[i, j]) < 0.2


def test_aid_users_never_cross_a_kerb(crossing):
    grid, graph = crossing
    plans = corridor_plans(np.random.default_rng(7), graph, grid, 40)
    cells = {tuple(np.round(graph.nodes[n]["pos"][:2], 3)): n for n in graph.nodes}
    for plan in plans:
        if plan.profile.can_step_kerb:
            continue
        nodes = [cells[tuple(np.round(p[:2], 3))] for p in plan.waypoints]
        assert not any(graph.edges[u, v]["kerb"] for u, v in zip(nodes, nodes[1:]))


def test_agents_pause_before_a_crosswalk(crossing):
    grid, graph = crossing
    path = route(graph, grid, "pedestrian", (-12.0, -5.0), (-12.0, 5.0))
    wp = np.array([graph.nodes[n]["pos"] for n in path])
    surfaces = tuple(graph.nodes[n]["surface"] for n in path)
    plan = Plan(PROFILES["pedestrian"], 1.3, wp, surfaces, 0.0, pause_before_crossing_s=2.0)
    (traj,), _ = simulate([plan], frames=24 * 12, fps=24.0)
    still = np.linalg.norm(np.diff(traj.positions[:, :2], axis=0), axis=1) < 1e-9
    run, longest = 0, 0
    for s in still:
        run = run + 1 if s else 0
        longest = max(longest, run)
    assert longest >= 2.0 * 24 - 1  # about two seconds standing at the kerb
    assert traj.distance_m[-1] > 9.0  # and then it crosses


def test_populate_is_deterministic_per_seed(run_cli, tmp_path):
    args = ("agents", "populate", SCENARIO, "--density", "0.05", "--frames", "12")
    assert run_cli(*args, "--seed", "4", "--out", tmp_path / "a.usda")[0] == 0
    assert run_cli(*args, "--seed", "4", "--out", tmp_path / "b.usda")[0] == 0
    assert run_cli(*args, "--seed", "5", "--out", tmp_path / "c.usda")[0] == 0
    a, b, c = ((tmp_path / n).read_bytes() for n in ("a.usda", "b.usda", "c.usda"))
    assert a == b and a != c


def test_populate_refuses_impossible_density_and_writes_nothing(run_cli, tmp_path):
    code, _, err = run_cli("agents", "populate", SCENARIO, "--density", "15", "--out", tmp_path / "a.usda")
    assert code == 2 and "physically impossible" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "a.usda").exists()


@pytest.mark.slow
def test_populated_layer_composes_renders_and_exports_person_device_pairs(run_cli, tmp_path):
    import json

    code, out, _ = run_cli("agents", "populate", SCENARIO, "--density", "0.2", "--aid-share", "1.0", "--frames", "24",
                           "--seed", "1", "--out", tmp_path / "crowd.usda")
    assert code == 0 and "with mobility aids" in out
    layers = [tmp_path / "crowd.usda"] + [STAGES / n for n in ("render.usda", "environment.usda", "cameras.usda",
                                                                 "semantics.usda", "twin.usda")]
    assert run_cli("compose", tmp_path / "scene.usda", *layers)[0] == 0
    assert run_cli("validate", "stage", tmp_path / "scene.usda")[0] == 0
    code, _, err = run_cli("render", tmp_path / "scene.usda", "--camera", "/World/Cameras/CCTV", "--frame", "12",
                           "--width", "160", "--height", "120", "--spp", "1", "--out", tmp_path / "frame")
    assert code == 0, err
    doc = json.loads((tmp_path / "frame" / "frame.json").read_text())
    by_path = {i["prim_path"]: i for i in doc["instances"]}
    pairs = [(i, by_path[i["relations"]["uses"]]) for i in doc["instances"]
             if i["prim_path"].startswith("/World/Agents/Agent_") and "relations" in i]
    assert pairs
    aid_classes = {"manual_wheelchair", "electric_wheelchair", "walker", "crutch", "smart_cane", "wooden_cane",
                   "orthopedic_cane", "tripod_cane"}
    for person, device in pairs:
        assert person["class_name"] == "person" and device["class_name"] in aid_classes
        assert person["id"] != device["id"]
    assert any(p["pixel_count"] and d["pixel_count"] for p, d in pairs)


def test_walk_on_roads_for_twins_without_sidewalks(run_cli, tmp_path):
    from conftest import DATA

    assert run_cli("twin", "import", "cityjson", DATA / "valid" / "lod2_house.city.json", "--out", tmp_path)[0] == 0
    code, _, err = run_cli("agents", "populate", tmp_path / "scenario.usda", "--out", tmp_path / "a.usda")
    assert code == 2 and "add --walk-on road" in err and not (tmp_path / "a.usda").exists()
    code, out, err = run_cli("agents", "populate", tmp_path / "scenario.usda", "--walk-on", "sidewalk,road",
                             "--density", "0.05", "--frames", "6", "--out", tmp_path / "a.usda")
    assert code == 0, err
    assert "walkable area 134 m²" in out  # 20 x 7 m road less its 2 x 3 m hole
    code, _, err = run_cli("agents", "populate", tmp_path / "scenario.usda", "--walk-on", "lava",
                           "--out", tmp_path / "b.usda")
    assert code == 2 and "walkable classes ['lava'] are not classes" in err


def test_some_agents_walk_to_a_bench_and_stay():
    verts, faces, classes = crossing_scene()
    bench_v, bench_f = geo.box((-14.0, 5.5, 0.45), (-12.0, 6.0, 0.5))  # a bench seat on the north sidewalk
    verts = np.concatenate([verts, bench_v])
    faces = np.concatenate([faces, bench_f + len(verts) - len(bench_v)])
    classes = np.concatenate([classes, np.array(["furniture"] * len(bench_f), object)])
    grid = build_grid(verts, faces, classes, cell_m=0.5)
    graph = walkable_graph(grid)
    beside = set(grid.cells_beside("furniture"))
    assert beside
    plans = plan_agents(np.random.default_rng(2), graph, grid, 3, aid_share=0.0, rest_share=1.0)
    assert all(p.rests for p in plans)
    trajs, _ = simulate(plans, frames=24 * 8, fps=24.0)
    for t in trajs:
        end = t.positions[-1]
        assert grid.cell_of(end[0], end[1]) in beside
        assert np.allclose(t.positions[-24:], end)  # resting for at least the last second
