"""Semantic-segmentation metrics from a confusion matrix, as SYNTHUA-DT defines them (Section 2.6.4).

For class c with ground-truth mask M_c and predicted mask M̂_c over the evaluated pixels:
TP = |M_c ∩ M̂_c|, FP = |M̂_c \\ M_c|, FN = |M_c \\ M̂_c|, TN = the remaining evaluated pixels, and

* IoU_c = TP / (TP + FP + FN)            (= |M_c ∩ M̂_c| / |M_c ∪ M̂_c|)
* precision_c = TP / (TP + FP)           (= |M_c ∩ M̂_c| / |M̂_c|)
* recall_c = TP / (TP + FN)              (= |M_c ∩ M̂_c| / |M_c|)
* F1_c = 2 precision recall / (precision + recall) = 2 TP / (2 TP + FP + FN)
* accuracy_c = (TP + TN) / (TP + FP + FN + TN): the class's one-vs-rest pixel accuracy. The paper does not
  define its per-class accuracy; its values (98-99.6 %, above each class's recall) fit this one.

A ratio whose denominator is 0 is undefined (None). Dataset figures: pixel accuracy = trace / total;
mean IoU over the classes whose IoU is defined (present in the ground truth or the predictions);
frequency-weighted IoU = sum_c (|M_c| / total) IoU_c over classes with ground-truth pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def confusion_matrix(gt: np.ndarray, pred: np.ndarray, classes: int, ignore: int | None = 0) -> np.ndarray:
    """(classes, classes) int64 counts, rows ground truth, columns prediction, of the pixels of ``gt`` and
    ``pred`` (same shape, integer ids in [0, classes)) whose ground truth is not ``ignore``."""
    g = np.asarray(gt, np.int64).ravel()
    p = np.asarray(pred, np.int64).ravel()
    if ignore is not None:
        keep = g != ignore
        g, p = g[keep], p[keep]
    return np.bincount(g * classes + p, minlength=classes * classes).reshape(classes, classes)


def _ratio(num: float, den: float) -> float | None:
    return float(num / den) if den > 0 else None


@dataclass(frozen=True)
class ClassMetrics:
    tp: int
    fp: int
    fn: int
    tn: int
    iou: float | None
    precision: float | None
    recall: float | None
    f1: float | None
    accuracy: float | None


def class_metrics(matrix: np.ndarray) -> list[ClassMetrics]:
    """Per-class metrics (module docstring) of a confusion matrix, one per row."""
    cm = np.asarray(matrix, np.int64)
    total = int(cm.sum())
    out = []
    for c in range(cm.shape[0]):
        tp = int(cm[c, c])
        fp = int(cm[:, c].sum()) - tp
        fn = int(cm[c, :].sum()) - tp
        tn = total - tp - fp - fn
        out.append(ClassMetrics(tp, fp, fn, tn, _ratio(tp, tp + fp + fn), _ratio(tp, tp + fp), _ratio(tp, tp + fn),
                                _ratio(2 * tp, 2 * tp + fp + fn), _ratio(tp + tn, total)))
    return out


def summary(matrix: np.ndarray, per_class: list[ClassMetrics], exclude: tuple[int, ...] = (0,)) -> dict:
    """Pixel accuracy, mean IoU and frequency-weighted IoU; classes in ``exclude`` (void) are left out of the
    means."""
    cm = np.asarray(matrix, np.int64)
    total = int(cm.sum())
    ious = [m.iou for c, m in enumerate(per_class) if c not in exclude and m.iou is not None]
    gt_pixels = cm.sum(axis=1)
    fw = sum(gt_pixels[c] / total * m.iou for c, m in enumerate(per_class)
             if c not in exclude and gt_pixels[c] > 0 and m.iou is not None) if total else None
    return {"pixels": total, "pixel_accuracy": _ratio(int(np.trace(cm)), total),
            "mean_iou": float(np.mean(ious)) if ious else None, "mean_iou_classes": len(ious),
            "frequency_weighted_iou": None if fw is None else float(fw)}
