"""Place camera rigs in a scenario, aim them at targets, and report what each camera sees: the job behind
``synthua cameras author``.

1. Targets (:mod:`synthua_usd.usd.targets`) and candidate placements (:mod:`synthua_usd.geometry.placement`) come from
   the stage. 2. Every candidate is scored by its target's visible pixels in the label pass, at a quarter of
   the image size, at three of the report's time codes (the first, middle and last); the smallest count
   decides, and each rig keeps its ``count`` best targets. 3. The chosen cameras are rendered (labels only,
   one exact ray per pixel centre) at every report time code and full size, twice: in the whole scene
   (*visible* pixels of the target) and in a scene holding only the target (*alone*: the pixels it would
   cover with everything else removed). ``occluded = 1 - visible / alone``. 4. A camera whose target
   covers fewer than ``min_target_px`` visible pixels at any report time code is rejected: reported, not
   written. 5. The layer (accepted cameras) and the JSON report beside it are written as a pair: each
   through a temporary file, both renamed only once both are complete.
"""

from __future__ import annotations

import logging
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synthua_usd import __version__
from synthua_usd.agents.walkable import WALKABLE
from synthua_usd.composition.rigs import RigSpec
from synthua_usd.core import json_text
from synthua_usd.core.atomic import atomic_path
from synthua_usd.core.errors import InputError, StageError, echo
from synthua_usd.core.input_guard import check_not_inputs
from synthua_usd.core.resources import check_frame_memory
from synthua_usd.core.schemas import validate_document
from synthua_usd.geometry.placement import (DEFAULT_DISTANCE_M, Placement, Terrain, dashcam_candidates, fixed_candidates,
                                   riding_placement)
from synthua_usd.geometry.roads import ROAD_CLASSES
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.scene import SceneSnapshot
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline.target_pixels import CandidateGroup, evaluate, prefilter, score
from synthua_usd.usd import targets as usd_targets
from synthua_usd.usd.agents_writer import AGENTS_ROOT
from synthua_usd.usd.authoring import check_layer_path, export_layer
from synthua_usd.usd.cameras import camera_paths
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.rig_layer import PlacedRig, build_rig_layer
from synthua_usd.usd.stage_io import check_time_code, open_stage, stage_metadata

log = logging.getLogger(__name__)

#: Report time codes when none are asked for: this many, evenly spread, first and last included.
DEFAULT_REPORT_TIME_CODES = 7
#: Targets tried per rig beyond its ``count`` (the best-scoring ones are kept).
EXTRA_TARGETS = 2
#: Riders tried per riding rig and target (the nearest ones that have the target ahead).
MAX_RIDERS = 16


@dataclass(frozen=True)
class RigRequest:
    """Rigs to place in ``stage_path`` and the layer to write (``out_path``; the report goes beside it as
    ``<stem>.report.json``). Pixel counts are for a ``width`` x ``height`` image at ``time_codes`` (default:
    DEFAULT_REPORT_TIME_CODES over the stage's range)."""

    stage_path: Path
    out_path: Path
    rigs: tuple[RigSpec, ...]
    width: int = RenderConfig.width
    height: int = RenderConfig.height
    time_codes: tuple[float, ...] = ()
    min_target_px: int = 1
    variant: str | None = None
    class_map_path: Path | None = None
    allow_external_assets: bool = False
    #: Layer files composed over the stage for the placement (strongest first; see ``open_stage``), e.g. the
    #: agents layer of a twin scenario that does not compose it yet.
    layers: tuple[Path, ...] = ()

    @property
    def report_path(self) -> Path:
        return self.out_path.with_name(self.out_path.stem + ".report.json")


@dataclass(frozen=True, eq=False)
class RigsResult:
    """What :func:`author_rigs` wrote: the report (as written), both paths, and how many cameras were written
    and rejected."""

    report: dict
    layer_path: Path
    report_path: Path
    accepted: int
    rejected: int


def author_rigs(request: RigRequest, show_progress: bool = False) -> RigsResult:
    """Place, score, verify and write every rig of ``request`` (see the module docstring)."""
    _check_request(request)
    class_map = ClassMap.load_or_bundled(request.class_map_path)
    stage = open_stage(request.stage_path, request.allow_external_assets, request.layers)
    # the rigs layer states the stage's metadata
    meta = stage_metadata(stage)
    if meta.up_axis != "Z":
        raise StageError(f"{request.stage_path}: upAxis is {meta.up_axis!r}; camera rigs expect a Z-up stage "
                         f"(heights are along +Z)")
    start, end = meta.start_time_code, meta.end_time_code
    report_tcs = list(request.time_codes) or default_time_codes(start, end)
    for tc in report_tcs:
        check_time_code(stage, tc)
    all_tcs = sorted({float(t) for t in np.arange(math.ceil(start), math.floor(end) + 1)} | set(report_tcs))
    check_frame_memory(request.width, request.height)
    reader = StageReader(stage, class_map)
    first = reader.snapshot(report_tcs[0])
    if not first.meshes:
        raise StageError(f"{request.stage_path}: has no renderable geometry; expected a twin to place cameras in")
    terrain = _terrain(first, class_map, str(request.stage_path))
    tracks = usd_targets.agents(stage, reader.instances, all_tcs)
    names = _names(request.rigs, {p.rsplit("/", 1)[-1] for p in camera_paths(stage)})
    fps = meta.time_codes_per_second
    groups = []
    for k, spec in enumerate(request.rigs):
        source = f"rig {k + 1} ({spec.type})"
        found = usd_targets.find_targets(stage, spec.aim, reader.instances, tracks, report_tcs, source)
        groups += _candidates(k, spec, found[:spec.count + EXTRA_TARGETS], terrain, tracks, all_tcs, report_tcs, fps,
                              request, source)
    config = RenderConfig(width=request.width, height=request.height, spp=1, variant=request.variant)
    prefilter(groups, terrain, report_tcs[len(report_tcs) // 2])
    score(groups, reader, request.rigs, config, report_tcs, show_progress)
    chosen = _choose(groups, request.rigs, names)
    evaluated = evaluate(chosen, reader, config, report_tcs, tracks, show_progress)
    rows, placed = [], []
    for (rig, target), frames in evaluated:
        entry = _camera_entry(rig, target, frames, request.min_target_px, terrain, report_tcs)
        rows.append(entry)
        if entry["status"] == "written":
            placed.append(rig)
    layer = build_rig_layer(meta, placed, f"Camera rigs placed by synthua cameras author on {request.stage_path.name}; "
                                          f"report: {request.report_path.name}.")
    report = {
        "$schema": "camera_rigs_report.schema.json",
        "generator": f"synthua-usd {__version__}",
        # Relative to the layer's folder: the pair stays right when the folder moves (or is staged).
        "stage": os.path.relpath(Path(request.stage_path).resolve(), Path(request.out_path).resolve().parent),
        "layer": Path(request.out_path).name,
        **({"layers": [os.path.relpath(Path(p).resolve(), Path(request.out_path).resolve().parent)
                       for p in request.layers]} if request.layers else {}),
        "image": {"width": request.width, "height": request.height},
        "time_codes": report_tcs,
        "min_target_px": request.min_target_px,
        "method": "labels: one ray per pixel centre (Mitsuba ray_intersect_preliminary); target_px: pixels of the "
                  "target's instances in the full scene; alone_px: its pixels with everything else removed; "
                  "occluded_fraction = 1 - target_px / alone_px",
        "cameras": rows,
    }
    validate_document(report, "camera_rigs_report", str(request.report_path))
    _write_pair(layer, request.out_path, report, request.report_path)
    accepted = sum(r["status"] == "written" for r in rows)
    return RigsResult(report, request.out_path, request.report_path, accepted, len(rows) - accepted)


def default_time_codes(start: float, end: float, n: int = DEFAULT_REPORT_TIME_CODES) -> list[float]:
    """``n`` integral time codes evenly spread over [start, end], both included (fewer on short ranges)."""
    return sorted({float(round(t)) for t in np.linspace(start, end, n)} & {float(t) for t in
                  np.arange(math.ceil(start), math.floor(end) + 1)} or {float(start)})


def _check_request(request: RigRequest) -> None:
    out = check_layer_path(request.out_path, "the cameras layer")
    check_not_inputs([out, request.report_path], {"SCENARIO": request.stage_path, "--layer": request.layers,
                                                  "--class-map": request.class_map_path})
    if not request.rigs:
        raise InputError("no --rig given; expected at least one (e.g. --rig cctv:aim=aid_user)")
    if not (isinstance(request.min_target_px, int) and request.min_target_px >= 0):
        raise InputError(f"min_target_px = {request.min_target_px!r}; expected an integer >= 0")
    for k, spec in enumerate(request.rigs):
        spec.check_lens(request.width, request.height, f"rig {k + 1} ({spec.type})")


def _terrain(snapshot: SceneSnapshot, class_map: ClassMap, source: str) -> Terrain:
    meshes = [m for m in snapshot.meshes if not m.prim_path.startswith(AGENTS_ROOT + "/")]
    verts, faces, owner = snapshot.world_triangles(meshes)
    names = np.array([class_map.by_id(m.class_id).name for m in meshes], object)
    return Terrain(verts, faces, names[owner] if len(owner) else np.zeros(0, object), source)


def _names(rigs: tuple[RigSpec, ...], taken: set[str]) -> list[list[str]]:
    """Camera names per rig: ``name`` (``name_<k>`` for count > 1) or ``<Prefix>_<Aim>_<k>``; a given name
    that the scenario already has is refused, default names skip taken ones."""
    out, used = [], set(taken)
    for spec in rigs:
        names = []
        if spec.name:
            names = [spec.name] if spec.count == 1 else [f"{spec.name}_{k + 1}" for k in range(spec.count)]
            clash = [n for n in names if n in used]
            if clash:
                raise InputError(f"rig name {clash[0]!r}: the scenario or another rig already has a camera of that "
                                 f"name; expected a new name")
        else:
            base = "_".join(filter(None, (spec.kind.prefix, spec.aim_label())))
            k = 1
            while len(names) < spec.count:
                if f"{base}_{k}" not in used:
                    names.append(f"{base}_{k}")
                k += 1
        used.update(names)
        out.append(names)
    return out


def _candidates(k: int, spec: RigSpec, found: list, terrain: Terrain, tracks: list, all_tcs: list[float],
                report_tcs: list[float], fps: float, request: RigRequest, source: str) -> list[CandidateGroup]:
    w, h = request.width, request.height
    if spec.type == "dashcam":
        drives = dashcam_candidates(spec, terrain, all_tcs, fps, aimed=bool(found))
        return [CandidateGroup(k, t, drives) for t in found] or [CandidateGroup(k, None, drives)]
    if spec.ride is not None:
        riders = _riders(spec, tracks, source)
        if not found:
            return [CandidateGroup(k, None, [riding_placement(spec, riders[0], all_tcs)])]
        mid = report_tcs[len(report_tcs) // 2]
        groups = [CandidateGroup(k, t, [riding_placement(spec, r, all_tcs) for r in _ahead(riders, t, mid)])
                  for t in found]
        if not any(g.candidates for g in groups):
            raise InputError(f"{source}: the only agents to ride with are its targets; expected another "
                             f"{'wheelchair user' if spec.type == 'wheelchair_eye' else 'agent on foot'} to ride with")
        return [g for g in groups if g.candidates]
    if not found:
        cells = terrain.cells(WALKABLE)
        anchor = cells.mean(axis=0) if len(cells) else terrain.vertices.mean(axis=0)
        placements = fixed_candidates(spec, terrain, anchor, None, w, h)
        if not placements:
            raise InputError(f"{source}: found no place to stand near the centre of the walkable area; expected "
                             f"sidewalks or squares (or give aim=...)")
        return [CandidateGroup(k, None, placements[:1])]
    groups = [CandidateGroup(k, t, fixed_candidates(spec, terrain, t.anchor(), t.corners(), w, h)) for t in found]
    if not any(g.candidates for g in groups):
        reach = spec.distance_m or DEFAULT_DISTANCE_M.get(spec.type)
        raise InputError(f"{source}: found no place for a {spec.type} around its targets (mount {spec.mount}"
                         + (f", within {reach:g} m" if reach else "") + "); expected sidewalks, squares or façades "
                         "nearby (or a larger distance_m)")
    return [g for g in groups if g.candidates]


def _riders(spec: RigSpec, tracks: list, source: str) -> list:
    seated = spec.type == "wheelchair_eye"
    if spec.ride.startswith("/"):
        rider = next((a for a in tracks if a.prim_path == spec.ride), None)
        if rider is None:
            raise InputError(f"{source}: ride = {echo(spec.ride)}: no agent at that path; expected an agent of the "
                             f"agents layer ({AGENTS_ROOT}/Agent_NNNN)")
        if rider.seated != seated:
            raise InputError(f"{source}: ride = {spec.ride} is a {rider.profile}; a {spec.type} rig rides with "
                             f"{'a seated (wheelchair) agent' if seated else 'an agent on foot'}")
        return [rider]
    riders = [a for a in tracks if a.seated == seated]
    if not riders:
        raise InputError(f"{source}: the scenario has no {'wheelchair users' if seated else 'agents on foot'} to ride "
                         f"with; expected an agents layer with them (`synthua agents populate`)")
    return riders


def _ahead(riders: list, target, time_code: float) -> list:
    """The riders (not the target itself) nearest the target that have it within 60 degrees of their
    heading at ``time_code``; the nearest few whatever their heading when none has."""
    goal = target.anchor()
    scored = []
    for r in riders:
        if r.prim_path == target.prim_path:
            continue
        m = r.transforms[time_code]
        to = goal[:2] - m[:2, 3]
        dist = float(np.linalg.norm(to))
        cos = float(m[:2, 0] @ to) / max(dist * float(np.linalg.norm(m[:2, 0])), 1e-9)
        scored.append((cos < 0.5, dist, r.prim_path, r))
    scored.sort(key=lambda s: s[:3])
    ahead = [s[3] for s in scored if not s[0]][:MAX_RIDERS]
    return ahead or [s[3] for s in scored[:4]]


def _choose(groups: list[CandidateGroup], rigs: tuple[RigSpec, ...], names: list[list[str]]) -> list[tuple]:
    """Per rig, its ``count`` best targets (by their best candidate's score) with their best candidates, as
    (PlacedRig, Target or None) pairs."""
    out = []
    for k, spec in enumerate(rigs):
        mine = [g for g in groups if g.rig == k]
        ranked = sorted(mine, key=lambda g: -(g.best()[1] if not math.isnan(g.best()[1]) else -1.0))
        for name, g in zip(names[k], ranked[:spec.count]):
            out.append((PlacedRig(name, spec, g.best()[0], g.target.prim_path if g.target else None), g.target))
        for name in names[k][len(ranked):]:
            log.warning("rig %d (%s): only %d target(s) to aim at; camera %s not placed", k + 1, spec.type,
                        len(ranked), name)
    return out


def _camera_entry(rig: PlacedRig, target, frames: list[dict], min_px: int, terrain: Terrain,
                  report_tcs: list[float]) -> dict:
    spec, place = rig.spec, rig.placement
    h_ap, v_ap = spec.apertures_mm
    entry = {"name": rig.name, "prim_path": rig.prim_path, "rig": spec.type, "height_m": spec.height_m,
             "where": place.where, "focal_length_mm": round(place.focal_length_mm, 4),
             "horizontal_aperture_mm": h_ap, "vertical_aperture_mm": v_ap,
             "distortion": None if spec.distortion.is_zero else spec.distortion.to_dict(),
             "moving": place.track is not None, "rides_with": place.rides_with,
             "target": target.to_dict() if target is not None else None, "frames": frames,
             "status": "written", "reason": None}
    if spec.type == "dashcam":
        entry["on_road"] = _on_road(place, terrain, report_tcs)
    if target is not None:
        worst = min(frames, key=lambda f: f["target_px"])
        entry["min_target_px"] = worst["target_px"]
        if worst["target_px"] < min_px:
            entry.update(status="rejected", reason=f"the target covers {worst['target_px']} visible pixels at time "
                                                   f"code {worst['time_code']:g}, fewer than --min-target-px {min_px}")
    return entry


def _on_road(place: Placement, terrain: Terrain, time_codes: list[float]) -> bool:
    """Whether a ray cast straight down from the camera hits a road surface first at every time code."""
    origins = np.array([place.camera_to_world(t)[:3, 3] for t in time_codes])
    tri = terrain.mesh.ray.intersects_first(origins, np.tile([0.0, 0.0, -1.0], (len(origins), 1)))
    return bool(np.all(tri >= 0) and np.isin(terrain.face_class[tri], ROAD_CLASSES).all())


def _write_pair(layer, layer_path: Path, report: dict, report_path: Path) -> None:
    """Both files through temporary files beside them, renamed only when both are complete."""
    layer_path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(report_path) as tmp_report, atomic_path(layer_path) as tmp_layer:
        export_layer(layer.GetRootLayer(), tmp_layer, layer_path)
        tmp_report.write_text(json_text.dumps(report, indent=2) + "\n", encoding="utf-8")
