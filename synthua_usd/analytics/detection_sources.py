"""Which reader opens a detection set: one table of formats, and the rule that picks one for a path.

``auto`` takes a ``.json`` file as COCO instances, a folder holding ``manifest.json`` and ``records/`` as a dataset
``synthua generate`` wrote (its boxes derived for the detector, :mod:`.detection_targets`), and a ``data.yaml`` (or
a folder holding one, or ``images/`` and ``labels/``) as Ultralytics YOLO. A generated dataset is also a YOLO dataset (its ``data.yaml`` and
segmentation labels): ``yolo`` reads it that way, each device its own box, as a third-party tool would.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from synthua_usd.analytics.detection_sets import DetectionSet, read_coco, read_yolo
from synthua_usd.analytics.detection_targets import DetectionTargets, read_generated
from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown

FORMATS = {
    "yolo": lambda path, split, images_dir, targets, scored: read_yolo(path, split),
    "coco": lambda path, split, images_dir, targets, scored: read_coco(path, images_dir),
    "synthua": lambda path, split, images_dir, targets, scored: read_generated(path, split, targets, scored),
}
FORMAT_NAMES = ("auto",) + tuple(FORMATS)


def is_synthua_dataset(path: Path) -> bool:
    """Whether ``path`` is a dataset `synthua generate` or `synthua composite` wrote (a manifest and records)."""
    return path.is_dir() and (path / "manifest.json").is_file() and (path / "records").is_dir()


def detect_format(path: Path) -> str:
    """The format ``auto`` reads ``path`` as; a path that is none of them raises :class:`InputError`."""
    if path.is_file() and path.suffix.lower() == ".json":
        return "coco"
    if is_synthua_dataset(path):
        return "synthua"
    if (path.is_file() and path.suffix.lower() in (".yaml", ".yml")) or (path / "data.yaml").is_file() \
            or ((path / "images").is_dir() and (path / "labels").is_dir()):
        return "yolo"
    raise InputError(f"{shown(path)}: {'not found' if not path.exists() else 'no data.yaml, COCO .json or dataset manifest'}"
                     f"; expected an Ultralytics YOLO folder (data.yaml + images/ + labels/), a COCO instances .json "
                     f"or a dataset written by `synthua generate`")


def read_detection_set(path: str | Path, fmt: str = "auto", split: str | None = None,
                       images_dir: str | Path | None = None,
                       targets: DetectionTargets | None = None, scored: str = "all") -> DetectionSet:
    """The detection set at ``path`` in format ``fmt`` (one of :data:`FORMAT_NAMES`); ``split`` for YOLO and
    generated datasets, ``images_dir`` for COCO, ``targets`` (default :class:`DetectionTargets`) for generated
    datasets, ``scored`` (:data:`~synthua_usd.model.detection_limits.SCORED_BOXES`) for composite ones."""
    path = Path(path)
    if fmt not in FORMAT_NAMES:
        raise InputError(f"--format: {fmt!r}; expected one of {', '.join(FORMAT_NAMES)}")
    fmt = detect_format(path) if fmt == "auto" else fmt
    if scored != "all" and fmt != "synthua":
        raise InputError(f"--boxes {scored}: {shown(path)} is read as a {fmt} set, which does not record which boxes "
                         f"were pasted; expected a dataset `synthua composite` wrote, read as one, or --boxes all")
    return FORMATS[fmt](path, split, images_dir, targets or DetectionTargets(), scored)


def set_id(dataset: DetectionSet) -> str:
    """SHA-256 of what a set holds for a detector: its class names and every image's path, size and boxes."""
    digest = hashlib.sha256(repr((dataset.names, dataset.split)).encode())
    for im in dataset.images:
        digest.update(repr((str(im.path), im.width, im.height, im.boxes)).encode())
        if im.regions:                          # a set read with --boxes pasted or photo; others keep their ids
            digest.update(repr(im.regions).encode())
    return digest.hexdigest()


def manifest_sha256(dataset: DetectionSet) -> str | None:
    """SHA-256 of a generated dataset's ``manifest.json`` (which lists every file of it with its own SHA-256 and
    the generation config): the id of the dataset; None for other layouts."""
    if dataset.layout != "synthua":
        return None
    from synthua_usd.dataset.manifest import sha256_file

    return sha256_file(Path(dataset.source) / "manifest.json")
