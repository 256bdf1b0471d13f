"""A contact sheet: one time code of a scenario under every condition it offers, from each of its cameras,
RGB beside the class overlay, in one PNG (the job behind ``synthua contact-sheet``).

Every cell renders from one :class:`RenderSession`. Conditions are visited grouped by what they build
into the scene (sun up or down, wetness, snow: :func:`weather_scene.scene_key`) so the session reloads
only when that changes; the sheet still lists them in display order. The labels of each camera are
checked to be byte-identical under every condition.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from synthua_usd.backends.contact_sheet import class_overlay, compose, write_sheet
from synthua_usd.core.images import linear_to_display
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.backends.mitsuba.weather_scene import scene_key
from synthua_usd.core.errors import InputError, StageError
from synthua_usd.core.input_guard import check_not_inputs
from synthua_usd.core.resources import check_frame_memory
from synthua_usd.model.conditions import display_order
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.usd.cameras import camera_paths, read_camera
from synthua_usd.usd.conditions import check_condition_name, condition_names, read_condition
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_io import check_time_code, open_stage

log = logging.getLogger(__name__)

#: Cells one sheet may hold (cameras x conditions).
MAX_CELLS = 400


@dataclass(frozen=True)
class SheetRequest:
    """What to put on the sheet. Empty ``camera_paths`` take every camera of the stage, empty
    ``conditions`` every condition it offers; ``time_code`` None the stage's start time code. ``width``,
    ``height`` and ``spp`` are per cell."""

    stage_path: Path
    out_path: Path
    time_code: float | None = None
    camera_paths: tuple[str, ...] = ()
    conditions: tuple[str, ...] = ()
    width: int = 320
    height: int = 240
    spp: int = 16
    seed: int = 0
    variant: str | None = None
    class_map_path: Path | None = None
    allow_external_assets: bool = False


@dataclass(eq=False)
class SheetRun:
    """The written sheet, its grid, seconds per cell ``(camera, condition) -> seconds`` and the session's
    loads and reloads."""

    path: Path
    cameras: list[str]
    conditions: list[str]
    seconds: dict = field(default_factory=dict)
    loads: int = 0
    reloads: int = 0


def make_contact_sheet(request: SheetRequest, show_progress: bool = False) -> SheetRun:
    """Check every input, render every cell, compose and write the sheet (one PNG, written atomically)."""
    if request.out_path.suffix.lower() != ".png":
        raise InputError(f"{request.out_path}: the contact sheet is a PNG; expected a file name ending in .png")
    check_not_inputs([request.out_path], {"SCENARIO": request.stage_path, "--class-map": request.class_map_path})
    class_map = ClassMap.load_or_bundled(request.class_map_path)
    stage = open_stage(request.stage_path, request.allow_external_assets)
    time_code = stage.GetStartTimeCode() if request.time_code is None else request.time_code
    check_time_code(stage, time_code)
    names = list(request.conditions) or display_order(condition_names(stage))
    if not names:
        check_condition_name(stage, "")  # the stage offers none: raises the one message that says so
    conditions = [read_condition(stage, name) for name in names]
    cameras = list(request.camera_paths) or camera_paths(stage)
    if not cameras:
        raise StageError(f"{request.stage_path}: has no cameras; expected at least one UsdGeom.Camera")
    if len(cameras) * len(conditions) > MAX_CELLS:
        raise InputError(f"{len(cameras)} cameras x {len(conditions)} conditions: a sheet holds at most "
                         f"{MAX_CELLS} cells")
    lenses = {path: read_camera(stage, path, time_code) for path in cameras}
    config = RenderConfig(width=request.width, height=request.height, spp=request.spp, seed=request.seed,
                          variant=request.variant)
    check_frame_memory(config.width * 2 * len(conditions) + 400, config.height * len(cameras) + 100)
    snapshot = StageReader(stage, class_map).snapshot(time_code)
    if not snapshot.meshes:
        raise StageError(f"{request.stage_path}: has no renderable geometry; expected a twin to render")
    session = RenderSession(config)
    palette = class_map.palette()
    run = SheetRun(path=request.out_path, cameras=cameras, conditions=names)
    # Render order: conditions grouped by what a reload would change; cell positions keep display order.
    order = sorted(range(len(conditions)), key=lambda i: (scene_key(conditions[i]), i))
    labels: dict[str, bytes] = {}
    cells = {}
    jobs = [(col, row) for col in order for row in range(len(cameras))]
    for col, row in tqdm(jobs, unit="cell", desc="contact sheet", disable=not show_progress):
        t0 = time.perf_counter()
        frame = session.render(snapshot, lenses[cameras[row]], condition=conditions[col])
        key = frame.class_ids.tobytes() + frame.instance_ids.tobytes()
        if labels.setdefault(cameras[row], key) != key:
            raise RuntimeError(f"labels of {cameras[row]} changed under condition {names[col]}; they must not")
        rgb8 = linear_to_display(frame.rgb * np.float32(frame.exposure.scale))
        cells[(row, col)] = (rgb8, class_overlay(rgb8, frame.class_ids, palette))
        run.seconds[(cameras[row], names[col])] = time.perf_counter() - t0
    title = (f"{request.stage_path.name}  time code {time_code:g}  {config.width}x{config.height}  {config.spp} spp  "
             f"{session.variant}  (labels identical under every condition)")
    write_sheet(request.out_path, compose(cells, [c.rsplit("/", 1)[-1] for c in cameras], names, title))
    run.loads, run.reloads = session.loads, session.reloads
    return run
