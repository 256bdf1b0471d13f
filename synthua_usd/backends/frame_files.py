"""Writing one rendered frame: every image, and ``frame.json`` describing it, each file atomically.

Files (see the README's "Outputs" section):

=================  ===========================================================================
rgb.exr            scene-linear Rec.709, float32, tagged ``lin_rec709_scene``
rgb.png            display sRGB, 8-bit, through OCIO (``lin_rec709_scene`` → ``srgb_rec709_scene``)
class.png          class ids, 8-bit, one channel, raw
semantic.png       class colours of the class map, 8-bit sRGB
instance.png       instance ids, 16-bit, one channel, raw; 0 = no instance
depth.exr          z-depth in metres along the camera's optical axis, float32, channel Z; 0 = no hit
frame.json         camera, image, render settings, class map, instances with pixel counts
=================  ===========================================================================
"""

from __future__ import annotations

import json
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from synthua_usd.atomic import atomic_path
from synthua_usd.backends import images
from synthua_usd.schemas import validate_document

DEPTH_DEFINITION = ("z-depth: distance in metres from the camera centre along its optical axis "
                    "(not along the ray); 0 where the pixel-centre ray hits nothing")

FILES = ("rgb.exr", "rgb.png", "class.png", "semantic.png", "instance.png", "depth.exr", "frame.json")


def write_json_atomic(path: Path, document: dict) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(document, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    return path


def write_frame(out_dir: Path, *, rgb: np.ndarray, class_ids: np.ndarray, instance_ids: np.ndarray,
                z_depth: np.ndarray, palette: np.ndarray, frame_doc: dict) -> list[Path]:
    """Write all files of a frame into ``out_dir`` (created if needed) on background threads.

    ``frame_doc`` is validated against ``frame.schema.json`` before anything is written.
    """
    validate_document(frame_doc, "frame", "frame.json")
    out_dir.mkdir(parents=True, exist_ok=True)
    jobs = [
        (images.write_linear_exr, out_dir / "rgb.exr", rgb),
        (images.write_display_png, out_dir / "rgb.png", rgb),
        (images.write_id_png, out_dir / "class.png", class_ids),
        (images.write_color_png, out_dir / "semantic.png", palette[class_ids]),
        (images.write_id_png, out_dir / "instance.png", instance_ids),
    ]
    with ThreadPoolExecutor(max_workers=4) as pool:
        futures = [pool.submit(fn, path, data) for fn, path, data in jobs]
        futures.append(pool.submit(images.write_depth_exr, out_dir / "depth.exr", z_depth, DEPTH_DEFINITION))
        written = [f.result() for f in futures]
    # frame.json last: its presence means the frame is complete.
    written.append(write_json_atomic(out_dir / "frame.json", frame_doc))
    return written
