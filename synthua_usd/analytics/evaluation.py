"""``synthua eval``: predictions against a dataset's labels.

Semantic predictions are PNGs named ``{image name}.png`` in one folder, one per evaluated image, at the
image's size: single-channel class ids (8 or 16 bit, ids of the dataset's class map) or colour images in the
class map's colours (a 4th, alpha channel is ignored), mapped back to ids. The ground truth is each image's
``frames/{name}/class.png``. Pixels whose ground truth is ``unlabelled`` are not evaluated (void).
Instance predictions in COCO results format (a JSON list of ``image_id``, ``category_id``, ``score`` and
``bbox`` and/or RLE ``segmentation``) are scored against the dataset's COCO instances by pycocotools' COCOeval.
"""

from __future__ import annotations

import contextlib
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synthua_usd.analytics import segmentation_metrics as sm
from synthua_usd.analytics.dataset_index import dataset_manifest, load_class_map
from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import check_input_file, shown
from synthua_usd.core.schemas import read_json
from synthua_usd.dataset.annotations import rle_problem
from synthua_usd.dataset.layout import SPLITS, Layout, inside
from synthua_usd.dataset.manifest import kept_images
from synthua_usd.model.taxonomy import ClassMap

#: Largest prediction image read (bytes): far above any label map of a 16384-pixel-wide image in PNG.
MAX_PNG_BYTES = 512 * 2**20


@dataclass(frozen=True)
class GroundTruthImage:
    id: int
    name: str
    split: str

    @property
    def class_png(self) -> str:
        return Layout.frame_file(self.name, "class")


def ground_truth_images(gt_dir: Path, split: str | None) -> list[GroundTruthImage]:
    """The images of the dataset at ``gt_dir`` that QA did not reject, of ``split`` when given, by id."""
    if split is not None and split not in SPLITS:
        raise InputError(f"--split: {split!r}; expected one of {', '.join(SPLITS)}")
    out = [GroundTruthImage(e["id"], e["name"], e["split"]) for e in kept_images(dataset_manifest(gt_dir), split)]
    if not out:
        raise InputError(f"{shown(gt_dir)}: no images{f' in split {split}' if split else ''}; expected a dataset "
                         f"with images to evaluate")
    return out


def _read_png(path: Path, what: str) -> np.ndarray:
    from synthua_usd.core.images import read_image

    check_input_file(path, MAX_PNG_BYTES, what)
    try:
        pixels, _ = read_image(path)
    except OSError:
        raise InputError(f"{shown(path)}: not an image OpenImageIO can read; expected {what}") from None
    return pixels


def prediction_ids(pixels: np.ndarray, class_map: ClassMap, where: str) -> np.ndarray:
    """(H, W) int64 class ids of a prediction image's pixels ((H, W, C) as read): C = 1 ids, C = 3 or 4
    colours of ``class_map`` (alpha ignored). Unknown ids or colours raise :class:`InputError` naming the
    first such pixel."""
    ids_known = np.zeros(65536, bool)
    ids_known[[c.id for c in class_map.classes]] = True
    channels = pixels.shape[2]
    if channels == 1:
        if not np.issubdtype(pixels.dtype, np.integer):
            raise InputError(f"{where}: {pixels.dtype} pixels; expected 8- or 16-bit class ids or 8-bit colours")
        ids = pixels[..., 0].astype(np.int64)
        bad = ~ids_known[ids]
        if bad.any():
            y, x = np.argwhere(bad)[0]
            raise InputError(f"{where}: class id {ids[y, x]} at pixel (x={x}, y={y}) is not in the class map; "
                             f"expected ids {', '.join(str(c.id) for c in class_map.classes[:3])}, ... "
                             f"{class_map.classes[-1].id}")
        return ids
    if channels in (3, 4) and pixels.dtype == np.uint8:
        rgb = pixels[..., :3].astype(np.int64)
        key = (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]
        lut = {(r << 16) | (g << 8) | b: c.id for c in class_map.classes for r, g, b in [c.color]}
        values, inverse = np.unique(key, return_inverse=True)
        mapped = np.array([lut.get(int(v), -1) for v in values], np.int64)
        if (mapped < 0).any():
            v = int(values[np.flatnonzero(mapped < 0)[0]])
            y, x = np.argwhere(key == v)[0]
            example = class_map.classes[1] if len(class_map.classes) > 1 else class_map.classes[0]
            raise InputError(f"{where}: colour {tuple(int(t) for t in rgb[y, x])} at pixel (x={x}, y={y}) is not a "
                             f"class colour; expected the class map's colours, e.g. {example.name} = "
                             f"{tuple(example.color)}")
        return mapped[inverse.reshape(key.shape)]
    raise InputError(f"{where}: {channels} channels of {pixels.dtype}; expected one channel of class ids or an "
                     f"8-bit RGB(A) image in the class colours")


@dataclass(frozen=True)
class SemanticEvaluation:
    class_map: ClassMap
    matrix: np.ndarray                  # (K, K) int64, rows ground truth, columns prediction; K = max id + 1
    per_class: list[sm.ClassMetrics]
    summary: dict
    images: int
    ignored_predictions: tuple[str, ...]


def evaluate_semantic(gt_dir: Path, pred_dir: Path, split: str | None = None) -> SemanticEvaluation:
    """Confusion matrix and metrics of the class-id or colour PNGs in ``pred_dir`` against ``gt_dir``."""
    gt_dir, pred_dir = Path(gt_dir), Path(pred_dir)
    images = ground_truth_images(gt_dir, split)
    class_map = load_class_map(gt_dir)
    if not pred_dir.is_dir():
        raise InputError(f"{shown(pred_dir)}: not a folder; expected a folder of {{image name}}.png predictions "
                         f"(or a COCO results .json file)")
    pred_paths = {g.name: inside(pred_dir, f"{g.name}.png") for g in images}   # names from the manifest: checked
    missing = [g.name for g in images if not pred_paths[g.name].is_file()]
    if missing:
        raise InputError(f"{shown(pred_dir / (missing[0] + '.png'))}: file not found; expected a prediction for each "
                         f"of the {len(images)} images evaluated ({len(missing)} missing)")
    k = max(c.id for c in class_map.classes) + 1
    matrix = np.zeros((k, k), np.int64)
    layout = Layout(gt_dir)
    for g in images:
        gt_path = layout.path(g.class_png)
        gt = _read_png(gt_path, "a class-id map")[..., 0].astype(np.int64)
        pred_path = pred_paths[g.name]
        pred = prediction_ids(_read_png(pred_path, "a prediction PNG"), class_map, shown(pred_path))
        if pred.shape != gt.shape:
            raise InputError(f"{shown(pred_path)}: {pred.shape[1]}x{pred.shape[0]} pixels; expected "
                             f"{gt.shape[1]}x{gt.shape[0]}, the size of its ground truth {shown(gt_path)}")
        if gt.max(initial=0) >= k:
            raise InputError(f"{shown(gt_path)}: class id {gt.max()} is not in the dataset's class map; expected ids "
                             f"below {k}")
        matrix += sm.confusion_matrix(gt, pred, k, ignore=0)
    names = {f"{g.name}.png" for g in images}
    ignored = tuple(sorted(p.name for p in pred_dir.glob("*.png") if p.name not in names))
    per_class = sm.class_metrics(matrix)
    return SemanticEvaluation(class_map, matrix, per_class, sm.summary(matrix, per_class), len(images), ignored)


def _finite(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _check_detection(r: dict, image: dict, where: str) -> None:
    """A detection's score, box and RLE mask are what COCOeval can read (else one-line :class:`InputError`)."""
    if not _finite(r["score"]):
        raise InputError(f"{where}.score: {r['score']!r}; expected a finite number")
    if "bbox" in r and not (isinstance(r["bbox"], list) and len(r["bbox"]) == 4 and all(map(_finite, r["bbox"]))
                            and r["bbox"][2] >= 0 and r["bbox"][3] >= 0):
        raise InputError(f"{where}.bbox: {str(r['bbox'])[:80]}; expected [x, y, width, height], finite, sizes >= 0")
    if "segmentation" in r:
        problem = rle_problem(r["segmentation"], (image["height"], image["width"]))
        if problem:
            raise InputError(f"{where}.segmentation: {echo(problem, 240)}; expected an RLE mask (pycocotools' "
                             f"compressed counts) of its image's size")


def evaluate_coco(gt_dir: Path, results_path: Path, split: str | None = None) -> dict:
    """COCO mAP of the results file against the dataset's COCO instances (the splits evaluated merged):
    per IoU type present in the results (``segm`` when they hold segmentations, ``bbox`` when boxes), the 12
    COCOeval numbers and the AP (IoU 0.50:0.95) per category."""
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    gt_dir = Path(gt_dir)
    images = ground_truth_images(gt_dir, split)
    splits = sorted({g.split for g in images})
    merged: dict = {"images": [], "annotations": [], "categories": None}
    for s in splits:
        doc = read_json(Layout(gt_dir).path(Layout.coco_instances(s)), "COCO instances")
        merged["images"] += doc["images"]
        merged["annotations"] += doc["annotations"]
        merged["categories"] = doc["categories"]
    results = read_json(results_path, "COCO results (a list of detections)")
    where = shown(results_path)
    if not isinstance(results, list) or not results:
        raise InputError(f"{where}: {type(results).__name__}; expected a non-empty JSON list of COCO results")
    images_by_id = {im["id"]: im for im in merged["images"]}
    image_ids = set(images_by_id)
    category_ids = {c["id"] for c in merged["categories"]}
    for i, r in enumerate(results):
        if not isinstance(r, dict) or not {"image_id", "category_id", "score"} <= set(r) or \
                not ({"bbox", "segmentation"} & set(r)):
            raise InputError(f"{where}: [{i}]: expected an object with image_id, category_id, score and bbox or "
                             f"segmentation")
        if r["image_id"] not in image_ids:
            raise InputError(f"{where}: [{i}].image_id: {r['image_id']!r} is not an image of the evaluated "
                             f"ground truth; expected one of its {len(image_ids)} image ids")
        if r["category_id"] not in category_ids:
            raise InputError(f"{where}: [{i}].category_id: {r['category_id']!r}; expected a thing class id of the "
                             f"class map")
        _check_detection(r, images_by_id[r["image_id"]], f"{where}: [{i}]")
    iou_types = [t for t, key in (("segm", "segmentation"), ("bbox", "bbox")) if all(key in r for r in results)]
    out: dict = {"images": len(image_ids), "detections": len(results), "iou_types": {}}
    names = {c["id"]: c["name"] for c in merged["categories"]}
    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO()
        gt.dataset = merged
        gt.createIndex()
        dt = gt.loadRes(results)
        for iou_type in iou_types:
            ev = COCOeval(gt, dt, iou_type)
            ev.evaluate()
            ev.accumulate()
            ev.summarize()
            labels = ["AP", "AP50", "AP75", "AP_small", "AP_medium", "AP_large", "AR1", "AR10", "AR100",
                      "AR_small", "AR_medium", "AR_large"]
            per_cat = {}
            for k, cat in enumerate(ev.params.catIds):
                p = ev.eval["precision"][:, :, k, 0, -1]
                per_cat[names[cat]] = float(p[p > -1].mean()) if (p > -1).any() else None
            out["iou_types"][iou_type] = {"stats": dict(zip(labels, (float(v) for v in ev.stats))),
                                          "ap_per_class": per_cat}
    return out
