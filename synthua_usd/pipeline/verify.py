"""``synthua verify`` and ``synthua replay``: is a dataset complete, intact and what its manifest says?

:func:`verify` checks, without trusting any file more than another: the manifest (against its schema)
and the plan (every planned image has a record), every file's size and SHA-256 against the manifest, that
the folder holds no file the manifest does not list, and cross-file consistency: each record against its own
label PNGs (the files its ``files`` names: its ``class_pixel_counts`` are ``class.png``'s, its instances are the
ids of ``instance.png`` with their pixel counts, boxes and, in ``class.png``, their class; ``semantic.png`` is
``class.png`` in the class map's colours), so that label PNGs swapped between images (checksums rewritten to
match) or a record naming a class its PNGs do not hold fail without rendering; every COCO annotation's
mask is its instance's pixels in ``instance.png`` (area and box included) and every visible thing instance
has one; the person keypoints file is the person part of the instances file; every panoptic segment matches its PNG exactly; the Cityscapes label ids are the class map's ids of
``class.png``, its instance ids and colours what its writer makes of ``instance.png``, ``class.png`` and the record; YOLO has one line per annotated instance. A record or an annotation document that is not
what generate writes (a record: one that does not validate against ``schemas/record.schema.json``) is a
problem of the dataset, never a crash.

:func:`replay` renders one image again in a fresh worker, into a temporary folder, and compares every file
with the file of the same name in the dataset, byte for byte (not with the checksums the dataset records:
a file overwritten after generation must show).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from synthua_usd.core.atomic import named_as
from synthua_usd.core.errors import InputError, OutputError, SynthuaError, echo
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import read_json, type_name
from synthua_usd.dataset.annotations import rle_problem
from synthua_usd.dataset.layout import SPLITS, Layout
from synthua_usd.dataset.manifest import read_manifest, sha256_file
from synthua_usd.dataset.record import SEQUENCE_FRAME, ImageRecord, is_rejected, read_record

#: Problems listed in full; beyond this many, verify counts the rest.
MAX_LISTED = 50


@dataclass
class Verification:
    images: int = 0
    files: int = 0
    problems: list[str] = field(default_factory=list)
    #: Tracking sequences checked and their frames.
    sequences: int = 0
    frames: int = 0

    def add(self, problem: str) -> None:
        self.problems.append(problem)

    @property
    def ok(self) -> bool:
        return not self.problems


def _job(root: Path) -> dict:
    """The run's ``generate.json`` with its plan (a list of planned images, each with an integer id)."""
    path = root / Layout.CONFIG
    if not path.exists():
        raise InputError(f"{shown(path)}: file not found; expected the generate.json of a dataset written by "
                         f"`synthua generate`")
    job = read_json(path, "the generate.json of a dataset")
    plan = job.get("plan") if isinstance(job, dict) else None
    if not isinstance(plan, list) or not all(isinstance(p, dict) and isinstance(p.get("id"), int)
                                             and not isinstance(p.get("id"), bool) for p in plan):
        raise InputError(f"{shown(path)}: plan: {type_name(plan)}; expected a list of planned images with integer "
                         f"ids (the generate.json of a dataset written by `synthua generate`)")
    return job


def _document(layout: Layout, relative: str, what: str, result: Verification):
    """The JSON file ``relative`` of the dataset, or None when it is absent (the checksums report that) or
    unreadable (a problem is added)."""
    try:
        path = layout.path(relative)
        return read_json(path, what) if path.exists() else None
    except (InputError, OutputError) as exc:
        result.add(f"{relative}: {echo(exc, 240)}")
        return None


def _record(layout: Layout, relative: str, result: Verification, kind: str | None = None):
    """The record ``relative`` of the dataset read and validated (:func:`synthua_usd.dataset.record.read_record`; of
    ``kind``, a dataset image's when None), or None when it is absent (the checksums report that) or is no such
    record (a problem naming ``relative`` is added)."""
    path = layout.path(relative)
    if not path.exists():
        return None
    try:
        return read_record(path, kind)
    except (InputError, OutputError) as exc:
        text = str(exc)
        said = f"{shown(path)}: "
        result.add(f"{relative}: {echo(text[len(said):] if text.startswith(said) else text, 240)}")
        return None


def _entries(document, key: str, fields: tuple[str, ...]) -> list[dict] | None:
    """``document[key]`` when it is a list of objects holding ``fields``, else None."""
    items = document.get(key) if isinstance(document, dict) else None
    if isinstance(items, list) and all(isinstance(i, dict) and all(f in i for f in fields) for i in items):
        return items
    return None


def unlisted_files(root: Path, listed: set[str]) -> list[str]:
    """Relative POSIX paths of every file, link or other non-folder entry below ``root`` that is not in
    ``listed`` (links are not followed)."""
    out = []
    for dirpath, dirnames, filenames in os.walk(root):
        folder = Path(dirpath)
        for name in filenames + [d for d in dirnames if (folder / d).is_symlink()]:
            rel = (folder / name).relative_to(root).as_posix()
            if rel not in listed:
                out.append(rel)
    return sorted(out)


def verify(root: Path, show_progress: bool = False) -> Verification:
    """Check the dataset at ``root``; problems are collected, not raised (a missing or malformed manifest or
    generate.json is an :class:`InputError` naming the file)."""
    from tqdm import tqdm

    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{shown(root)}: not a folder; expected a dataset folder written by `synthua generate`")
    result = Verification()
    manifest = read_manifest(root / Layout.MANIFEST)
    job = _job(root)
    layout = Layout(root)
    planned = {p["id"] for p in job["plan"]}
    listed = {img["id"] for img in manifest["images"]}
    for missing in sorted(planned - listed):
        result.add(f"image {missing}: planned in generate.json but not in the manifest (run generate again to "
                   f"finish it)")
    entries = [e for img in manifest["images"] for e in img["files"]] + manifest["dataset_files"]
    for rel in unlisted_files(root, {e["path"] for e in entries} | {Layout.MANIFEST}):
        result.add(f"{rel}: in the dataset folder but not listed in the manifest (written there since, or left "
                   f"by another tool)")
    damaged = set()
    for entry in tqdm(entries, desc="checksums", unit="file", disable=not show_progress):
        result.files += 1
        if not _check_file(layout, entry, result):
            damaged.add(entry["path"])
    from synthua_usd.dataset.formats.yolo import class_index
    from synthua_usd.model.taxonomy import ClassMap

    try:
        class_map = ClassMap.load(root / Layout.CLASS_MAP)
        yolo_classes = class_index(class_map)
    except InputError as exc:
        result.add(f"{Layout.CLASS_MAP}: {exc}")
        class_map, yolo_classes = None, {}
    records = []
    for img in manifest["images"]:
        record = _record(layout, Layout.record(img["name"]), result)
        if record is not None:
            records.append(record)
    result.images = len(records)
    coco_by_image: dict[int, list[dict]] = {}
    coco_images: dict[int, str] = {}
    for split in SPLITS:
        relative = Layout.coco_instances(split)
        document = _document(layout, relative, "COCO instances", result)
        if document is None:
            continue
        images, annotations = _entries(document, "images", ("id",)), _entries(document, "annotations", ("image_id",))
        if images is None or annotations is None:
            result.add(f"{relative}: not a COCO instances document (images with ids, annotations with image ids)")
            continue
        coco_images.update({img["id"]: split for img in images})
        for ann in annotations:
            coco_by_image.setdefault(ann["image_id"], []).append(ann)
        _check_person_keypoints(layout, split, document, result)
    kept = {r["id"]: r for r in records if not is_rejected(r)}
    for image_id in sorted(set(coco_by_image) - set(kept), key=str):
        result.add(f"COCO annotations of image {echo(image_id)}: no such image kept in the dataset (unknown or "
                   f"rejected)")
    for image_id, record in kept.items():
        if coco_images.get(image_id) != record["split"]:
            result.add(f"image {image_id} ({record['name']}): not among the COCO images of its split "
                       f"{echo(record['split'])}")
    panoptic_by_image = {}
    for split in SPLITS:
        relative = Layout.coco_panoptic(split)
        document = _document(layout, relative, "COCO panoptic", result)
        if document is None:
            continue
        annotations = _entries(document, "annotations", ("image_id", "segments_info"))
        if annotations is None:
            result.add(f"{relative}: not a COCO panoptic document (annotations with image ids and segments_info)")
            continue
        for ann in annotations:
            panoptic_by_image[ann["image_id"]] = ann
    config = (job.get("job_key") or {}).get("config") or {}
    min_px = config.get("min_instance_px", 0) if isinstance(config, dict) else 0
    convention = config.get("convention") if isinstance(config, dict) else None
    for record in tqdm(records, desc="consistency", unit="image", disable=not show_progress):
        if is_rejected(record) or damaged & set(record["files"].values()):
            continue  # a damaged file is reported already; its image is not read
        try:
            _check_image(layout, record, coco_by_image.get(record["id"], []), panoptic_by_image.get(record["id"]),
                         yolo_classes, result, min_px, class_map, convention)
        except Exception as exc:  # noqa: BLE001 - whatever a broken file raises, it is a problem of the dataset
            result.add(f"image {record['id']} ({record['name']}): cannot be checked: {type(exc).__name__}: "
                       f"{echo(exc)}")
    if isinstance(job.get("sequences"), list):
        try:
            _check_sequences(layout, job["sequences"], ClassMap.load(root / Layout.CLASS_MAP), damaged, result)
        except InputError as exc:
            result.add(f"{Layout.CLASS_MAP}: {exc}")
    return result


def _check_sequences(layout: Layout, planned: list, class_map, damaged: set, result: Verification) -> None:
    """Every planned frame of every sequence is there; its record's tracked instances have, in its instance map,
    the pixels the record says; a track keeps one prim, class and link over the sequence; ``gt/gt.txt`` and
    ``tracks.csv`` are what the records make, and ``seqinfo.ini`` counts the frames."""
    from synthua_usd.dataset.formats import mot
    from synthua_usd.dataset.sequences import PlannedSequence

    for document in planned:
        try:
            seq = PlannedSequence.from_dict(document)
        except (TypeError, KeyError, ValueError) as exc:
            result.add(f"{Layout.CONFIG}: sequences: {echo(exc)}; expected the sequences generate plans")
            continue
        result.sequences += 1
        pairs = []
        tracks: dict[int, tuple] = {}
        for k in range(1, seq.frames + 1):
            relative = Layout.sequence_frame(seq.name, k, "records")
            record = _record(layout, relative, result, SEQUENCE_FRAME)
            if record is None:
                continue
            result.frames += 1
            try:
                instances = record["instances"]
                pairs.append((k, instances))
                ids_path = record["files"]["instances"]
                ids = None if ids_path in damaged else _read(layout, ids_path)
                for entry in instances:
                    tid = int(entry["id"])
                    seen = (entry["prim_path"], entry["class_name"], entry["relations"].get("uses"))
                    if tracks.setdefault(tid, seen) != seen:
                        result.add(f"sequence {seq.name} frame {k}: track {tid} is {echo(seen)}, earlier "
                                   f"{echo(tracks[tid])}; expected a track to keep its prim, class and link")
                    if ids is not None and int((ids == tid).sum()) != int(entry["area"]):
                        result.add(f"sequence {seq.name} frame {k}: track {tid} has {int((ids == tid).sum())} "
                                   f"pixels in {ids_path}, the record says {entry['area']}")
            except (KeyError, TypeError, ValueError) as exc:
                result.add(f"{relative}: {type(exc).__name__} {echo(exc)}; expected the record generate writes")
        if len(pairs) != seq.frames:
            result.add(f"sequence {seq.name}: {len(pairs)} of {seq.frames} frames have a record (run generate "
                       f"again to finish it)")
            continue
        expected = {"gt/gt.txt": mot.gt_text(mot.gt_rows(pairs, class_map)),
                    "tracks.csv": mot.tracks_text(pairs, class_map)}
        for name, text in expected.items():
            path = layout.path(Layout.sequence_file(seq.name, name))
            if not path.is_file() or path.read_text(encoding="utf-8") != text:
                result.add(f"{Layout.sequence_file(seq.name, name)}: missing or not what the frames' records make")
        info = layout.path(Layout.sequence_file(seq.name, "seqinfo.ini"))
        if not info.is_file() or f"seqLength={seq.frames}\n" not in info.read_text(encoding="utf-8"):
            result.add(f"{Layout.sequence_file(seq.name, 'seqinfo.ini')}: missing or not seqLength={seq.frames}")


def _check_person_keypoints(layout: Layout, split: str, instances: dict, result: Verification) -> None:
    """``person_keypoints_{split}.json`` is the person part of the split's (checked) instances document."""
    from synthua_usd.dataset.formats.coco import person_keypoints

    relative = Layout.coco_person_keypoints(split)
    document = _document(layout, relative, "COCO person keypoints", result)
    try:
        expected = person_keypoints(instances)
    except (KeyError, TypeError):
        expected = None
    if document is not None and document != expected:
        result.add(f"{relative}: differs from the person category and annotations of "
                   f"{Layout.coco_instances(split)}")


def _check_file(layout: Layout, entry: dict, result: Verification) -> bool:
    """Whether the file of a manifest entry is there with its size and SHA-256 (else a problem is added)."""
    try:
        path = layout.path(entry["path"])
    except OutputError as exc:
        result.add(f"manifest: {exc}")
        return False
    if not path.is_file():
        result.add(f"{entry['path']}: missing")
    elif path.stat().st_size != entry["bytes"]:
        result.add(f"{entry['path']}: {path.stat().st_size} bytes; the manifest says {entry['bytes']} (truncated "
                   f"or replaced)")
    elif sha256_file(path) != entry["sha256"]:
        result.add(f"{entry['path']}: SHA-256 differs from the manifest's (altered)")
    else:
        return True
    return False


def _read(layout: Layout, relative: str) -> np.ndarray:
    from synthua_usd.core.images import read_image

    pixels, _ = read_image(layout.path(relative))
    return pixels


def _check_image(layout: Layout, record: ImageRecord, coco_annotations: list[dict], panoptic_annotation: dict | None,
                 yolo_classes: dict[int, int], result: Verification, min_px: int = 0, class_map=None,
                 convention: str | None = None) -> None:
    """The record and the image's annotations against its label maps (each PNG read once); an instance with fewer
    than ``min_px`` pixels in ``instance.png`` must be an ignore region (COCO iscrowd 1, no YOLO line) and every
    other one must not. A composite's YOLO file must be its boxes under the job's ``convention``, as its record
    makes them."""
    from pycocotools import mask as mask_utils

    where = f"image {record['id']} ({record['name']})"
    files = record["files"]
    instance_ids = _read(layout, files["instance"])[..., 0]
    class_ids = _read(layout, files["class"])[..., 0]
    if class_map is not None:
        _check_record_labels(layout, where, record, instance_ids, class_ids, class_map, result)
    things = {i["id"]: i for i in record["instances"] if i["isthing"]}
    seen = set()
    for ann in coco_annotations:
        inst = ann.get("instance_id")
        problem = rle_problem(ann.get("segmentation"), instance_ids.shape)
        if problem:  # pycocotools would read past the string or write past the mask
            result.add(f"{where}: COCO annotation {echo(ann.get('id'))} (instance {echo(inst)}): segmentation: "
                       f"{problem}")
            continue
        mask = mask_utils.decode(ann["segmentation"]).astype(bool)
        truth = instance_ids == inst
        if mask.shape != truth.shape or not np.array_equal(mask, truth):
            result.add(f"{where}: COCO annotation {ann['id']} (instance {inst}): its mask differs from the "
                       f"instance's pixels in {files['instance']}")
            continue
        if int(ann["area"]) != int(truth.sum()):
            result.add(f"{where}: COCO annotation {ann['id']}: area {ann['area']}; the mask has {int(truth.sum())}")
        ys, xs = np.nonzero(truth)
        box = [float(xs.min()), float(ys.min()), float(xs.max() - xs.min() + 1), float(ys.max() - ys.min() + 1)]
        if [float(v) for v in ann["bbox"]] != box:
            result.add(f"{where}: COCO annotation {ann['id']}: bbox {ann['bbox']}; the mask's box is {box}")
        if "keypoints" in ann:
            _check_keypoints(where, ann, truth, result)
        if int(ann.get("iscrowd", 0)) != int(truth.sum() < min_px):
            result.add(f"{where}: COCO annotation {ann['id']}: iscrowd {ann.get('iscrowd')} for {int(truth.sum())} "
                       f"pixels; expected iscrowd 1 below min_instance_px = {min_px}, else 0")
        seen.add(inst)
    for missing in sorted(set(things) - seen):
        result.add(f"{where}: instance {missing} ({things[missing]['class_name']}) is visible but has no COCO "
                   f"annotation")
    if panoptic_annotation is None:
        result.add(f"{where}: no annotation in the panoptic JSON")
    else:
        png = _read(layout, files["panoptic"]).astype(np.int64)
        ids = png[..., 0] + 256 * png[..., 1] + 65536 * png[..., 2]
        values, counts = np.unique(ids, return_counts=True)
        in_png = {int(v): int(c) for v, c in zip(values, counts) if v}
        in_json = {int(s["id"]): int(s["area"]) for s in panoptic_annotation["segments_info"]}
        if in_png != in_json:
            diff = sorted(set(in_png.items()) ^ set(in_json.items()))[:4]
            result.add(f"{where}: panoptic segments (id, area) of the JSON and of {files['panoptic']} differ, "
                       f"e.g. {diff}")
    if "cs_labelIds" in files and not np.array_equal(_read(layout, files["cs_labelIds"])[..., 0], class_ids):
        result.add(f"{where}: {files['cs_labelIds']} differs from {files['class']}")
    if class_map is not None and {"cs_instanceIds", "cs_color"} & set(files):
        _check_cityscapes(layout, where, record, instance_ids, class_ids, class_map, result)
    if "yolo_label" in files and "composite" in record:
        from synthua_usd.model.taxonomy import ClassMap
        from synthua_usd.pipeline.composite_worker import composite_yolo_text

        expected_text = composite_yolo_text(record, ClassMap.load(layout.path(Layout.CLASS_MAP)), convention)
        if layout.path(files["yolo_label"]).read_text(encoding="utf-8") != expected_text:
            result.add(f"{where}: {files['yolo_label']} is not the boxes its record makes under the convention "
                       f"{convention} (pasted instances, then the photo's kept boxes)")
    elif "yolo_label" in files:
        lines = [ln for ln in layout.path(files["yolo_label"]).read_text(encoding="utf-8").splitlines() if ln.strip()]
        pixels = np.bincount(instance_ids.reshape(-1).astype(np.int64))
        expected = sum(1 for i in record["instances"] if i["category_id"] in yolo_classes
                       and (pixels[i["id"]] if i["id"] < len(pixels) else 0) >= min_px)
        if len(lines) != expected:
            result.add(f"{where}: {files['yolo_label']} has {len(lines)} lines; the image has {expected} instances "
                       f"of YOLO classes with at least min_instance_px = {min_px} pixels")


#: Disagreements of one record with its label PNGs listed in full; the rest are counted in one line.
RECORD_DISAGREEMENTS = 4


def _check_record_labels(layout: Layout, where: str, record: ImageRecord, instance_ids: np.ndarray,
                         class_ids: np.ndarray, class_map, result: Verification) -> None:
    """The record against its own label PNGs, without rendering: ``class_pixel_counts`` against ``class.png``;
    every instance's id, pixel count and box against ``instance.png`` and its class against ``class.png`` under its
    pixels (no id of ``instance.png`` missing from the record); ``semantic.png`` (when the record lists it) against
    ``class.png`` in the class map's colours. ``instance_ids``, ``class_ids``: (H, W) as read."""
    files = record["files"]
    found: list[str] = []
    if instance_ids.shape != class_ids.shape or instance_ids.shape != (record["height"], record["width"]):
        result.add(f"{where}: {files['instance']} is {instance_ids.shape[1]}x{instance_ids.shape[0]} and "
                   f"{files['class']} {class_ids.shape[1]}x{class_ids.shape[0]}; the record says "
                   f"{record['width']}x{record['height']}")
        return
    name_of = {c.id: c.name for c in class_map.classes}
    counts = np.bincount(class_ids.reshape(-1).astype(np.int64), minlength=256)
    in_png = {name_of.get(k, f"class id {k}"): int(n) for k, n in enumerate(counts) if n}
    said = {str(k): int(v) for k, v in record["class_pixel_counts"].items()}
    for name in sorted(set(in_png) | set(said)):
        if in_png.get(name, 0) != said.get(name, 0):
            found.append(f"class_pixel_counts {name} is {said.get(name, 0)}, {files['class']} has "
                         f"{in_png.get(name, 0)} pixels of it")
    # one pass over the pixels: every (instance id, class id) pair, its pixel count and its box
    ids = instance_ids.reshape(-1).astype(np.int64)
    pairs, pixels = np.unique(ids * 256 + class_ids.reshape(-1).astype(np.int64), return_counts=True)
    top = int(ids.max()) + 1
    height, width = instance_ids.shape
    xs, ys = np.tile(np.arange(width), height), np.repeat(np.arange(height), width)
    lo_x, lo_y = np.full(top, width), np.full(top, height)
    hi_x, hi_y = np.full(top, -1), np.full(top, -1)
    np.minimum.at(lo_x, ids, xs)
    np.minimum.at(lo_y, ids, ys)
    np.maximum.at(hi_x, ids, xs)
    np.maximum.at(hi_y, ids, ys)
    classes_of: dict[int, dict[int, int]] = {}
    for pair, n in zip(pairs.tolist(), pixels.tolist()):
        classes_of.setdefault(pair // 256, {})[pair % 256] = n
    listed = set()
    for inst in record["instances"]:
        iid, area = int(inst["id"]), int(inst["area"])
        listed.add(iid)
        held = classes_of.get(iid, {}) if iid > 0 else {}
        if sum(held.values()) != area:
            found.append(f"instance {iid} ({inst['class_name']}) has {area} pixels in the record, "
                         f"{sum(held.values())} in {files['instance']}")
            continue
        if not area:
            continue
        expected = class_map.resolve(str(inst["class_name"]))
        if expected is None or expected.id != int(inst["category_id"]) or set(held) != {expected.id}:
            shown = ", ".join(f"{name_of.get(c, f'class id {c}')} ({n} px)" for c, n in sorted(held.items()))
            found.append(f"instance {iid} is {inst['class_name']} (category {inst['category_id']}) in the record, "
                         f"{shown} in {files['class']}")
        box = [int(lo_x[iid]), int(lo_y[iid]), int(hi_x[iid] - lo_x[iid] + 1), int(hi_y[iid] - lo_y[iid] + 1)]
        if [float(v) for v in inst["bbox"]] != [float(v) for v in box]:
            found.append(f"instance {iid} ({inst['class_name']}) has bbox {inst['bbox']} in the record, {box} in "
                         f"{files['instance']}")
    unlisted = sorted(i for i in classes_of if i and i not in listed)
    if unlisted:
        found.append(f"{files['instance']} holds instance ids {unlisted[:8]} the record does not list")
    if "semantic" in files:
        semantic = _read(layout, files["semantic"])[..., :3]
        if semantic.shape != (*class_ids.shape, 3) or not np.array_equal(semantic, class_map.palette()[class_ids]):
            found.append(f"{files['semantic']} is not {files['class']} in the class map's colours")
    for line in found[:RECORD_DISAGREEMENTS]:
        result.add(f"{where}: its record and its label PNGs disagree: {line}")
    if len(found) > RECORD_DISAGREEMENTS:
        result.add(f"{where}: ... and {len(found) - RECORD_DISAGREEMENTS} more disagreements of its record with "
                   f"its label PNGs")


def _check_cityscapes(layout: Layout, where: str, record: ImageRecord, instance_ids: np.ndarray,
                      class_ids: np.ndarray, class_map, result: Verification) -> None:
    """``cs_instanceIds`` and ``cs_color`` are what the Cityscapes writer makes of ``instance.png``, ``class.png``
    and the record's instances (their classes and ignore flags)."""
    from synthua_usd.dataset.formats.cityscapes import cityscapes_arrays
    from synthua_usd.model.scene import Instance

    files = record["files"]
    instances = [Instance(int(i["id"]), str(i["prim_path"]), int(i["category_id"]), str(i["class_name"]),
                          bool(i["isthing"])) for i in record["instances"]]
    ignored = {int(i["id"]) for i in record["instances"] if i["ignore"]}
    try:
        _, expected_ids, expected_color = cityscapes_arrays(class_ids.astype(np.uint8), instance_ids.astype(np.uint16),
                                                            instances, class_map, ignored)
    except SynthuaError as exc:
        result.add(f"{where}: its record and its label PNGs disagree: {echo(exc)}")
        return
    for key, expected in (("cs_instanceIds", expected_ids), ("cs_color", expected_color)):
        if key in files:
            found = _read(layout, files[key])
            found = found[..., 0] if expected.ndim == 2 else found[..., :3]
            if found.shape != expected.shape or not np.array_equal(found, expected):
                result.add(f"{where}: {files[key]} is not what {files['instance']}, {files['class']} and the record "
                           f"make (Cityscapes {key[3:]})")


def _check_keypoints(where: str, ann: dict, truth: np.ndarray, result: Verification) -> None:
    """A COCO annotation's keypoints against its instance's pixels ``truth`` (H, W) bool: ``num_keypoints``
    counts the labelled ones, an unlabelled one is at 0, 0, a labelled one lies in the image, and a visible
    one (v = 2) has its instance within :data:`WINDOW_PX` pixels (the rule of
    :mod:`synthua_usd.dataset.keypoints`; its depth part needs the depth image, which is optional)."""
    from synthua_usd.dataset.keypoints import WINDOW_PX

    values = np.asarray(ann["keypoints"], float).reshape(-1, 3)
    labelled = values[:, 2] > 0
    if int(ann.get("num_keypoints", -1)) != int(labelled.sum()):
        result.add(f"{where}: COCO annotation {ann['id']}: num_keypoints {ann.get('num_keypoints')}; "
                   f"{int(labelled.sum())} keypoints are labelled")
    height, width = truth.shape
    for k, (x, y, v) in enumerate(values):
        if v == 0:
            bad = x != 0 or y != 0
        else:
            col, row = int(x), int(y)
            bad = not (0 <= x < width and 0 <= y < height) or (v == 2 and not truth[
                max(0, row - WINDOW_PX):row + WINDOW_PX + 1, max(0, col - WINDOW_PX):col + WINDOW_PX + 1].any())
        if bad:
            result.add(f"{where}: COCO annotation {ann['id']}: keypoint {k} at ({x:g}, {y:g}) with v = {v:g} "
                       f"disagrees with the instance's pixels (v = 2 needs them within {WINDOW_PX} px)")
            return


@dataclass
class Replay:
    """What a replay found: each file of the image, identical to the dataset's file on disk or different (a
    file of the dataset's record that the re-render did not make, or one missing on disk, is different)."""

    image_id: int
    name: str
    identical: list[str] = field(default_factory=list)
    different: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.different


def _sha256_or_none(path: Path) -> str | None:
    return sha256_file(path) if path.is_file() else None


def replay(root: Path, image: str) -> Replay:
    """Render the image ``image`` (its id or name) of the dataset at ``root`` again and compare each of its
    files with the dataset's file on disk."""
    from synthua_usd.dataset.sampling import PlannedImage
    from synthua_usd.pipeline.dataset_worker import FLUSH, init_worker, work
    from synthua_usd.pipeline.generate import worker_job_from_document

    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{shown(root)}: not a folder; expected a dataset folder written by `synthua generate`")
    job_doc = _job(root)
    from synthua_usd.pipeline.composite import is_composite_job

    if is_composite_job(job_doc):
        return _compare(root, _replay_composite(root, job_doc, image))
    try:
        plan = [PlannedImage(**p) for p in job_doc["plan"]]
    except (TypeError, ValueError) as exc:
        raise InputError(f"{shown(root / Layout.CONFIG)}: plan: {echo(exc)}; expected the planned images "
                         f"`synthua generate` writes") from None
    chosen = [p for p in plan if str(p.id) == str(image).lstrip("0") or str(p.id) == str(image)]
    if not chosen:
        from synthua_usd.dataset.layout import image_name

        chosen = [p for p in plan if image_name(p.id, p.camera_name, p.time_code, p.condition, p.seed) == image]
    if not chosen:
        raise InputError(f"{echo(image)}: no such image id or name in {root / Layout.CONFIG}; expected one of "
                         f"1..{len(plan)}")
    planned = chosen[0]

    def remake(scratch: Path) -> dict:
        try:
            job = worker_job_from_document(job_doc, scratch, dataset=root)
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"{shown(root / Layout.CONFIG)}: {type(exc).__name__} {echo(exc)}; expected the "
                             f"generate.json `synthua generate` writes") from None
        state = init_worker(job)
        return (work(state, planned) + work(state, FLUSH))[-1]["record"]

    return _compare(root, remake)


def _replay_composite(root: Path, job_doc: dict, image: str):
    """The remaking of the planned composite ``image`` (its id or name) of a ``synthua composite`` dataset."""
    from synthua_usd.pipeline.composite import remake

    plan = job_doc.get("plan") or []
    chosen = [p for p in plan if str(p.get("id")) in (str(image), str(image).lstrip("0")) or p.get("name") == image]
    if not chosen:
        raise InputError(f"{echo(image)}: no such image id or name in {root / Layout.CONFIG}; expected one of "
                         f"1..{len(plan)}")
    return lambda scratch: remake(job_doc, chosen[0], scratch)


def _compare(root: Path, remake) -> Replay:
    """Make an image again with ``remake(scratch) -> record`` into a scratch folder beside the dataset and compare
    each of its files, and those the dataset's record lists, with the dataset's file on disk."""
    layout = Layout(root)
    try:
        scratch = Path(tempfile.mkdtemp(prefix=".replay-", dir=root.parent))
    except OSError as exc:
        raise OutputError(f"{shown(root.parent)}: cannot make the replay's scratch folder beside the dataset "
                          f"({exc.strerror}); expected a writable folder") from None
    try:
        with named_as(scratch, root):  # a failure names the dataset, never the scratch folder
            record = remake(scratch)
        out = Replay(record["id"], record["name"])
        record_path = Layout.record(record["name"])
        original = _record(layout, record_path, Verification())
        theirs = set() if original is None else set(original["files"].values())
        for rel in sorted(set(record["files"].values()) | theirs | {record_path}):
            ours = _sha256_or_none(scratch / rel)
            same = ours is not None and ours == _sha256_or_none(layout.path(rel))
            (out.identical if same else out.different).append(rel)
        return out
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
