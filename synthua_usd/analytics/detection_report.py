"""``synthua evaluate-real``'s outputs, written as a set into the --out folder::

    metrics.json           per scored class AP50, AP50-95, TP/FP/FN, precision and recall at the fixed confidence;
                           COCOeval's 12 numbers; the mapping, the test set, the model and its training provenance
    per_class.csv          the per-class rows of metrics.json
    false_negatives.csv    every false negative at the fixed confidence, largest box first: image, class, box,
                           the best IoU a detection of its class reached on it and that detection's score
    false_negatives.png    the worst (largest) of them, cropped from their images: the missed box in red, the
                           best-overlapping detection dashed yellow
    false_positives.csv    every false positive at the fixed confidence, highest score first: image, class, score,
                           box, and what it lands on (duplicate, another class's box, its own class's box badly
                           placed, near another class's box, or nothing labelled) with that box's class and IoU
    false_positives.png    the highest-scoring of them, cropped: the detection in red, the box it lands on dashed
                           yellow
    report.html            the tables and the figure (self-contained: it refers only to files in the folder)
    detections.json        every detection, in the model's classes (COCO results format, with class names)
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np

from synthua_usd.analytics import plots
from synthua_usd.analytics.csv_text import csv_text
from synthua_usd.analytics.detection_metrics import (BACKGROUND_IOU, FOREGROUND_IOU, FP_KINDS, Detection,
                                                     DetectionEvaluation, FalsePositive, Miss)
from synthua_usd.analytics.detection_sets import DetectionSet
from synthua_usd.core.atomic import output_set, write_json_atomic, write_text_atomic
from synthua_usd.core.input_guard import Inputs

#: Every file of the report (the module's docstring says what each is).
REPORT_FILES = ("metrics.json", "per_class.csv", "false_negatives.csv", "false_negatives.png",
                "false_positives.csv", "false_positives.png", "report.html", "detections.json")

#: False negatives, and false positives, shown in each figure.
SHOWN_MISSES = 12
#: A crop shows the missed box with this much of its size around it on each side (at least MIN_CROP_PX pixels).
CROP_MARGIN = 0.5
MIN_CROP_PX = 48


def _rgb8(pixels: np.ndarray) -> np.ndarray:
    """(H, W, C) pixels as read -> (H, W, 3) uint8 for display (grey repeated, alpha dropped, 16-bit scaled)."""
    if pixels.dtype == np.uint16:
        pixels = (pixels >> 8).astype(np.uint8)
    elif pixels.dtype != np.uint8:
        pixels = (np.clip(pixels.astype(np.float64), 0, 1) * 255 + 0.5).astype(np.uint8)
    if pixels.shape[2] < 3:
        pixels = np.repeat(pixels[..., :1], 3, axis=2)
    return pixels[..., :3]


def crop_around(rgb: np.ndarray, box: tuple[float, float, float, float]) -> tuple[np.ndarray, int, int]:
    """The part of ``rgb`` (H, W, 3) around ``box`` (x, y, w, h pixels) and its top-left corner (x0, y0)."""
    x, y, w, h = box
    half = max(MIN_CROP_PX / 2, (0.5 + CROP_MARGIN) * max(w, h))
    cx, cy = x + w / 2, y + h / 2
    x0, y0 = max(0, int(cx - half)), max(0, int(cy - half))
    x1, y1 = min(rgb.shape[1], int(np.ceil(cx + half))), min(rgb.shape[0], int(np.ceil(cy + half)))
    return rgb[y0:y1, x0:x1], x0, y0


def _panels(test: DetectionSet, misses: tuple[Miss, ...]):
    by_id = {im.id: im for im in test.images}
    panels = []
    for miss in misses[:SHOWN_MISSES]:
        image = by_id[miss.image_id]
        rgb = _rgb_of(image.path)
        b = miss.box
        crop, x0, y0 = crop_around(rgb, (b.x, b.y, b.w, b.h))
        near = miss.best_box
        best = None if near is None else (near[0] - x0, near[1] - y0, near[2], near[3])
        caption = (f"{image.path.name[:28]}\n{b.label} {b.w:.0f}x{b.h:.0f} px, best IoU {miss.best_iou:.2f}"
                   + (f" @ {miss.best_score:.2f}" if miss.best_score is not None else ", no detection"))
        panels.append((crop, (b.x - x0, b.y - y0, b.w, b.h), best, _caption(caption)))
    return panels


#: How the report names each kind of false positive.
FP_KIND_TEXT = {"duplicate": "duplicates", "other_class": "on another class's box",
                "localisation": "badly placed on a box of their class", "near_other_class": "near another class's box",
                "background": "on nothing labelled"}


def _fp_caption(f: FalsePositive) -> str:
    where = {"duplicate": "a duplicate on", "other_class": "on", "localisation": "badly placed on",
             "near_other_class": "near"}
    if f.on is None:
        return f"on nothing labelled (best IoU {f.iou:.2f})"
    return f"{where[f.kind]} {f.on.label}, IoU {f.iou:.2f}"


def _fp_panels(test: DetectionSet, false_positives: tuple[FalsePositive, ...]):
    by_id = {im.id: im for im in test.images}
    panels = []
    for f in false_positives[:SHOWN_MISSES]:
        image, d = by_id[f.detection.image_id], f.detection
        crop, x0, y0 = crop_around(_rgb_of(image.path), (d.x, d.y, d.w, d.h))
        on = None if f.on is None else (f.on.x - x0, f.on.y - y0, f.on.w, f.on.h)
        caption = f"{image.path.name[:28]}  {d.label} @ {d.score:.2f}\n{_fp_caption(f)}"
        panels.append((crop, (d.x - x0, d.y - y0, d.w, d.h), on, _caption(caption)))
    return panels


def _rgb_of(path) -> np.ndarray:
    from synthua_usd.core.images import read_image

    return _rgb8(read_image(path)[0])


def _caption(text: str) -> str:
    """``text`` as a matplotlib title shows it (a ``$`` would start mathtext)."""
    return text.replace("$", r"\$")


def _fmt(value, digits: int = 3) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def _html(ev: DetectionEvaluation, about: dict, misses_shown: int, false_positives_shown: int) -> str:
    e = html.escape
    rows = [("test set", f"{about['test_set']['source']} ({about['test_set']['layout']}, split "
                         f"{about['test_set']['split'] or '-'}, {ev.images} images)"),
            ("boxes scored", {"all": "all", "pasted": "the pasted instances alone (the photos' own ignored)",
                              "photo": "the photos' own alone (the pasted instances ignored)"}
             [about["test_set"].get("scored_boxes", "all")]),
            ("model", about["model"]["weights"]), ("mapping", about["mapping_options"]),
            ("confidence for precision, recall and false negatives", f"{ev.confidence:g} (IoU 0.5)"),
            ("COCO AP (IoU 0.50:0.95) / AP50 over the scored classes",
             f"{ev.stats['AP']:.4f} / {ev.stats['AP50']:.4f}")]
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8"><title>synthua evaluate-real</title>',
           "<style>body{font-family:sans-serif;margin:1.5em;max-width:1300px}table{border-collapse:collapse;"
           "font-size:0.85em;margin:0.5em 0 1.5em}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}"
           "td:first-child,th:first-child{text-align:left}img{max-width:100%}</style></head><body>",
           "<h1>Detector on a test set</h1><p>Scored by pycocotools' COCOeval (bbox). Files: "
           '<a href="metrics.json">metrics.json</a>, <a href="per_class.csv">per_class.csv</a>, '
           '<a href="false_negatives.csv">false_negatives.csv</a>, '
           '<a href="false_positives.csv">false_positives.csv</a>, '
           '<a href="detections.json">detections.json</a>.</p>',
           "<table>"]
    out += [f"<tr><td>{e(k)}</td><td>{e(str(v))}</td></tr>" for k, v in rows]
    out.append("</table><h2>Per class</h2><table><tr><th>class</th><th>model classes</th><th>boxes</th>"
               "<th>AP50</th><th>AP50-95</th><th>precision</th><th>recall</th><th>TP</th><th>FP</th><th>FN</th></tr>")
    for c in ev.classes:
        out.append(f"<tr><td>{e(c.name)}</td><td>{e(', '.join(c.model_classes))}</td><td>{c.boxes}</td>"
                   f"<td>{_fmt(c.ap50)}</td><td>{_fmt(c.ap50_95)}</td><td>{_fmt(c.precision)}</td>"
                   f"<td>{_fmt(c.recall)}</td><td>{c.tp}</td><td>{c.fp}</td><td>{c.fn}</td></tr>")
    out.append(f"</table><h2>What the false positives land on</h2><p>At confidence {ev.confidence:g}, each false "
               f"positive by the first that holds, TIDE's rules (Bolya et al. 2020): IoU {BACKGROUND_IOU:g} to "
               f"{FOREGROUND_IOU:g} with a box of its class (badly placed); {FOREGROUND_IOU:g} or more with another "
               f"class's box; {FOREGROUND_IOU:g} or more with a box of its class that another detection took (a "
               f"duplicate); {BACKGROUND_IOU:g} or less with every labelled box (nothing labelled); else near another "
               "class's box.</p><table><tr><th>class</th>"
               "<th>FP</th>" + "".join(f"<th>{e(FP_KIND_TEXT[k])}</th>" for k in FP_KINDS)
               + "<th>other classes landed on or near</th></tr>")
    for c in ev.classes:
        on = ", ".join(f"{e(label)} {n}" for label, n in c.fp_on.items()) or "–"
        out.append(f"<tr><td>{e(c.name)}</td><td>{c.fp}</td>"
                   + "".join(f"<td>{c.fp_kinds.get(k, 0)}</td>" for k in FP_KINDS) + f"<td>{on}</td></tr>")
    out.append(f"</table><h2>Worst false negatives</h2><p>The {misses_shown} largest of {len(ev.misses)} boxes no "
               f"detection at confidence {ev.confidence:g} matched (IoU 0.5): missed box red, the best-overlapping "
               "detection of its class (any score) dashed yellow.</p>"
               '<img src="false_negatives.png" alt="worst false negatives">'
               f"<h2>Highest-scoring false positives</h2><p>The {false_positives_shown} of {len(ev.false_positives)} "
               "with the highest scores: the detection red, the box it lands on dashed yellow.</p>"
               '<img src="false_positives.png" alt="highest-scoring false positives"></body></html>')
    return "\n".join(out) + "\n"


def write_detection_report(out_dir: str | Path, test: DetectionSet, ev: DetectionEvaluation,
                           detections: list[Detection], about: dict, inputs: Inputs | None = None) -> Path:
    """Write the report of ``ev`` (``detections`` as predicted, in the model's classes; ``about``: what was scored
    with what, for metrics.json) into ``out_dir`` as a set, none of its files one of the command's ``inputs``."""
    panels, fp_panels = _panels(test, ev.misses), _fp_panels(test, ev.false_positives)  # a missing image fails here
    by_id = {im.id: im for im in test.images}
    with output_set(out_dir, inputs=inputs) as stage:
        document = about | ev.document() | {"false_negatives": len(ev.misses),
                                                  "false_positives": len(ev.false_positives)}
        write_json_atomic(stage / "metrics.json", document)
        rows = [c.row() for c in ev.classes]
        write_text_atomic(stage / "per_class.csv", csv_text(list(rows[0]), [list(r.values()) for r in rows]))
        write_text_atomic(stage / "false_negatives.csv", csv_text(
            ["image", "class", "x", "y", "w", "h", "best_iou", "best_score"],
            [[str(by_id[m.image_id].path), m.box.label, round(m.box.x, 2), round(m.box.y, 2), round(m.box.w, 2),
              round(m.box.h, 2), round(m.best_iou, 4), None if m.best_score is None else round(m.best_score, 4)]
             for m in ev.misses]))
        plots.box_panels(panels, stage / "false_negatives.png", "no false negatives")
        write_text_atomic(stage / "false_positives.csv", csv_text(
            ["image", "class", "score", "x", "y", "w", "h", "lands_on", "on_class", "iou"],
            [[str(by_id[d.image_id].path), d.label, round(d.score, 4), round(d.x, 2), round(d.y, 2), round(d.w, 2),
              round(d.h, 2), f.kind, None if f.on is None else f.on.label, round(f.iou, 4)]
             for f in ev.false_positives for d in (f.detection,)]))
        plots.box_panels(fp_panels, stage / "false_positives.png", "no false positives")
        write_json_atomic(stage / "detections.json",
                          [{"image_id": d.image_id, "file_name": str(by_id[d.image_id].path), "class_name": d.label,
                            "score": round(d.score, 5), "bbox": [round(v, 2) for v in (d.x, d.y, d.w, d.h)]}
                           for d in detections], indent=None)
        write_text_atomic(stage / "report.html", _html(ev, about, len(panels), len(fp_panels)))
    return Path(out_dir)
