"""Writing one rendered frame: the files of its outputs (:mod:`synthua_usd.core.outputs`) and ``frame.json``.

Image files are encoded in parallel on a small thread pool (OpenImageIO releases the GIL while it
encodes): the caller's (a :class:`synthua_usd.pipeline.background.BackgroundWriter`'s encoders, when frames are
written while the next one renders) or one made for the call; :func:`write_frame` returns when every file is
written. Each file is written atomically; the caller writes a whole command's frames into a staging folder
(:func:`synthua_usd.core.atomic.output_set`).
"""

from __future__ import annotations

from concurrent.futures import Executor, ThreadPoolExecutor
from pathlib import Path

import numpy as np

from synthua_usd.backends import previews
from synthua_usd.core import images
from synthua_usd.core.atomic import write_json_atomic
from synthua_usd.core.outputs import DEPTH_DEFINITION, FRAME_DOCUMENT, RenderOutput
from synthua_usd.core.schemas import validate_document


def _jobs(output: RenderOutput, out_dir: Path, *, rgb, class_ids, instance_ids, z_depth, palette, display_scale):
    """(writer, path, data) for every file of ``output``."""
    path = {f.key: out_dir / f.name for f in output.files}
    if output.var == "rgb":
        return [(images.write_linear_exr, path["rgb_exr"], rgb),
                (images.write_display_png, path["rgb_png"], rgb * np.float32(display_scale))]
    if output.var == "class_id":
        return [(images.write_id_png, path["class"], class_ids),
                (images.write_color_png, path["semantic"], palette[class_ids])]
    if output.var == "instance_id":
        return [(images.write_id_png, path["instance"], instance_ids),
                (images.write_color_png, path["instance_preview"], previews.instance_preview(instance_ids))]
    if output.var == "depth":
        return [(lambda path, data: images.write_depth_exr(path, data, DEPTH_DEFINITION), path["depth"], z_depth)]
    raise ValueError(f"output '{output.var}' has no writer")


def write_frame(out_dir: Path, outputs: tuple[RenderOutput, ...], *, rgb: np.ndarray | None, class_ids: np.ndarray,
                instance_ids: np.ndarray, z_depth: np.ndarray, palette: np.ndarray, frame_doc: dict,
                display_scale: float = 1.0, encoders: Executor | None = None) -> list[Path]:
    """Write the files of ``outputs`` and ``frame.json`` into ``out_dir`` (created if needed). ``rgb.exr``
    holds ``rgb`` as rendered; ``rgb.png`` holds it times ``display_scale`` (the frame's exposure).

    ``frame_doc`` is validated against ``frame.schema.json`` before anything is written; frame.json is
    written last. ``encoders`` (a thread pool) encodes the files; None: a pool for this call."""
    validate_document(frame_doc, "frame", FRAME_DOCUMENT)
    out_dir.mkdir(parents=True, exist_ok=True)
    jobs = [job for o in outputs for job in _jobs(o, out_dir, rgb=rgb, class_ids=class_ids, instance_ids=instance_ids,
                                                   z_depth=z_depth, palette=palette, display_scale=display_scale)]
    if encoders is None:
        with ThreadPoolExecutor(max_workers=4) as pool:
            written = [f.result() for f in [pool.submit(fn, path, data) for fn, path, data in jobs]]
    else:
        written = [f.result() for f in [encoders.submit(fn, path, data) for fn, path, data in jobs]]
    written.append(write_json_atomic(out_dir / FRAME_DOCUMENT, frame_doc))
    return written
