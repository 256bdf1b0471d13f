"""Writing the files of a rendered frame and of a dataset image: one writer per kind of file (:data:`WRITERS`, by the
file's key: ``rgb_png``, ``class``, ``depth``, ``yolo_label``, ...), and :func:`write_frame`, the files of a frame's
outputs (:mod:`synthua_usd.core.outputs`) and ``frame.json``. The dataset workers
(:mod:`synthua_usd.pipeline.dataset_worker`, :mod:`synthua_usd.pipeline.composite_worker`) write an image's files
with the same table (:func:`file_writers`: a composite's PNGs at a faster zlib level).

Image files are encoded in parallel on a small thread pool (OpenImageIO releases the GIL while it
encodes): the caller's (a :class:`synthua_usd.pipeline.background.BackgroundWriter`'s encoders, when frames are
written while the next one renders) or one made for the call; :func:`write_frame` returns when every file is
written. Each file is written atomically; the caller writes a whole command's frames into a staging folder
(:func:`synthua_usd.core.atomic.output_set`).
"""

from __future__ import annotations

import functools
from concurrent.futures import Executor, ThreadPoolExecutor
from pathlib import Path
from typing import Any, Callable

import numpy as np

from synthua_usd.backends import previews
from synthua_usd.core import images
from synthua_usd.core.atomic import write_json_atomic, write_text_atomic
from synthua_usd.core.outputs import DEPTH_DEFINITION, FRAME_DOCUMENT, RenderOutput
from synthua_usd.core.schemas import validate_document
from synthua_usd.dataset.formats import onehot


def _depth(path: Path, z_depth: np.ndarray) -> Path:
    return images.write_depth_exr(path, z_depth, DEPTH_DEFINITION)


def _onehot(path: Path, data: tuple[np.ndarray, int]) -> Path:
    class_ids, num_classes = data  # expanded here, on the encoder thread: the tensor is num_classes times the map
    return onehot.write_onehot_npz(path, onehot.onehot(class_ids, num_classes))


def file_writers(png_compression: int | None = None, jpeg_quality: int = 95) -> dict[str, Callable[[Path, Any], Path]]:
    """The writer of each kind of file, by key: ``writer(path, data) -> path``, atomic. ``data`` is, by key:
    ``rgb_png``, ``semantic``, ``instance_preview``, ``panoptic``, ``cs_color`` (H, W, 3) uint8 sRGB; ``img1`` (a
    sequence frame's JPEG) the same; ``class``, ``instance``, ``cs_labelIds``, ``cs_instanceIds``, ``instances`` (a
    sequence frame's) (H, W) uint8 or uint16 ids; ``rgb_exr`` (H, W, 3) float32 scene-linear Rec.709; ``depth``
    (H, W) float32 z-depth in metres; ``yolo_label`` the label file's text; ``onehot`` (class ids (H, W), number of
    classes). ``png_compression``: the zlib level of every PNG (None: OpenImageIO's default); ``jpeg_quality`` 1..100.
    A dataset's ``cs_leftImg8bit`` is no file of its own (a link to ``rgb_png``)."""
    colour = functools.partial(images.write_color_png, compression=png_compression)
    ids = functools.partial(images.write_id_png, compression=png_compression)
    return {"rgb_png": colour, "class": ids, "semantic": colour, "instance": ids, "instance_preview": colour,
            "panoptic": colour, "cs_labelIds": ids, "cs_instanceIds": ids, "cs_color": colour,
            "rgb_exr": images.write_linear_exr, "depth": _depth, "yolo_label": write_text_atomic, "onehot": _onehot,
            "img1": functools.partial(images.write_color_jpeg, quality=jpeg_quality), "instances": ids}


#: :func:`file_writers` at OpenImageIO's PNG compression: a frame's files and a rendered dataset image's.
WRITERS = file_writers()


def _frame_data(*, rgb, class_ids, instance_ids, z_depth, palette, display_scale) -> dict[str, Callable[[], Any]]:
    """What each file of a frame holds, made when its writer runs (on an encoder thread)."""
    return {"rgb_exr": lambda: rgb,
            "rgb_png": lambda: images.linear_to_display(rgb * np.float32(display_scale)),
            "class": lambda: class_ids, "semantic": lambda: palette[class_ids],
            "instance": lambda: instance_ids, "instance_preview": lambda: previews.instance_preview(instance_ids),
            "depth": lambda: z_depth}


def _write(writer: Callable[[Path, Any], Path], path: Path, data: Callable[[], Any]) -> Path:
    return writer(path, data())


def write_frame(out_dir: Path, outputs: tuple[RenderOutput, ...], *, rgb: np.ndarray | None, class_ids: np.ndarray,
                instance_ids: np.ndarray, z_depth: np.ndarray, palette: np.ndarray, frame_doc: dict,
                display_scale: float = 1.0, encoders: Executor | None = None) -> list[Path]:
    """Write the files of ``outputs`` and ``frame.json`` into ``out_dir`` (created if needed). ``rgb.exr``
    holds ``rgb`` as rendered; ``rgb.png`` holds it times ``display_scale`` (the frame's exposure).

    ``frame_doc`` is validated against ``frame.schema.json`` before anything is written; frame.json is
    written last. ``encoders`` (a thread pool) encodes the files; None: a pool for this call."""
    validate_document(frame_doc, "frame", FRAME_DOCUMENT)
    out_dir.mkdir(parents=True, exist_ok=True)
    data = _frame_data(rgb=rgb, class_ids=class_ids, instance_ids=instance_ids, z_depth=z_depth, palette=palette,
                       display_scale=display_scale)
    jobs = [(WRITERS[f.key], out_dir / f.name, data[f.key]) for o in outputs for f in o.files]
    if encoders is None:
        with ThreadPoolExecutor(max_workers=4) as pool:
            written = [f.result() for f in [pool.submit(_write, *job) for job in jobs]]
    else:
        written = [f.result() for f in [encoders.submit(_write, *job) for job in jobs]]
    written.append(write_json_atomic(out_dir / FRAME_DOCUMENT, frame_doc))
    return written
