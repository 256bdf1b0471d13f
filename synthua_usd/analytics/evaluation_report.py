"""``synthua eval``'s outputs, written as a set into the --out folder::

    metrics.csv      per class: id, name, ground-truth and predicted pixels, TP, FP, FN, TN, accuracy, IoU,
                     precision, recall, F1 (ratios in [0, 1], empty when undefined)
    metrics.json     the same, with pixel accuracy, mean IoU, frequency-weighted IoU (and COCO mAP when given)
    confusion.csv    rows ground truth, columns prediction, pixel counts, classes by id
    confusion.png    the row-normalised confusion matrix of the classes that occur
    coco.json        COCOeval's numbers, when COCO results were evaluated
"""

from __future__ import annotations

from pathlib import Path

from synthua_usd.analytics import plots
from synthua_usd.analytics.csv_text import csv_text
from synthua_usd.analytics.evaluation import SemanticEvaluation
from synthua_usd.core.atomic import output_set, write_json_atomic, write_text_atomic
from synthua_usd.core.input_guard import Inputs

#: Every file the report may hold (the module's docstring says what each is).
EVALUATION_FILES = ("metrics.csv", "metrics.json", "confusion.csv", "confusion.png", "coco.json")


def class_rows(ev: SemanticEvaluation) -> list[dict]:
    """One row per class of the class map (``metrics.csv``)."""
    gt_px = ev.matrix.sum(axis=1)
    pred_px = ev.matrix.sum(axis=0)
    rows = []
    for c in ev.class_map.classes:
        m = ev.per_class[c.id]
        rows.append({"id": c.id, "name": c.name, "gt_pixels": int(gt_px[c.id]), "pred_pixels": int(pred_px[c.id]),
                     "tp": m.tp, "fp": m.fp, "fn": m.fn, "tn": m.tn, "accuracy": m.accuracy, "iou": m.iou,
                     "precision": m.precision, "recall": m.recall, "f1": m.f1})
    return rows


def write_evaluation(out_dir: str | Path, semantic: SemanticEvaluation | None, coco: dict | None,
                     inputs: Inputs | None = None) -> Path:
    """Write the report of ``semantic`` and/or ``coco`` into ``out_dir`` as a set, none of its files one of the
    command's ``inputs``."""
    with output_set(out_dir, inputs=inputs) as stage:
        document: dict = {}
        if semantic is not None:
            rows = class_rows(semantic)
            write_text_atomic(stage / "metrics.csv", csv_text(list(rows[0]), [list(r.values()) for r in rows]))
            names = [c.name for c in semantic.class_map.classes]
            ids = [c.id for c in semantic.class_map.classes]
            sub = semantic.matrix[ids][:, ids]
            write_text_atomic(stage / "confusion.csv",
                              csv_text(["gt \\ pred"] + names, [[n] + [int(v) for v in sub[i]] for i, n in enumerate(names)]))
            plots.confusion_heatmap(names, sub, stage / "confusion.png")
            document |= {"images": semantic.images, "void": "pixels whose ground truth is unlabelled are not evaluated",
                         "summary": semantic.summary, "classes": rows,
                         "ignored_predictions": list(semantic.ignored_predictions)}
        if coco is not None:
            write_json_atomic(stage / "coco.json", coco)
            document["coco"] = coco
        write_json_atomic(stage / "metrics.json", document)
    return Path(out_dir)
