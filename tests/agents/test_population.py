"""Populations: density bounds, Poisson counts, routes that respect each profile, agents who rest."""

import logging

import numpy as np
import pytest
from scipy import stats

from crossing import corridor_plans, crossing_network, crossing_scene
from synthua_usd.agents.motion import simulate
from synthua_usd.agents.population import check_density, plan_agents, sample_count
from synthua_usd.agents.walkable import build_grid, walkable_graph
from synthua_usd.core.errors import InputError
from synthua_usd.model import meshes as geo


@pytest.fixture(scope="module")
def crossing():
    return crossing_network()


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


def test_aid_users_never_cross_a_kerb(crossing):
    grid, graph = crossing
    plans = corridor_plans(np.random.default_rng(7), graph, grid, 40)
    cells = {tuple(np.round(graph.nodes[n]["pos"][:2], 3)): n for n in graph.nodes}
    for plan in plans:
        if plan.profile.can_step_kerb:
            continue
        nodes = [cells[tuple(np.round(p[:2], 3))] for p in plan.waypoints]
        assert not any(graph.edges[u, v]["kerb"] for u, v in zip(nodes, nodes[1:]))


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
    trajs, _ = simulate(plans, time_codes=24 * 8, fps=24.0)
    for t in trajs:
        end = t.positions[-1]
        assert grid.cell_of(end[0], end[1]) in beside
        assert np.allclose(t.positions[-24:], end)  # resting for at least the last second

