"""Render one frame of a scenario to a folder: the job behind ``synthua render``."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synthua_usd import __version__
from synthua_usd.backends.frame_files import DEPTH_DEFINITION, write_frame
from synthua_usd.backends.mitsuba.render import RenderedFrame, render_frame
from synthua_usd.cameras import PinholeCamera
from synthua_usd.errors import StageError
from synthua_usd.render_config import RenderConfig
from synthua_usd.scene import SceneSnapshot
from synthua_usd.taxonomy import ClassMap
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.render_settings import render_defaults
from synthua_usd.usd.stage_io import check_time_code, open_stage

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class FrameRequest:
    """What to render. Unset camera, size and spp come from the stage's UsdRender settings."""

    stage_path: Path
    out_dir: Path
    camera_path: str | None = None
    frame: float | None = None
    width: int | None = None
    height: int | None = None
    spp: int | None = None
    seed: int = 0
    variant: str | None = None
    class_map_path: Path | None = None


@dataclass(frozen=True, eq=False)
class FrameResult:
    out_dir: Path
    files: list[Path]
    document: dict
    snapshot: SceneSnapshot
    camera: PinholeCamera
    rendered: RenderedFrame


def run_frame(request: FrameRequest, show_progress: bool = False) -> FrameResult:
    """Check every input, render, then write. Nothing is written unless every check passed."""
    class_map = ClassMap.load(request.class_map_path) if request.class_map_path else ClassMap.default()
    stage = open_stage(request.stage_path)
    defaults = render_defaults(stage)
    frame = request.frame if request.frame is not None else stage.GetStartTimeCode()
    check_time_code(stage, frame)
    camera_path = request.camera_path or defaults.camera_path
    if camera_path is None:
        raise StageError(f"{request.stage_path}: no --camera given and no UsdRender settings name one")
    camera = read_camera(stage, camera_path, frame)
    width, height = defaults.resolution or (1280, 960)
    config = RenderConfig(width=request.width or width, height=request.height or height,
                          spp=request.spp or defaults.spp or RenderConfig.spp, seed=request.seed,
                          variant=request.variant)
    snapshot = read_snapshot(stage, frame, class_map)
    rendered = render_frame(snapshot, camera, config, show_progress=show_progress)
    doc = frame_document(request, stage_frame=frame, camera=camera, config=config, snapshot=snapshot,
                         rendered=rendered, class_map=class_map)
    t0 = time.perf_counter()
    files = write_frame(request.out_dir, rgb=rendered.rgb, class_ids=rendered.class_ids,
                        instance_ids=rendered.instance_ids, z_depth=rendered.hits.z_m,
                        palette=class_map.palette(), frame_doc=doc)
    log.info("wrote %d files to %s in %.2f s", len(files), request.out_dir, time.perf_counter() - t0)
    return FrameResult(request.out_dir, files, doc, snapshot, camera, rendered)


def frame_document(request: FrameRequest, *, stage_frame: float, camera: PinholeCamera, config: RenderConfig,
                   snapshot: SceneSnapshot, rendered: RenderedFrame, class_map: ClassMap) -> dict:
    """The content of ``frame.json`` (schema: ``schemas/frame.schema.json``)."""
    w, h = config.width, config.height
    inst_counts = np.bincount(rendered.instance_ids.ravel(), minlength=len(snapshot.instances) + 1)
    class_counts = np.bincount(rendered.class_ids.ravel(), minlength=256)
    hap, vap = camera.conformed_aperture_mm(w, h)
    instances = []
    for inst in snapshot.instances:
        entry = inst.to_dict()
        entry["pixel_count"] = int(inst_counts[inst.id])
        instances.append(entry)
    return {
        "$schema": "frame.schema.json",
        "generator": f"synthua-usd {__version__}",
        "stage": str(request.stage_path),
        "time_code": stage_frame,
        "image": {"width": w, "height": h},
        "camera": {
            "prim_path": camera.path,
            "focal_length_mm": camera.focal_length_mm,
            "horizontal_aperture_mm": camera.horizontal_aperture_mm,
            "vertical_aperture_mm": camera.vertical_aperture_mm,
            "conformed_aperture_mm": [hap, vap],
            "aspect_ratio_conform_policy": "expandAperture",
            "fov_deg": list(camera.fov_deg(w, h)),
            "clipping_range_m": [camera.clip_near_m, camera.clip_far_m],
            "K": camera.intrinsics(w, h).tolist(),
            "camera_to_world": camera.camera_to_world.tolist(),
            "world_to_camera_opencv": camera.world_to_camera_opencv().tolist(),
            "conventions": "camera_to_world: column vectors, camera looks down -Z with +Y up (USD); "
                           "world_to_camera_opencv and K: x right, y down, z forward, pixel centres at +0.5",
        },
        "render": {"renderer": "mitsuba", "variant": rendered.variant, "spp": config.spp,
                   "max_depth": config.max_depth, "pixel_filter": config.pixel_filter, "seed": config.seed,
                   "labels": "one ray through each pixel centre", "seconds": rendered.seconds},
        "files": {
            "rgb_exr": {"path": "rgb.exr", "colorspace": "lin_rec709_scene"},
            "rgb_png": {"path": "rgb.png", "colorspace": "srgb_rec709_scene"},
            "class": {"path": "class.png", "dtype": "uint8", "meaning": "class id (class_map), 0 = unlabelled"},
            "semantic": {"path": "semantic.png", "colorspace": "srgb_rec709_scene", "meaning": "class colour"},
            "instance": {"path": "instance.png", "dtype": "uint16", "meaning": "instance id (instances), 0 = none"},
            "depth": {"path": "depth.exr", "dtype": "float32", "channel": "Z", "kind": "z",
                      "meaning": DEPTH_DEFINITION},
        },
        "class_map": {"source": class_map.source, "taxonomy": class_map.taxonomy,
                      "classes": [c.to_dict() for c in class_map.classes]},
        "class_pixel_counts": {class_map.by_id(i).name: int(n) for i, n in enumerate(class_counts) if n},
        "instances": instances,
    }
