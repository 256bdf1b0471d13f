"""A crowd: agents placed, routed and animated on the walkable surfaces of a twin, with their looks.

:func:`populate_crowd` is the whole chain from triangles to trajectories: walkable grid → graph →
Poisson population → routes (A*) and places on benches → collision-free motion → looks. It takes plain arrays, so a twin
model (the demos) and a stage read through USD (``synthua agents populate``) populate the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from synthua_usd.agents.motion import Trajectory, min_separation, simulate
from synthua_usd.agents.population import DEFAULT_AID_SHARE, check_density, plan_agents, sample_count
from synthua_usd.agents.seats import find_seat_places
from synthua_usd.agents.walkable import WALKABLE, build_grid, walkable_graph
from synthua_usd.assets.people import PersonLook
from synthua_usd.core.errors import InputError


#: Most time codes a crowd is animated over (the motion planner's work grows with agents² x time codes).
MAX_TIME_CODES = 10_000


@dataclass(frozen=True)
class CrowdParams:
    """How to populate. ``density_per_m2`` persons per m² of walkable area; ``aid_share`` the fraction
    using a mobility aid; ``time_codes`` samples at ``time_codes_per_second``; ``cell_m`` the walkable grid
    cell; ``walkable`` the class names people walk on."""

    density_per_m2: float = 0.03
    aid_share: float = DEFAULT_AID_SHARE
    time_codes: int = 48
    time_codes_per_second: float = 24.0
    seed: int = 0
    cell_m: float = 0.5
    walkable: tuple[str, ...] = WALKABLE

    def __post_init__(self) -> None:
        check_density(self.density_per_m2)
        if not (isinstance(self.time_codes, int) and 1 <= self.time_codes <= MAX_TIME_CODES):
            raise InputError(f"time codes: {self.time_codes!r}; expected an integer in 1..{MAX_TIME_CODES}")
        if not (math.isfinite(self.aid_share) and 0.0 <= self.aid_share <= 1.0):
            raise InputError(f"aid share should be a fraction in [0, 1], but was {self.aid_share}")
        if not (math.isfinite(self.cell_m) and self.cell_m > 0):
            raise InputError(f"cell size should be a finite number of metres > 0, but was {self.cell_m}")
        if not self.walkable:
            raise InputError("walkable classes should name at least one class people walk on, but none were given")


@dataclass(frozen=True, eq=False)
class Crowd:
    """Trajectories and looks, aligned; and what populating found (``report``: walkable area, expected,
    sampled, placed and dropped counts, aid users, agents per profile, minimum gap in metres)."""

    trajectories: tuple[Trajectory, ...]
    looks: tuple[PersonLook, ...]
    params: CrowdParams
    report: dict

    @property
    def doc(self) -> str:
        p = self.params
        return (f"synthua agents: density {p.density_per_m2:g}/m², aid share {p.aid_share:g}, seed {p.seed}, "
                f"{len(self.trajectories)} agents, {p.time_codes} time codes.")


def populate_crowd(vertices: np.ndarray, faces: np.ndarray, face_class: np.ndarray, params: CrowdParams) -> Crowd:
    """Populate the surfaces ``vertices`` (n, 3) float64 world metres Z up, ``faces`` (m, 3) int64 with
    class names ``face_class`` (m,) object."""
    grid = build_grid(vertices, faces, face_class, params.cell_m, params.walkable)
    graph = walkable_graph(grid)
    rng = np.random.default_rng(params.seed)
    count = sample_count(rng, params.density_per_m2, grid.area_m2())
    seats = tuple(find_seat_places(vertices, faces, face_class, grid))
    plans = plan_agents(rng, graph, grid, count, params.aid_share, seats=seats)
    trajectories, dropped = simulate(plans, params.time_codes, params.time_codes_per_second)
    looks = [PersonLook.random(rng, aid_user=t.plan.profile.device is not None) for t in trajectories]
    by_profile: dict[str, int] = {}
    for t in trajectories:
        by_profile[t.plan.profile.name] = by_profile.get(t.plan.profile.name, 0) + 1
    report = {"walkable_area_m2": grid.area_m2(), "expected": params.density_per_m2 * grid.area_m2(),
              "sampled": count, "placed": len(trajectories), "dropped": dropped,
              "aid_users": sum(1 for t in trajectories if t.plan.profile.device),
              "seated": sum(1 for t in trajectories if t.plan.seat is not None),
              "by_profile": dict(sorted(by_profile.items())), "min_separation_m": min_separation(trajectories)}
    return Crowd(tuple(trajectories), tuple(looks), params, report)


def scripted_crowd(trajectories: list[Trajectory], looks: list[PersonLook], params: CrowdParams) -> Crowd:
    """A crowd whose routes were scripted, not sampled (the demo street)."""
    return Crowd(tuple(trajectories), tuple(looks), params,
                 {"placed": len(trajectories), "min_separation_m": min_separation(trajectories)})
