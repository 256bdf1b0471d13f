"""``synthua verify`` and ``synthua replay``: is a dataset complete, intact and what its manifest says?

:func:`verify` checks, without trusting any file more than another: the manifest and the plan (every
planned image has a record), every file's size and SHA-256 against the manifest, and cross-file
consistency: every COCO annotation's mask is its instance's pixels in ``instance.png`` (area and box
included) and every visible thing instance has one; every panoptic segment matches its PNG exactly; the
Cityscapes label ids are the class map's ids of ``class.png``; YOLO has one line per annotated instance.

:func:`replay` renders one image again in a fresh worker, into a temporary folder, and compares every file
with the dataset's, byte for byte.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from synthua_usd.dataset.layout import SPLITS, Layout
from synthua_usd.dataset.manifest import sha256_file
from synthua_usd.errors import InputError, OutputError, echo

#: Problems listed in full; beyond this many, verify counts the rest.
MAX_LISTED = 50


@dataclass
class Verification:
    images: int = 0
    files: int = 0
    problems: list[str] = field(default_factory=list)

    def add(self, problem: str) -> None:
        self.problems.append(problem)

    @property
    def ok(self) -> bool:
        return not self.problems


def _load_json(path: Path, what: str) -> dict:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{path}: missing; expected the {what} of a dataset written by synthua generate") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: unreadable ({echo(exc)}); expected the {what} JSON") from None


def verify(root: Path, show_progress: bool = False) -> Verification:
    """Check the dataset at ``root``; problems are collected, not raised (a missing manifest is an error)."""
    from tqdm import tqdm

    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{root}: not a folder; expected a dataset folder written by synthua generate")
    result = Verification()
    manifest = _load_json(root / Layout.MANIFEST, "manifest")
    job = _load_json(root / Layout.CONFIG, "generate.json")
    layout = Layout(root)
    planned = {p["id"] for p in job.get("plan", [])}
    listed = {img["id"] for img in manifest.get("images", [])}
    for missing in sorted(planned - listed):
        result.add(f"image {missing}: planned in generate.json but not in the manifest (run generate again to "
                   f"finish it)")
    entries = [e for img in manifest.get("images", []) for e in img["files"]] + manifest.get("dataset_files", [])
    damaged = set()
    for entry in tqdm(entries, desc="checksums", unit="file", disable=not show_progress):
        result.files += 1
        if not _check_file(layout, entry, result):
            damaged.add(entry["path"])
    from synthua_usd.dataset.formats.records import is_rejected
    from synthua_usd.dataset.formats.yolo import class_index
    from synthua_usd.taxonomy import ClassMap

    try:
        yolo_classes = class_index(ClassMap.load(root / Layout.CLASS_MAP))
    except InputError as exc:
        result.add(f"{Layout.CLASS_MAP}: {exc}")
        yolo_classes = {}
    records = []
    for img in manifest.get("images", []):
        try:
            records.append(json.loads(layout.path(Layout.record(img["name"])).read_text(encoding="utf-8")))
        except (OSError, ValueError):
            continue  # already reported by the checksums
    result.images = len(records)
    coco_by_image, coco_images = {}, {}
    for split in SPLITS:
        path = layout.path(Layout.coco_instances(split))
        if path.exists():
            try:
                document = json.loads(path.read_text(encoding="utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError):
                continue  # reported by the checksums
            coco_images.update({img["id"]: split for img in document.get("images", [])})
            for ann in document.get("annotations", []):
                coco_by_image.setdefault(ann["image_id"], []).append(ann)
    kept = {r["id"]: r for r in records if not is_rejected(r)}
    for image_id in sorted(set(coco_by_image) - set(kept)):
        result.add(f"COCO annotations of image {image_id}: no such image kept in the dataset (unknown or rejected)")
    for image_id, record in kept.items():
        if coco_images.get(image_id) != record["split"]:
            result.add(f"image {image_id} ({record['name']}): not among the COCO images of its split "
                       f"{record['split']}")
    panoptic_by_image = {}
    for split in SPLITS:
        path = layout.path(Layout.coco_panoptic(split))
        if path.exists():
            try:
                document = json.loads(path.read_text(encoding="utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError):
                continue
            for ann in document.get("annotations", []):
                panoptic_by_image[ann["image_id"]] = ann
    for record in tqdm(records, desc="consistency", unit="image", disable=not show_progress):
        if is_rejected(record) or damaged & set(record["files"].values()):
            continue  # a damaged file is reported already; its image is not read
        try:
            _check_image(layout, record, coco_by_image.get(record["id"], []), panoptic_by_image.get(record["id"]),
                         yolo_classes, result)
        except Exception as exc:  # noqa: BLE001 - whatever a broken file raises, it is a problem of the dataset
            result.add(f"image {record['id']} ({record['name']}): cannot be checked: {type(exc).__name__}: "
                       f"{echo(exc)}")
    return result


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
    from synthua_usd.backends.images import read_image

    pixels, _ = read_image(layout.path(relative))
    return pixels


def _check_image(layout: Layout, record: dict, coco_annotations: list[dict], panoptic_annotation: dict | None,
                 yolo_classes: dict[int, int], result: Verification) -> None:
    from pycocotools import mask as mask_utils

    where = f"image {record['id']} ({record['name']})"
    files = record["files"]
    instance_ids = _read(layout, files["instance"])[..., 0]
    class_ids = _read(layout, files["class"])[..., 0]
    things = {i["id"]: i for i in record["instances"] if i["isthing"]}
    seen = set()
    for ann in coco_annotations:
        inst = ann.get("instance_id")
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
    if "yolo_label" in files:
        lines = [ln for ln in layout.path(files["yolo_label"]).read_text(encoding="utf-8").splitlines() if ln.strip()]
        expected = sum(1 for i in record["instances"] if i["category_id"] in yolo_classes)
        if len(lines) != expected:
            result.add(f"{where}: {files['yolo_label']} has {len(lines)} lines; the image has {expected} instances "
                       f"of YOLO classes")


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
    image_id: int
    name: str
    identical: list[str] = field(default_factory=list)
    different: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.different


def replay(root: Path, image: str) -> Replay:
    """Render the image ``image`` (its id or name) of the dataset at ``root`` again and compare its files."""
    from synthua_usd.pipeline.dataset_worker import FLUSH, init_worker, work
    from synthua_usd.pipeline.generate import worker_job_from_document
    from synthua_usd.dataset.sampling import PlannedImage

    root = Path(root)
    job_doc = _load_json(root / Layout.CONFIG, "generate.json")
    plan = [PlannedImage(**p) for p in job_doc["plan"]]
    chosen = [p for p in plan if str(p.id) == str(image).lstrip("0") or str(p.id) == str(image)]
    if not chosen:
        from synthua_usd.dataset.layout import image_name

        chosen = [p for p in plan if image_name(p.id, p.camera_name, p.time_code, p.condition, p.seed) == image]
    if not chosen:
        raise InputError(f"{echo(image)}: no such image id or name in {root / Layout.CONFIG}; expected one of "
                         f"1..{len(plan)}")
    planned = chosen[0]
    layout = Layout(root)
    scratch = Path(tempfile.mkdtemp(prefix=".replay-", dir=root.parent))
    try:
        job = worker_job_from_document(job_doc, scratch, dataset=root)
        state = init_worker(job)
        results = work(state, planned) + work(state, FLUSH)
        record = results[-1]["record"]
        out = Replay(planned.id, record["name"])
        original = json.loads(layout.path(Layout.record(record["name"])).read_text(encoding="utf-8"))
        for key, rel in sorted(record["files"].items()):
            theirs = original.get("checksums", {}).get(key, {}).get("sha256")
            ours = sha256_file(scratch / rel)
            (out.identical if ours == theirs else out.different).append(rel)
        ours_record = sha256_file(scratch / Layout.record(record["name"]))
        theirs_record = sha256_file(layout.path(Layout.record(record["name"])))
        (out.identical if ours_record == theirs_record else out.different).append(Layout.record(record["name"]))
        return out
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
