"""A detector's boxes scored against a detection set, by pycocotools' COCOeval (``bbox``).

The test set's boxes of the scored classes (:class:`~synthua_usd.analytics.class_mapping.ClassMapping`) become a
COCO ground truth (``ignore`` boxes as ``iscrowd``: neither required nor penalised); the detections, their model
classes renamed to the test classes they score as, its results. Where several model classes score as one test
class (``wheelchair`` from ``manual_wheelchair`` and ``electric_wheelchair``), a box that both predicted would be
one true and one false positive: detections of such a class are first suppressed across the model classes at
``merge_iou`` (box IoU by pycocotools, the highest score kept), as the detector's own NMS does within a class.

Per scored class: AP50 (IoU 0.5) and AP50-95 (mean over IoU 0.50:0.05:0.95), from COCOeval's precision table at
area ``all`` and 100 detections an image; and, at one fixed confidence (default 0.25), precision TP / (TP + FP) and
recall TP / (TP + FN) at IoU 0.5, counted from COCOeval's own matches (its greedy matching takes detections by
falling score, so the matches of those above the confidence are the ones a run on them alone would make). The
false negatives at that confidence, largest first, say which objects the model misses; the false positives, by
falling score, what it takes for the class, each sorted by what it lands on by TIDE's rules (Bolya et al., ECCV
2020; :func:`classify_false_positive`).
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass, field

import numpy as np

from synthua_usd.analytics.class_mapping import ClassMapping
from synthua_usd.analytics.detection_sets import Box, DetectionSet

#: COCOeval's summary numbers, in its order.
STAT_NAMES = ("AP", "AP50", "AP75", "AP_small", "AP_medium", "AP_large", "AR1", "AR10", "AR100", "AR_small",
              "AR_medium", "AR_large")


@dataclass(frozen=True)
class Detection:
    """One predicted box: ``image_id`` of the set's image, ``label`` a model class, ``score`` in [0, 1]; x, y, w, h
    in pixels of the image (pixel edges)."""

    image_id: int
    label: str
    score: float
    x: float
    y: float
    w: float
    h: float


@dataclass(frozen=True)
class Miss:
    """A false negative at the fixed confidence: the missed box, its image, and the detection of its class (at any
    score) that overlaps it most: its IoU (0 when none overlaps), score and box (x, y, w, h; None when none)."""

    image_id: int
    box: Box
    best_iou: float
    best_score: float | None
    best_box: tuple[float, float, float, float] | None = None


#: A false positive overlapping a box by this IoU or more lies on it; by BACKGROUND_IOU or less with every box, on
#: nothing (TIDE's foreground and background thresholds).
FOREGROUND_IOU = 0.5
BACKGROUND_IOU = 0.1
#: What a false positive lands on, in the order :func:`classify_false_positive` tries them.
FP_KINDS = ("localisation", "other_class", "duplicate", "background", "near_other_class")
#: How false positives are sorted, as metrics.json records it: a report whose record differs sorted them otherwise.
FP_RULES = {"kinds": list(FP_KINDS), "order": "TIDE's", "foreground_iou": FOREGROUND_IOU,
            "background_iou": BACKGROUND_IOU, "boxes": "every labelled box and crowd region of the image"}


@dataclass(frozen=True)
class FalsePositive:
    """A false positive at the fixed confidence (``detection`` in its test class) and what it lands on: ``kind``
    one of :data:`FP_KINDS`, ``on`` the box of that kind it overlaps most (its own class's for ``duplicate`` and
    ``localisation``, another label's for ``other_class`` and ``near_other_class``, None for ``background``) and
    ``iou`` its box IoU with that box (the best over every box for ``background``)."""

    detection: Detection
    kind: str
    on: Box | None
    iou: float


@dataclass(frozen=True)
class ClassResult:
    name: str
    model_classes: tuple[str, ...]
    boxes: int                  # boxes scored (not ignored)
    detections: int             # detections at any score
    ap50: float | None          # None when the class has no box in the set
    ap50_95: float | None
    tp: int                     # at the fixed confidence, IoU 0.5
    fp: int
    fn: int
    fp_kinds: dict[str, int] = field(default_factory=dict)     # FP_KINDS -> count, summing to fp
    fp_on: dict[str, int] = field(default_factory=dict)        # other label -> its other_class + near_other_class

    @property
    def precision(self) -> float | None:
        return self.tp / (self.tp + self.fp) if self.tp + self.fp else None

    @property
    def recall(self) -> float | None:
        return self.tp / (self.tp + self.fn) if self.tp + self.fn else None

    def row(self) -> dict:
        return {"class": self.name, "model_classes": "+".join(self.model_classes), "boxes": self.boxes,
                "detections": self.detections, "AP50": self.ap50, "AP50_95": self.ap50_95, "tp": self.tp,
                "fp": self.fp, "fn": self.fn, "precision": self.precision, "recall": self.recall} | {
                    f"fp_{kind}": self.fp_kinds.get(kind, 0) for kind in FP_KINDS}


@dataclass(frozen=True)
class DetectionEvaluation:
    classes: tuple[ClassResult, ...]
    stats: dict                          # COCOeval's 12 numbers over the scored classes
    confidence: float
    images: int
    misses: tuple[Miss, ...] = field(default=())
    false_positives: tuple[FalsePositive, ...] = field(default=())

    def document(self) -> dict:
        return {"evaluator": "pycocotools COCOeval (bbox)", "images": self.images, "confidence": self.confidence,
                "iou_for_precision_recall": 0.5, "coco_stats": self.stats,
                "false_positive_kinds": dict(FP_RULES),
                "classes": [c.row() | {"fp_on": c.fp_on} for c in self.classes]}


def _xywh_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    from pycocotools import mask as mask_utils

    if not len(a) or not len(b):
        return np.zeros((len(a), len(b)))
    return np.asarray(mask_utils.iou(a.astype(np.float64), b.astype(np.float64), [0] * len(b)), np.float64).reshape(
        len(a), len(b))


def merge_detections(detections: list[Detection], mapping: ClassMapping, merge_iou: float) -> list[Detection]:
    """``detections`` of scored model classes, renamed to their test classes; where a test class takes several
    model classes, suppressed across them at ``merge_iou`` (greedy by falling score, per image)."""
    test_of = mapping.test_class_of()
    several = {t for t, models in mapping.pairs if len(models) > 1}
    renamed = [Detection(d.image_id, test_of[d.label], d.score, d.x, d.y, d.w, d.h) for d in detections
               if d.label in test_of]
    kept = [d for d in renamed if d.label not in several]
    groups: dict[tuple[int, str], list[Detection]] = {}
    for d in renamed:
        if d.label in several:
            groups.setdefault((d.image_id, d.label), []).append(d)
    for group in groups.values():
        group.sort(key=lambda d: -d.score)
        boxes = np.array([[d.x, d.y, d.w, d.h] for d in group])
        iou = _xywh_iou(boxes, boxes)
        alive = np.ones(len(group), bool)
        for i in range(len(group)):
            if alive[i]:
                alive[i + 1:] &= iou[i, i + 1:] <= merge_iou
        kept += [d for d, a in zip(group, alive) if a]
    return sorted(kept, key=lambda d: (d.image_id, -d.score))


def evaluate_detections(test: DetectionSet, detections: list[Detection], mapping: ClassMapping,
                        confidence: float = 0.25, merge_iou: float = 0.7,
                        unmapped_as_regions: bool = False) -> DetectionEvaluation:
    """COCOeval of ``detections`` on ``test`` under ``mapping``; see the module's docstring. Each image's
    ``regions``, and with ``unmapped_as_regions`` its boxes of test classes no mapping scores, are crowd regions of
    every scored class: a detection on them is neither a hit nor a false positive of any class."""
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    cat_id = {t: k for k, t in enumerate(mapping.test_classes, 1)}
    gt_doc = {"images": [{"id": im.id, "width": im.width, "height": im.height, "file_name": str(im.path)}
                         for im in test.images],
              "annotations": [], "categories": [{"id": k, "name": t} for t, k in cat_id.items()]}
    gt_boxes: dict[int, Box] = {}

    def annotate(image_id: int, box: Box, category: int, crowd: bool) -> int:
        ann_id = len(gt_doc["annotations"]) + 1
        gt_doc["annotations"].append({"id": ann_id, "image_id": image_id, "category_id": category,
                                      "bbox": [box.x, box.y, box.w, box.h], "area": box.area, "iscrowd": int(crowd)})
        return ann_id

    for im in test.images:
        for box in im.boxes:
            if box.label in cat_id:
                gt_boxes[annotate(im.id, box, cat_id[box.label], box.ignore)] = box
        regions = im.regions + tuple(b for b in im.boxes if unmapped_as_regions and b.label not in cat_id)
        for box in regions:
            for category in cat_id.values():
                annotate(im.id, box, category, True)
    merged = merge_detections(detections, mapping, merge_iou)
    results = [{"image_id": d.image_id, "category_id": cat_id[d.label], "score": d.score, "bbox": [d.x, d.y, d.w, d.h]}
               for d in merged]
    with contextlib.redirect_stdout(io.StringIO()):
        gt = COCO()
        gt.dataset = gt_doc
        gt.createIndex()
        dt = gt.loadRes(results) if results else COCO()
        if not results:
            dt.dataset = {"images": gt_doc["images"], "annotations": [], "categories": gt_doc["categories"]}
            dt.createIndex()
        ev = COCOeval(gt, dt, "bbox")
        ev.evaluate()
        ev.accumulate()
        ev.summarize()
    precision = ev.eval["precision"]            # (T iou, R recall, K classes, A areas, M max dets)
    area_all, last_max = 0, len(ev.params.maxDets) - 1
    t50 = int(np.argmin(np.abs(ev.params.iouThrs - 0.5)))
    counts = {k: [0, 0, 0] for k in cat_id.values()}
    misses, wrong = [], []
    for e in ev.evalImgs:
        if e is None or e["aRng"] != ev.params.areaRng[area_all] or e["maxDet"] != ev.params.maxDets[last_max]:
            continue
        scores = np.asarray(e["dtScores"], np.float64)
        above = scores >= confidence
        matched = np.asarray(e["dtMatches"][t50]) > 0
        ignored = np.asarray(e["dtIgnore"][t50], bool)
        c = counts[e["category_id"]]
        c[0] += int((above & matched & ~ignored).sum())
        c[1] += int((above & ~matched & ~ignored).sum())
        wrong += [d for d, w in zip(e["dtIds"], above & ~matched & ~ignored) if w]
        dt_score = dict(zip(e["dtIds"], scores))
        for g, gid in enumerate(e["gtIds"]):
            if e["gtIgnore"][g]:
                continue
            by = int(e["gtMatches"][t50][g])
            if by == 0 or dt_score.get(by, 0.0) < confidence:
                c[2] += 1
                misses.append((e["image_id"], e["category_id"], gid))
    name_of = {k: t for t, k in cat_id.items()}
    boxes_of = {im.id: im.boxes + im.regions for im in test.images}
    false_positives = []
    for dt_id in wrong:
        a = dt.anns[dt_id]
        d = Detection(a["image_id"], name_of[a["category_id"]], float(a["score"]), *map(float, a["bbox"]))
        false_positives.append(classify_false_positive(d, boxes_of[d.image_id]))
    false_positives.sort(key=lambda f: (-f.detection.score, f.detection.image_id, f.detection.x, f.detection.y))
    class_results = []
    for t, models in mapping.pairs:
        k = cat_id[t] - 1
        p = precision[:, :, k, area_all, last_max]
        boxes = sum(1 for a in gt_doc["annotations"] if a["category_id"] == k + 1 and not a["iscrowd"])
        ap = float(p[p > -1].mean()) if boxes and (p > -1).any() else None
        p50 = p[t50]
        ap50 = float(p50[p50 > -1].mean()) if boxes and (p50 > -1).any() else None
        tp, fp, fn = counts[k + 1]
        mine = [f for f in false_positives if f.detection.label == t]
        kinds = {kind: sum(1 for f in mine if f.kind == kind) for kind in FP_KINDS}
        on = [f.on.label for f in mine if f.on is not None and f.kind in ("other_class", "near_other_class")]
        class_results.append(ClassResult(t, models, boxes, sum(1 for d in merged if d.label == t), ap50, ap, tp, fp, fn,
                                         kinds, {label: on.count(label) for label in sorted(set(on))}))
    return DetectionEvaluation(tuple(class_results), dict(zip(STAT_NAMES, (float(v) for v in ev.stats))), confidence,
                               len(test.images), tuple(_rank_misses(misses, gt_boxes, merged, cat_id)),
                               tuple(false_positives))


def classify_false_positive(d: Detection, boxes: tuple[Box, ...]) -> FalsePositive:
    """What false positive ``d`` lands on among its image's labelled ``boxes`` (every label; ignored boxes and crowd
    regions too, where TIDE looks at the scored boxes alone), by TIDE's rules in TIDE's order, the first that holds
    (own: its best IoU with a box of its class; other: with another label's):

    1. ``localisation``: BACKGROUND_IOU <= own <= FOREGROUND_IOU (too big, too small or shifted);
    2. ``other_class``: other >= FOREGROUND_IOU (well placed, wrong class);
    3. ``duplicate``: own >= FOREGROUND_IOU (a box a higher-scoring detection took: COCO's greedy matching would
       have given ``d`` any free one);
    4. ``background``: both <= BACKGROUND_IOU (on nothing labelled);
    5. ``near_other_class``: the rest, other between the two (TIDE's "both" error: wrong class, badly placed)."""
    box = np.array([[d.x, d.y, d.w, d.h]])

    def best(group: list[Box]) -> tuple[Box | None, float]:
        iou = _xywh_iou(box, np.array([[b.x, b.y, b.w, b.h] for b in group]).reshape(-1, 4)).ravel()
        k = int(np.argmax(iou)) if len(iou) else -1
        return (group[k], float(iou[k])) if k >= 0 else (None, 0.0)

    (own, own_iou), (other, other_iou) = best([b for b in boxes if b.label == d.label]), best(
        [b for b in boxes if b.label != d.label])
    if own is not None and BACKGROUND_IOU <= own_iou <= FOREGROUND_IOU:
        return FalsePositive(d, "localisation", own, own_iou)
    if other is not None and other_iou >= FOREGROUND_IOU:
        return FalsePositive(d, "other_class", other, other_iou)
    if own is not None and own_iou >= FOREGROUND_IOU:
        return FalsePositive(d, "duplicate", own, own_iou)
    if max(own_iou, other_iou) <= BACKGROUND_IOU:
        return FalsePositive(d, "background", None, max(own_iou, other_iou))
    return FalsePositive(d, "near_other_class", other, other_iou)


def _rank_misses(misses, gt_boxes: dict[int, Box], merged: list[Detection], cat_id: dict[str, int]) -> list[Miss]:
    """The false negatives, largest box first, each with the best IoU a detection of its class reached on it."""
    by_image: dict[tuple[int, str], list[Detection]] = {}
    for d in merged:
        by_image.setdefault((d.image_id, d.label), []).append(d)
    out = []
    for image_id, _, gid in misses:
        box = gt_boxes[gid]
        candidates = by_image.get((image_id, box.label), [])
        iou = _xywh_iou(np.array([[d.x, d.y, d.w, d.h] for d in candidates]).reshape(-1, 4),
                        np.array([[box.x, box.y, box.w, box.h]])).ravel()
        best = int(np.argmax(iou)) if len(iou) and iou.max() > 0 else None
        near = candidates[best] if best is not None else None
        out.append(Miss(image_id, box, float(iou[best]) if near else 0.0, near.score if near else None,
                        (near.x, near.y, near.w, near.h) if near else None))
    return sorted(out, key=lambda m: (-m.box.area, m.image_id, m.box.x, m.box.y))
