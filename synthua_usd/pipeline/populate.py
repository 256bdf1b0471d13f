"""Populate a twin or scenario stage with agents and write them as a composable layer: ``synthua agents populate``."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synthua_usd.agents.crowd import Crowd, CrowdParams, populate_crowd
from synthua_usd.composition.scenario import StageMetadata
from synthua_usd.core.errors import InputError
from synthua_usd.core.input_guard import check_not_inputs
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.usd.agents_writer import AGENTS_ROOT, build_agents_layer
from synthua_usd.usd.authoring import check_layer_path, save_layer_atomic
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_io import open_stage, time_range


@dataclass(frozen=True)
class PopulateRequest:
    stage_path: Path
    out_path: Path
    params: CrowdParams = CrowdParams()
    class_map_path: Path | None = None
    allow_external_assets: bool = False


def populate(request: PopulateRequest) -> tuple[Crowd, Path, float]:
    """Read the stage's surfaces at its first time code, populate them, write the agents layer.

    Agents already in the stage (under ``/World/Agents``) are ignored: the new layer is meant to replace
    them. Everything else, parked devices of the twin included, is terrain or obstacle. Returns the crowd,
    the layer written and the seconds it took."""
    t0 = time.perf_counter()
    out = check_layer_path(request.out_path, "the agents layer")
    check_not_inputs([out], {"TWIN_OR_SCENARIO": request.stage_path, "--class-map": request.class_map_path})
    class_map = ClassMap.load_or_bundled(request.class_map_path)
    unknown = [c for c in request.params.walkable if class_map.resolve(c) is None]
    if unknown:
        raise InputError(f"walkable classes {unknown} are not classes of {class_map.source}")
    walkable = tuple(class_map.resolve(c).name for c in request.params.walkable)
    stage = open_stage(request.stage_path, request.allow_external_assets)
    span = time_range(stage)
    start = span[0] if span else 1.0
    fps = stage.GetTimeCodesPerSecond()
    params = CrowdParams(**{**request.params.__dict__, "walkable": walkable, "time_codes_per_second": fps})
    snapshot = StageReader(stage, class_map).snapshot(start)
    meshes = [m for m in snapshot.meshes if not m.prim_path.startswith(AGENTS_ROOT + "/")]
    verts, faces, owner = snapshot.world_triangles(meshes)
    names = np.array([class_map.by_id(m.class_id).name for m in meshes], object)
    _check_walkable_classes(request.stage_path, set(names), walkable)
    crowd = populate_crowd(verts, faces, names[owner] if len(owner) else np.zeros(0, object), params)
    meta = StageMetadata(up_axis="Z", meters_per_unit=1.0, time_codes_per_second=fps, start_time_code=start,
                         end_time_code=start + params.time_codes - 1, default_prim="World")
    layer = build_agents_layer(crowd, meta, class_map.taxonomy)
    save_layer_atomic(layer.GetRootLayer(), out)  # one file: atomic by itself
    return crowd, out, time.perf_counter() - t0


def _check_walkable_classes(stage_path: Path, classes: set[str], walkable: tuple[str, ...]) -> None:
    """Name the real cause when nothing of the stage is walkable: its gprims carry no labels at all (a twin layer
    opened without its semantics layer), or none of the walkable classes."""
    if classes & set(walkable):
        return
    labelled = sorted(classes - {"unlabelled"})
    path = Path(stage_path)
    if not labelled:
        scenario = path.parent / "scenario.usda"
        fix = (f"pass the scenario ({scenario}) or compose its semantics layer over it" if scenario.exists()
               and scenario.resolve() != path.resolve() else
               "compose the twin's semantics layer (semantics.usda, written beside twin.usdc by `synthua twin`) "
               "over it with `synthua compose`, or pass the scenario that does")
        raise InputError(f"{path}: none of its gprims has a 'synthua' label (all are class 0, unlabelled), so "
                         f"nothing is walkable; expected labelled surfaces: {fix}")
    fix = ("add --walk-on road when its roads include their sidewalks (CityJSON often does), or name the classes "
           "people walk on with --walk-on" if "road" in labelled else "name the classes people walk on with --walk-on")
    raise InputError(f"{path}: has none of the walkable classes ({', '.join(walkable)}); its classes are "
                     f"{', '.join(labelled)}; expected one to walk on: {fix}")
