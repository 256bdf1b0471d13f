"""Render frames of a scenario to a folder: the job behind ``synthua render``.

Several (camera, time code) pairs render from one :class:`RenderSession` (one scene load). One frame
writes its files straight into the output folder; several write ``<camera name>/<time code>/`` below it.
A frame's files are written on a background thread while the next frame renders
(:class:`synthua_usd.pipeline.background.BackgroundWriter`, bounded: one frame waits at most). All frames are
written into a staging folder and moved into place together, so a failed run (a failed write included)
leaves the output folder as it was.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from synthua_usd import __version__
from synthua_usd.backends.frame_files import write_frame
from synthua_usd.backends.mitsuba.render import RenderedFrame
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.core.atomic import output_set
from synthua_usd.core.errors import InputError, StageError, echo
from synthua_usd.core.outputs import OUTPUT_NAMES, RenderOutput, select_outputs
from synthua_usd.core.resources import check_frame_memory
from synthua_usd.dataset.record import record_camera, record_render
from synthua_usd.model.cameras import CONFORM_EXPAND, PinholeCamera
from synthua_usd.model.render_config import RenderConfig, resolve_render
from synthua_usd.model.scene import SceneSnapshot
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline.background import BackgroundWriter
from synthua_usd.usd.cameras import author_auto_camera, read_camera
from synthua_usd.usd.conditions import read_condition
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.render_settings import render_defaults
from synthua_usd.usd.stage_io import check_time_code, open_stage

log = logging.getLogger(__name__)

#: Frames one ``synthua render`` call may hold (each is a folder of files).
MAX_FRAMES = 10_000


#: ``--camera auto``: a camera framing the stage, authored into its session layer
#: (:func:`synthua_usd.usd.cameras.author_auto_camera`).
AUTO_CAMERA = "auto"


@dataclass(frozen=True)
class FrameRequest:
    """What to render: every camera at every time code. Empty ``camera_paths`` take the render settings'
    camera; empty ``time_codes`` the stage's start time code; unset render settings (None) come from the
    stage's UsdRender settings, else from :class:`RenderConfig`'s defaults (:func:`resolve_render`)."""

    stage_path: Path
    out_dir: Path
    camera_paths: tuple[str, ...] = ()
    time_codes: tuple[float, ...] = ()
    width: int | None = None
    height: int | None = None
    spp: int | None = None
    seed: int = 0
    variant: str | None = None
    class_map_path: Path | None = None
    allow_external_assets: bool = False
    #: Keep every frame's buffers in the result (tests); by default only a single frame's are kept, so a
    #: long sweep holds documents and paths, not images, in memory.
    keep_buffers: bool | None = None
    #: A condition the stage offers (its ``condition`` variant); None: the stage's own selection.
    condition: str | None = None
    #: Denoise RGB (:attr:`RenderConfig.denoise`); None: the default.
    denoise: bool | None = None
    #: Path length (:attr:`RenderConfig.max_depth`); None: the default.
    max_depth: int | None = None
    #: Layer files composed over the stage through its session layer, strongest first (a randomisation layer).
    layers: tuple[Path, ...] = ()

    def render_values(self) -> dict:
        """The request's render settings as :func:`resolve_render`'s ``options`` source (None: unset)."""
        return {"width": self.width, "height": self.height, "spp": self.spp, "seed": self.seed,
                "variant": self.variant, "denoise": self.denoise, "max_depth": self.max_depth}


@dataclass(frozen=True, eq=False)
class FrameResult:
    """One rendered frame: where it went, its ``frame.json`` document, and (see
    :attr:`FrameRequest.keep_buffers`) its snapshot and buffers, else None."""

    out_dir: Path
    files: list[Path]
    document: dict
    snapshot: SceneSnapshot | None
    camera: PinholeCamera
    rendered: RenderedFrame | None


@dataclass(eq=False)
class RenderRun:
    """Every frame of one request, and the session's counters (loads, reloads)."""

    frames: list[FrameResult] = field(default_factory=list)
    loads: int = 0
    reloads: int = 0


def time_code_folder(time_code: float) -> str:
    """``0024`` for time code 24, ``0024.500`` for 24.5: folder names that sort in time order."""
    return f"{int(time_code):04d}" if float(time_code).is_integer() else f"{time_code:08.3f}"


def run_frames(request: FrameRequest, show_progress: bool = False) -> RenderRun:
    """Check every input, render every frame from one session, then move all files into place together."""
    class_map = ClassMap.load_or_bundled(request.class_map_path)
    stage = open_stage(request.stage_path, request.allow_external_assets, request.layers)
    defaults = render_defaults(stage)
    unknown = [n for n in defaults.var_names if n not in OUTPUT_NAMES]
    if unknown:
        log.warning("render vars %s are not outputs synthua writes (known: %s); ignoring them",
                    unknown, ", ".join(OUTPUT_NAMES))
    outputs = select_outputs([n for n in defaults.var_names if n in OUTPUT_NAMES])
    time_codes = request.time_codes or (stage.GetStartTimeCode(),)
    for tc in time_codes:
        check_time_code(stage, tc)
    camera_paths = request.camera_paths or ((defaults.camera_path,) if defaults.camera_path else ())
    if not camera_paths:
        raise StageError(f"{request.stage_path}: no --camera given and no UsdRender settings name one; expected "
                         f"--camera PATH, or --camera auto for a camera framing the stage")
    if AUTO_CAMERA in camera_paths:
        auto = author_auto_camera(stage, time_codes[0])
        camera_paths = tuple(auto if c == AUTO_CAMERA else c for c in camera_paths)
    frames = [(cam, tc) for cam in camera_paths for tc in time_codes]
    if len(frames) > MAX_FRAMES:
        raise InputError(f"{len(frames)} frames requested ({len(camera_paths)} cameras x {len(time_codes)} time "
                         f"codes); one render call holds at most {MAX_FRAMES}")
    for cam in camera_paths:  # every camera is checked before anything renders
        read_camera(stage, cam, time_codes[0])
    folders: dict[str, str] = {}
    for cam in dict.fromkeys(camera_paths):  # frame folders are named by the camera's prim name
        other = folders.setdefault(cam.rsplit("/", 1)[-1], cam)
        if other != cam and len(frames) > 1:
            raise InputError(f"--camera {echo(other)} and {echo(cam)}: both would write frames into "
                             f"'{cam.rsplit('/', 1)[-1]}/'; expected cameras with different prim names")
    config = resolve_render(stage=defaults.render_values(), options=request.render_values())
    condition = read_condition(stage, request.condition)
    reader = StageReader(stage, class_map)
    if not reader.snapshot(time_codes[0]).meshes:
        raise StageError(f"{request.stage_path}: has no renderable geometry (no visible Mesh, Cube, Sphere, Cylinder, "
                         f"Cone or Capsule); expected a twin to render")
    check_frame_memory(config.width, config.height)
    session = RenderSession(config)
    run = RenderRun()
    single = len(frames) == 1
    want_rgb = any(o.var == "rgb" for o in outputs)
    keep = request.keep_buffers if request.keep_buffers is not None else single
    # Frame N's files are written on a background thread while frame N+1 renders; at most one frame waits.
    inputs = {"SCENARIO": request.stage_path, "--layer": request.layers, "--class-map": request.class_map_path}
    with output_set(request.out_dir, inputs=inputs) as staging, BackgroundWriter(max_pending=1) as writer:
        bar = tqdm(frames, unit="frame", desc="render", disable=not show_progress or single)
        for cam_path, tc in bar:
            snapshot = reader.snapshot(tc)
            camera = read_camera(stage, cam_path, tc)
            rendered = session.render(snapshot, camera, rgb=want_rgb, show_progress=show_progress and single,
                                      condition=condition)
            rel = Path() if single else Path(cam_path.rsplit("/", 1)[-1]) / time_code_folder(tc)
            doc = frame_document(request.stage_path, outputs, time_code=tc, camera=camera, config=config,
                                 snapshot=snapshot, rendered=rendered, class_map=class_map)
            run.frames += writer.submit(_write_frame, writer, staging, rel, request.out_dir, outputs, doc,
                                        snapshot if keep else None, camera, rendered, class_map, keep)
        run.frames += writer.drain()
    run.loads, run.reloads = session.loads, session.reloads
    return run


def _write_frame(writer: BackgroundWriter, staging: Path, rel: Path, out_dir: Path, outputs, doc: dict, snapshot,
                 camera: PinholeCamera, rendered: RenderedFrame, class_map: ClassMap, keep: bool) -> FrameResult:
    """Write one frame's files into ``staging / rel`` (on the writer's thread); its :class:`FrameResult`."""
    t0 = time.perf_counter()
    written = write_frame(staging / rel, outputs, rgb=rendered.rgb, class_ids=rendered.class_ids,
                          instance_ids=rendered.instance_ids, z_depth=rendered.hits.z_m, palette=class_map.palette(),
                          frame_doc=doc, display_scale=rendered.exposure.scale if rendered.exposure else 1.0,
                          encoders=writer.encoders)
    log.info("wrote %d files for %s at %g in %.2f s", len(written), camera.path, doc["time_code"],
             time.perf_counter() - t0)
    return FrameResult(out_dir / rel, [out_dir / rel / p.name for p in written], doc, snapshot, camera,
                       rendered if keep else None)


def frame_document(stage_path: Path, outputs: tuple[RenderOutput, ...], *, time_code: float, camera: PinholeCamera,
                   config: RenderConfig, snapshot: SceneSnapshot, rendered: RenderedFrame, class_map: ClassMap) -> dict:
    """The content of ``frame.json`` (schema: ``schemas/frame.schema.json``)."""
    w, h = config.width, config.height
    inst_counts = np.bincount(rendered.instance_ids.ravel(), minlength=len(snapshot.instances) + 1)
    class_counts = np.bincount(rendered.class_ids.ravel(), minlength=256)
    hap, vap = camera.conformed_aperture_mm(w, h)
    view = record_camera(camera, (w, h), (w, h), name=camera.path.rsplit("/", 1)[-1], rig_type=None)
    instances = []
    for inst in snapshot.instances:
        entry = inst.to_dict()
        entry["pixel_count"] = int(inst_counts[inst.id])
        instances.append(entry)
    document = {
        "$schema": "frame.schema.json",
        "generator": f"synthua-usd {__version__}",
        "stage": str(stage_path),
        "time_code": time_code,
        "image": {"width": w, "height": h},
        # a record's camera and render blocks (the same builders), with what only frame.json says
        "camera": {
            **{k: v for k, v in view.items() if k not in ("name", "rig_type", "distortion")},
            "conformed_aperture_mm": [hap, vap],
            "aspect_ratio_conform_policy": CONFORM_EXPAND,
            "fov_deg": list(camera.fov_deg(w, h)),
            "conventions": "camera_to_world: column vectors, camera looks down -Z with +Y up (USD); "
                           "world_to_camera_opencv and K: x right, y down, z forward, pixel centres at +0.5",
        },
        "render": {"renderer": "mitsuba", **record_render(config, rendered.variant, rendered.denoised),
                   "seed": config.seed, "labels": "one ray through each pixel centre", "seconds": rendered.seconds},
        "files": {f.key: f.document() for o in outputs for f in o.files},
        "class_map": {"source": class_map.source, "taxonomy": class_map.taxonomy,
                      "classes": [c.to_dict() for c in class_map.classes]},
        "class_pixel_counts": {class_map.by_id(i).name: int(n) for i, n in enumerate(class_counts) if n},
        "instances": instances,
        "condition": rendered.condition.to_dict() if rendered.condition is not None else None,
        "exposure": rendered.exposure.to_dict() if rendered.exposure is not None else None,
    }
    if view["distortion"] is not None:  # K is the ideal pinhole's; pixels went through this lens model
        document["camera"]["distortion"] = view["distortion"]
    return document
