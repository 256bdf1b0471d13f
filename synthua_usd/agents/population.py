"""Populations: how many agents (Poisson in the walkable area), who they are, and where they go.

Density is persons per m² of walkable area. Above ``MAX_DENSITY`` (5 /m², where crowd crush begins; the
paper's 15 /m² is physically impossible) it is refused; above ``LOS_WARN_DENSITY`` (0.7 /m², the start
of Fruin's walkway level of service E: movement constrained) it is accepted with a warning.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from synthua_usd.agents.profiles import AID_PROFILES, PROFILES, AgentProfile
from synthua_usd.agents.seats import SeatPlace
from synthua_usd.agents.walkable import Router, WalkableGrid
from synthua_usd.core.errors import InputError

if TYPE_CHECKING:  # imported where used (~0.2 s that most processes never need)
    import networkx as nx

log = logging.getLogger(__name__)

MAX_DENSITY = 5.0
LOS_WARN_DENSITY = 0.7
#: A default that puts a mobility-aid user in most camera views of the demo district.
DEFAULT_AID_SHARE = 0.3
#: Consecutive agents for whom no route is found before the walkable surface is declared unusable.
MAX_ROUTE_MISSES = 200


def check_density(density_per_m2: float) -> None:
    """Refuse impossible densities with the reason; warn above the level-of-service threshold."""
    if not (np.isfinite(density_per_m2) and density_per_m2 > 0):
        raise InputError(f"density should be > 0 persons/m², but was {density_per_m2}")
    if density_per_m2 > MAX_DENSITY:
        raise InputError(f"density {density_per_m2:g} persons/m² is physically impossible for moving people: crowd "
                         f"crush begins near 5-6 persons/m² (the paper's 15/m² cannot happen); use at most "
                         f"{MAX_DENSITY:g}, and below {LOS_WARN_DENSITY:g} for free walking")
    if density_per_m2 > LOS_WARN_DENSITY:
        log.warning("density %g persons/m² is beyond level of service D (%g/m²): people can barely move; "
                    "collision-free placement may drop agents", density_per_m2, LOS_WARN_DENSITY)


def sample_count(rng: np.random.Generator, density_per_m2: float, area_m2: float) -> int:
    """N ~ Poisson(λ = density x walkable area)."""
    check_density(density_per_m2)
    return int(rng.poisson(density_per_m2 * area_m2))


@dataclass(frozen=True, eq=False)
class Plan:
    """One agent's route: ``waypoints`` (k, 3) world metres along the walkable graph, and where to pause."""

    profile: AgentProfile
    speed_mps: float
    waypoints: np.ndarray
    surfaces: tuple[str, ...]
    start_offset_m: float
    pause_before_crossing_s: float
    group: int | None = None
    rests: bool = False  # walks to a bench and stays there
    seat: SeatPlace | None = None  # sits there (on a bench) all the time


def plan_agents(rng: np.random.Generator, graph: nx.Graph, grid: WalkableGrid, count: int, aid_share: float,
                min_route_m: float = 15.0, rest_share: float = 0.15, seats: tuple[SeatPlace, ...] = ()) -> list[Plan]:
    """Routes for ``count`` agents: ``aid_share`` of them (rounded stochastically) use mobility aids.

    Each agent walks between two random reachable cells at least ``min_route_m`` apart, starting at a
    random point along its route; about a third of pedestrians come in groups of two or three, who share
    a route and walk 0.9 m apart. ``rest_share`` of single agents head for a bench (a cell beside street
    furniture) and arrive within the first seconds, then stay there; of the pedestrians among them, every
    other one is instead seated the whole time at the free place of ``seats`` nearest its route's end
    (while places are free).
    """
    if not 0.0 <= aid_share <= 1.0:
        raise InputError(f"aid share should be a fraction in [0, 1], but was {aid_share}")
    nodes = sorted(graph.nodes)
    if not nodes:
        raise InputError("the twin has no walkable surface of the walkable classes (default sidewalk, crosswalk, "
                         "curb_ramp, street_road); for twins whose roads include sidewalks add --walk-on road")
    pos = np.array([graph.nodes[n]["pos"] for n in nodes])
    benches = sorted(set(grid.cells_beside("furniture")) & set(graph.nodes))
    index = {n: k for k, n in enumerate(nodes)}
    bench_index = [index[n] for n in benches]
    router = Router(graph)  # each profile's edge costs once for all routes
    plans: list[Plan] = []
    free = list(seats)
    resting_pedestrians = 0
    group_id = 0
    misses = 0
    while len(plans) < count:
        is_aid = rng.random() < aid_share
        profile = PROFILES[AID_PROFILES[int(rng.integers(len(AID_PROFILES)))]] if is_aid else PROFILES["pedestrian"]
        rests = bool(benches) and rng.random() < rest_share
        route = _route(rng, router, nodes, pos, profile, min_route_m, bench_index if rests else None)
        if route is None:
            misses += 1
            if misses > MAX_ROUTE_MISSES:
                area = len(nodes) * grid.cell_m ** 2
                raise InputError(f"walkable surface: {area:g} m² in {len(nodes)} cells holds no route of at least "
                                 f"{min_route_m:g} m after {MAX_ROUTE_MISSES} tries; expected connected sidewalks or "
                                 f"streets (check --walk-on)")
            continue
        misses = 0
        waypoints, surfaces = route
        length = float(np.linalg.norm(np.diff(waypoints, axis=0), axis=1).sum())
        speed = float(np.clip(rng.normal(profile.speed_mps, profile.speed_sd_mps), 0.5 * profile.speed_mps,
                              1.5 * profile.speed_mps))
        # Resting agents are 1-3 m from their bench at the first frame; the others anywhere on the way.
        offset = max(length - float(rng.uniform(1.0, 3.0)), 0.0) if rests else float(rng.uniform(0, 0.8 * length))
        pause = float(rng.uniform(1.0, 4.0))
        size = int(rng.choice([2, 3])) if (not is_aid and not rests and rng.random() < 0.3) else 1
        size = min(size, count - len(plans))
        gid = group_id if size > 1 else None
        group_id += size > 1
        place = None
        if rests and profile.device is None:
            resting_pedestrians += 1
            if free and resting_pedestrians % 2 == 0:
                place = min(free, key=lambda q: float(np.linalg.norm(np.subtract(q.origin[:2], waypoints[-1][:2]))))
                free.remove(place)
                waypoints, surfaces, offset = np.array([place.origin, place.origin]), ("seat", "seat"), 0.0
        for k in range(size):
            plans.append(Plan(profile, speed, waypoints, surfaces, max(offset - 0.9 * k, 0.0), pause, gid, rests, place))
    return plans


def _route(rng, router, nodes, pos, profile, min_route_m, goals=None):
    """Waypoints (k, 3) and surfaces of a route of ``profile`` between two random nodes at least ``min_route_m``
    apart (the second one of ``goals``, indices into ``nodes``, if given); None after 20 tries."""
    import networkx as nx
    graph = router.graph
    for _ in range(20):
        a, b = rng.integers(len(nodes), size=2)
        if goals:
            b = goals[int(rng.integers(len(goals)))]
        if np.linalg.norm(pos[a, :2] - pos[b, :2]) < min_route_m:
            continue
        try:
            path = router.path(nodes[a], nodes[b], profile)
        except nx.NetworkXNoPath:
            continue
        return (np.array([graph.nodes[n]["pos"] for n in path]), tuple(graph.nodes[n]["surface"] for n in path))
    return None
