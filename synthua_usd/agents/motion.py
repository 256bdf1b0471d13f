"""Time-sampled motion: agents move along their routes at their speeds, pause before stepping onto a
crosswalk, and never come closer than ``MARGIN_M`` between their discs at any sampled time.

Planning is prioritised: agents are placed one after another; at each frame an agent advances along its
route unless that would bring it within r_i + r_j + MARGIN_M of an agent already placed, in which case it
waits. An agent that cannot even wait without a conflict (or cannot start) is dropped and counted.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from synthua_usd.agents.population import Plan

MARGIN_M = 0.1
START_TRIES = 5


@dataclass(frozen=True, eq=False)
class Trajectory:
    """``positions`` (T, 3) world metres on the walkable surface, one row per time code; ``headings_deg``
    (T,) about Z (0 = +X); ``distance_m`` (T,) travelled so far (drives the walking cycle)."""

    plan: Plan
    positions: np.ndarray
    headings_deg: np.ndarray
    distance_m: np.ndarray


def _along(waypoints: np.ndarray, s: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Point and unit direction at arc length ``s`` (clamped), and the waypoint index reached."""
    seg = np.diff(waypoints, axis=0)
    lengths = np.linalg.norm(seg[:, :2], axis=1)
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    s = float(np.clip(s, 0.0, cum[-1]))
    k = int(np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1))
    t = (s - cum[k]) / lengths[k] if lengths[k] > 0 else 0.0
    d = seg[k, :2] / (lengths[k] or 1.0)
    return waypoints[k] + t * seg[k], d, k


def simulate(plans: list[Plan], time_codes: int, fps: float) -> tuple[list[Trajectory], int]:
    """Trajectories sampled at ``time_codes`` consecutive time codes ``1 / fps`` s apart for the agents
    that fit, and how many were dropped."""
    dt = 1.0 / fps
    placed: list[Trajectory] = []
    dropped = 0
    for plan in plans:
        traj = None
        # A start already taken is moved further along the route (a few tries) before giving up.
        for attempt in range(START_TRIES):
            traj = _simulate_one(replace(plan, start_offset_m=plan.start_offset_m + 2.0 * attempt), time_codes, dt, placed)
            if traj is not None:
                break
        if traj is None:
            dropped += 1
        else:
            placed.append(traj)
    return placed, dropped


def _conflicts(p: np.ndarray, r: float, frame: int, placed: list[Trajectory]) -> bool:
    for other in placed:
        limit = r + other.plan.profile.radius_m + MARGIN_M
        q = other.positions[frame]
        if (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 < limit * limit:
            return True
    return False


def _simulate_one(plan: Plan, time_codes: int, dt: float, placed: list[Trajectory]) -> Trajectory | None:
    r = plan.profile.radius_m
    wp = plan.waypoints
    s = plan.start_offset_m
    point, direction, k = _along(wp, s)
    p = point
    if _conflicts(p, r, 0, placed):
        return None
    heading = plan.seat.heading_deg if plan.seat is not None else np.degrees(np.arctan2(direction[1], direction[0]))
    positions, headings, travelled = [p], [heading], [0.0]
    waited = 0.0
    entered_crossing = plan.surfaces[k] == "crosswalk"
    for f in range(1, time_codes):
        s_next = s + plan.speed_mps * dt
        point_n, dir_n, k_n = _along(wp, s_next)
        # Pause at the kerb before the first crosswalk cell, then go.
        if not entered_crossing and "crosswalk" in plan.surfaces[k + 1:k_n + 2] and waited < plan.pause_before_crossing_s:
            waited += dt
            s_next, point_n, dir_n, k_n = s, point, direction, k
        elif "crosswalk" in plan.surfaces[k:k_n + 1]:
            entered_crossing = True
        p_n = point_n
        if _conflicts(p_n, r, f, placed):
            p_n = positions[-1]  # wait where we are
            if _conflicts(p_n, r, f, placed):
                return None
            s_next, point_n, dir_n, k_n = s, point, direction, k
        moved = float(np.linalg.norm(p_n[:2] - positions[-1][:2]))
        positions.append(p_n)
        headings.append(np.degrees(np.arctan2(dir_n[1], dir_n[0])) if moved > 1e-6 else headings[-1])
        travelled.append(travelled[-1] + moved)
        s, point, direction, k = s_next, point_n, dir_n, k_n
    return Trajectory(plan, np.array(positions), np.unwrap(np.array(headings), period=360.0), np.array(travelled))


def min_separation(trajectories: list[Trajectory]) -> float:
    """Smallest gap between any two agents' discs over all time codes (metres); inf for fewer than two."""
    if len(trajectories) < 2:
        return float("inf")
    pos = np.stack([t.positions[:, :2] for t in trajectories])  # (agents, time codes, 2)
    radii = np.array([t.plan.profile.radius_m for t in trajectories])
    best = np.inf
    for f in range(pos.shape[1]):
        d = np.linalg.norm(pos[:, None, f] - pos[None, :, f], axis=-1) - radii[:, None] - radii[None, :]
        np.fill_diagonal(d, np.inf)
        best = min(best, float(d.min()))
    return best
