"""Motion: collision-free trajectories on walkable cells, pauses at the kerb."""

import numpy as np
import pytest
from scipy.spatial.distance import cdist

from crossing import corridor_plans, crossing_network, route
from synthua_usd.agents.motion import MARGIN_M, simulate
from synthua_usd.agents.population import Plan
from synthua_usd.agents.profiles import PROFILES


@pytest.fixture(scope="module")
def crossing():
    return crossing_network()


def test_no_two_agents_overlap_at_any_frame(crossing):
    grid, graph = crossing
    plans = corridor_plans(np.random.default_rng(5), graph, grid, 60)
    trajs, dropped = simulate(plans, time_codes=72, fps=24.0)
    assert len(trajs) + dropped == 60 and len(trajs) >= 30
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
    trajs, _ = simulate(corridor_plans(np.random.default_rng(6), graph, grid, 30), time_codes=48, fps=24.0)
    for t in trajs:
        for x, y, z in t.positions:
            i, j = grid.cell_of(x, y)
            assert grid.walkable[i, j], (t.plan.profile.name, x, y)
            assert abs(z - grid.z[i, j]) < 0.2


def test_agents_pause_before_a_crosswalk(crossing):
    grid, graph = crossing
    path = route(graph, grid, "pedestrian", (-12.0, -5.0), (-12.0, 5.0))
    wp = np.array([graph.nodes[n]["pos"] for n in path])
    surfaces = tuple(graph.nodes[n]["surface"] for n in path)
    plan = Plan(PROFILES["pedestrian"], 1.3, wp, surfaces, 0.0, pause_before_crossing_s=2.0)
    (traj,), _ = simulate([plan], time_codes=24 * 12, fps=24.0)
    still = np.linalg.norm(np.diff(traj.positions[:, :2], axis=0), axis=1) < 1e-9
    run, longest = 0, 0
    for s in still:
        run = run + 1 if s else 0
        longest = max(longest, run)
    assert longest >= 2.0 * 24 - 1  # about two seconds standing at the kerb
    assert traj.distance_m[-1] > 9.0  # and then it crosses

