"""The training sets of a sim-to-real experiment (``tools/sim2real.py``), written as Ultralytics YOLO folders of
links (no photo is copied): a nested subset of the real photos (arms b and c), that subset with another labelled set
mixed in (arm d; its classes renamed to the real set's), the real photos no subset holds as a test set (--held-back),
and a generated dataset standing in for real photos where none are at hand. Each folder states what it holds in
``subset.json``. Also what a mixed set of composites was made from (its backgrounds' SHA-256), so that no test photo
reaches a training through a composite.
"""

from __future__ import annotations

import json
import os
from dataclasses import replace
from pathlib import Path

from synthua_usd.analytics.class_mapping import build_mapping
from synthua_usd.analytics.detection_sets import DetectionSet
from synthua_usd.analytics.dataset_index import dataset_manifest
from synthua_usd.analytics.detection_sources import detect_format, read_detection_set
from synthua_usd.analytics.detection_targets import read_generated, targets_for
from synthua_usd.pipeline.detector.yolo_data import write_yolo_boxes
from synthua_usd.core.atomic import write_json_atomic
from synthua_usd.core.errors import InputError
from synthua_usd.dataset.layout import Layout
from synthua_usd.dataset.manifest import kept_images
from synthua_usd.dataset.record import read_record

#: Photos of a subset that Ultralytics validates its last epoch on (figures unused: the model kept is the last
#: epoch's, and no test photo is seen in training).
VAL_IMAGES = 16


def stand_in(dataset: Path, out: Path, test_split: str = "test", convention: str = "wheelchair-sets") -> tuple[Path, Path]:
    """A generated dataset written as a third party's YOLO sets (train, test) with the classes ``person`` and
    ``wheelchair`` (both wheelchair classes, each box covering the chair and its user, as a real annotator draws
    it; the seated user a person too or not, by ``convention``): no synthua file is read through them, only
    data.yaml, images/ and labels/."""
    targets = targets_for(convention, ("person", "manual_wheelchair", "electric_wheelchair"))
    rename = {"manual_wheelchair": "wheelchair", "electric_wheelchair": "wheelchair"}
    folders = []
    for split in ("train", test_split):
        s = read_generated(dataset, split, targets)
        images = tuple(replace(im, boxes=tuple(replace(b, label=rename.get(b.label, b.label)) for b in im.boxes))
                       for im in s.images)
        folders.append(write_yolo_boxes(out / split, {split: replace(s, images=images)}, ("person", "wheelchair")).parent)
    return folders[0], folders[1]


def _base(dataset: DetectionSet) -> Path:
    source = Path(dataset.source)
    return source.parent if source.suffix.lower() in (".yaml", ".yml", ".json") else source


def photo_names(dataset: DetectionSet) -> dict[str, object]:
    """Each image of ``dataset`` by its path relative to the set's folder (how subsets are stated)."""
    base = _base(dataset)
    return {os.path.relpath(im.path, base): im for im in dataset.images}


def _write_folder(out: Path, images: list, names: tuple[str, ...], about: dict, splits) -> Path:
    record = out / "subset.json"
    if record.is_file() and json.loads(record.read_text(encoding="utf-8")) != about:
        raise InputError(f"{out}: holds another draw ({record.name} differs: other photos, seed or mixed set); "
                         f"expected the same draw in a --work folder: give a new --work or remove the old one")
    numbered = tuple(replace(im, id=k) for k, im in enumerate(images, 1))
    whole = DetectionSet(names, numbered, "yolo", str(out), "train")
    write_yolo_boxes(out, {split: replace(whole, images=numbered[:count], split=split) for split, count in splits},
                     names)
    write_json_atomic(record, about)
    return out


def write_training_folder(out: Path, images: list, names: tuple[str, ...], about: dict) -> Path:
    """``images`` as a YOLO folder (links, no copies) with ``names``; its val split the first :data:`VAL_IMAGES` of
    them; ``about`` (what it holds) as ``subset.json``. A folder holding another draw is refused, since the runs kept
    beside it were trained on that one."""
    return _write_folder(out, images, names, about, (("train", len(images)), ("val", VAL_IMAGES)))


def write_test_folder(out: Path, images: list, names: tuple[str, ...], about: dict) -> Path:
    """``images`` as a YOLO folder of links whose one split is ``test`` (the held-back photos), ``about`` as
    ``subset.json``; another draw in ``out`` is refused as by :func:`write_training_folder`."""
    return _write_folder(out, images, names, about, (("test", len(images)),))


def composite_backgrounds(path: Path, split: str) -> dict[str, str]:
    """The photos the composites of ``split`` of a `synthua composite` dataset at ``path`` were made from: SHA-256
    -> the background's path as its records name it (relative to the backgrounds folder); empty for any other set
    (a `synthua generate` dataset, a YOLO folder, a COCO file), whose images are their own."""
    if detect_format(path) != "synthua":
        return {}
    root = Path(path)
    found = {}
    for entry in kept_images(dataset_manifest(root), split):
        record = read_record(root / Layout.record(entry["name"]))
        if "composite" in record:
            background = record["composite"]["background"]
            found[background["sha256"]] = background["path"]
    return found


def renamed_mix(path: Path, split: str, real_names: tuple[str, ...], maps: list[str], convention: str) -> DetectionSet:
    """The mixed set's ``split`` with its classes renamed to the real set's (--mix-map; default same names, and
    ``wheelchair`` takes both wheelchair classes); boxes of classes no real class takes are left out."""
    mix = read_detection_set(path, "auto", split, targets=targets_for(convention))
    try:
        mapping = build_mapping(maps, real_names, mix.names, "the real set", f"the mixed set {path}")
    except InputError as exc:
        raise InputError(str(exc).replace("--map", "--mix-map")) from None
    to_real = mapping.test_class_of()
    images = tuple(replace(im, boxes=tuple(replace(b, label=to_real[b.label]) for b in im.boxes if b.label in to_real))
                   for im in mix.images)
    return replace(mix, names=real_names, images=images)
