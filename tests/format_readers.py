"""The real dataset readers set up the way the format tests run them: cityscapesScripts' pixel-level evaluation
with synthua's label table patched in, and pycocotools' COCOeval of a ground truth against itself.

Used by tests/dataset/formats/ (writers on hand-made records) and tests/pipeline/test_generate_readers.py (the
files of a whole ``synthua generate`` run).
"""

from __future__ import annotations

import contextlib
import io

import numpy as np

from synthua_usd.dataset.formats.cityscapes import cityscapes_labels
from synthua_usd.model.taxonomy import ClassMap


def cityscapes_evaluation(monkeypatch, class_map: ClassMap):
    """cityscapesScripts' pixel-level evaluation module with synthua's label table patched in (as its README
    says to do for a dataset with other labels: edit labels.py), its options set for a quiet run.

    Returns the module and the patched labels; run it as ``ev.evaluateImgLists(preds, gts, ev.args)``.
    """
    from cityscapesscripts.evaluation import evalPixelLevelSemanticLabeling as ev
    from cityscapesscripts.helpers.labels import Label

    labels = [Label(**entry) for entry in cityscapes_labels(class_map)]
    tables = {"labels": labels, "name2label": {l.name: l for l in labels}, "id2label": {l.id: l for l in labels},
              "trainId2label": {l.trainId: l for l in reversed(labels)}, "category2labels": {}}
    for l in labels:
        tables["category2labels"].setdefault(l.category, []).append(l)
    for name, value in tables.items():
        monkeypatch.setattr(ev, name, value)
    # cityscapesScripts 2.3 calls np.in1d, which NumPy 2.4 removed; np.isin is its documented replacement.
    monkeypatch.setattr(np, "in1d", np.isin, raising=False)
    args = ev.args
    for name, value in (("quiet", True), ("JSONOutput", False), ("evalInstLevelScore", True),
                        ("evalLabels", list(args.evalLabels)),  # evaluateImgLists rewrites it: restore after
                        ("avgClassSize", {l.name: 100.0 for l in labels if l.hasInstances})):
        monkeypatch.setattr(args, name, value)
    return ev, labels


def coco_self_evaluation(gt, annotations: list[dict]) -> dict[str, list[float]]:
    """COCOeval's stats for "bbox" and "segm" of ``gt`` (a pycocotools COCO) against ``annotations`` given as
    detections with score 1, run quietly: 1.0 for AP and AP50 when the annotations are ``gt``'s own."""
    from pycocotools.cocoeval import COCOeval

    dets = [{"image_id": a["image_id"], "category_id": a["category_id"], "segmentation": a["segmentation"],
             "bbox": a["bbox"], "score": 1.0} for a in annotations]
    stats = {}
    with contextlib.redirect_stdout(io.StringIO()):
        dt = gt.loadRes(dets)
        for kind in ("bbox", "segm"):
            ev = COCOeval(gt, dt, kind)
            ev.evaluate()
            ev.accumulate()
            ev.summarize()
            stats[kind] = [float(s) for s in ev.stats]
    return stats


def coco_keypoint_self_evaluation(gt) -> dict[str, float]:
    """COCOeval's keypoint AP (OKS) of ``gt`` (a pycocotools COCO) against its own keypoints as detections
    with score 1, per category that has labelled keypoints on an annotation that is not a crowd (an ignore
    region, iscrowd 1: the detections on those are passed too, and COCOeval must neither reward nor penalise
    them), each with its own OKS sigmas (:func:`synthua_usd.model.keypoint_classes.sigmas`: COCOeval takes one
    sigma array for all the categories it evaluates); 1.0 for each when the format is right."""
    from pycocotools.cocoeval import COCOeval

    from synthua_usd.model.keypoint_classes import sigmas

    dets = [{"image_id": a["image_id"], "category_id": a["category_id"], "keypoints": a["keypoints"], "score": 1.0}
            for a in gt.dataset["annotations"] if a.get("num_keypoints")]
    out = {}
    with contextlib.redirect_stdout(io.StringIO()):
        if not dets:
            return out
        dt = gt.loadRes(dets)
        scored = {a["category_id"] for a in gt.dataset["annotations"] if a.get("num_keypoints") and not a["iscrowd"]}
        for cat in gt.loadCats(sorted(scored)):
            ev = COCOeval(gt, dt, "keypoints")
            ev.params.catIds = [cat["id"]]
            ev.params.kpt_oks_sigmas = sigmas(cat["name"])
            ev.evaluate()
            ev.accumulate()
            ev.summarize()
            out[cat["name"]] = float(ev.stats[0])
    return out
