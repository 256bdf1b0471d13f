"""Populate a twin or scenario with agents and write them as a composable USD layer: ``synthua agents populate``."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from synthua_usd.agents.motion import min_separation, simulate
from synthua_usd.agents.population import DEFAULT_AID_SHARE, check_density, plan_agents, sample_count
from synthua_usd.agents.walkable import WALKABLE, build_grid, walkable_graph
from synthua_usd.assets.people import PersonLook
from synthua_usd.errors import InputError
from synthua_usd.taxonomy import ClassMap
from synthua_usd.usd.agents_writer import AGENTS_ROOT, write_agents_layer
from synthua_usd.usd.authoring import StageMetadata
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.stage_io import open_stage

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class PopulateRequest:
    stage_path: Path
    out_path: Path
    density_per_m2: float = 0.03
    aid_share: float = DEFAULT_AID_SHARE
    frames: int = 48
    seed: int = 0
    cell_m: float = 0.5
    class_map_path: Path | None = None
    walkable: tuple[str, ...] = WALKABLE


@dataclass
class PopulateReport:
    walkable_area_m2: float
    expected: float
    sampled: int
    placed: int
    dropped: int
    aid_users: int
    by_profile: dict[str, int]
    min_separation_m: float
    seconds: float
    files: list[Path] = field(default_factory=list)


def populate(request: PopulateRequest) -> PopulateReport:
    """Walkable graph → Poisson population → routes (A*) → collision-free motion → agents layer.

    Agents already in the stage (under ``/World/Agents``) are ignored: the new layer is meant to replace
    them. Everything else, parked devices of the twin included, is terrain or obstacle."""
    t0 = time.perf_counter()
    check_density(request.density_per_m2)
    if request.frames < 1:
        raise InputError(f"frames should be >= 1, but was {request.frames}")
    if not 0.0 <= request.aid_share <= 1.0:
        raise InputError(f"aid share should be a fraction in [0, 1], but was {request.aid_share}")
    class_map = ClassMap.load(request.class_map_path) if request.class_map_path else ClassMap.default()
    unknown = [c for c in request.walkable if class_map.resolve(c) is None]
    if unknown:
        raise InputError(f"walkable classes {unknown} are not classes of {class_map.source}")
    stage = open_stage(request.stage_path)
    start = stage.GetStartTimeCode() if stage.HasAuthoredTimeCodeRange() else 1.0
    fps = stage.GetTimeCodesPerSecond()
    snapshot = read_snapshot(stage, start, class_map)
    # Agents already in the stage (an earlier agents layer) are not part of the twin.
    snapshot = replace(snapshot, meshes=tuple(m for m in snapshot.meshes if not m.prim_path.startswith(AGENTS_ROOT + "/")))
    verts, faces, owner = snapshot.world_triangles()
    names = np.array([class_map.by_id(m.class_id).name for m in snapshot.meshes], object)
    grid = build_grid(verts, faces, names[owner] if len(owner) else np.zeros(0, object), request.cell_m,
                      tuple(class_map.resolve(c).name for c in request.walkable))
    graph = walkable_graph(grid)
    rng = np.random.default_rng(request.seed)
    count = sample_count(rng, request.density_per_m2, grid.area_m2())
    plans = plan_agents(rng, graph, grid, count, request.aid_share)
    trajectories, dropped = simulate(plans, request.frames, fps)
    looks = [PersonLook.random(rng) for _ in trajectories]
    meta = StageMetadata(up_axis="Z", meters_per_unit=1.0, time_codes_per_second=fps, start_time_code=start,
                         end_time_code=start + request.frames - 1, default_prim="World")
    doc = (f"synthua agents for {request.stage_path.name}: density {request.density_per_m2:g}/m², aid share "
           f"{request.aid_share:g}, seed {request.seed}, {len(trajectories)} agents, {request.frames} frames.")
    path = write_agents_layer(request.out_path, trajectories, looks, meta, class_map.taxonomy, doc)
    by_profile: dict[str, int] = {}
    for t in trajectories:
        by_profile[t.plan.profile.name] = by_profile.get(t.plan.profile.name, 0) + 1
    return PopulateReport(walkable_area_m2=grid.area_m2(), expected=request.density_per_m2 * grid.area_m2(),
                          sampled=count, placed=len(trajectories), dropped=dropped,
                          aid_users=sum(1 for t in trajectories if t.plan.profile.device),
                          by_profile=dict(sorted(by_profile.items())), min_separation_m=min_separation(trajectories),
                          seconds=time.perf_counter() - t0, files=[path])
