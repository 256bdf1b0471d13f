"""``synthua evaluate-real``: a trained detector scored on a test set, real photos or a held-out split.

The model (a run folder of `synthua train`) predicts every image of the test set at a low confidence
(``PREDICT_CONFIDENCE``, as COCO's AP needs the whole ranking), Ultralytics' NMS at IoU 0.7 and at most 300
boxes an image; its classes are mapped to the test set's (:mod:`synthua_usd.analytics.class_mapping`) and
scored by pycocotools (:mod:`synthua_usd.analytics.detection_metrics`); the report
(:mod:`synthua_usd.analytics.detection_report`) is written as a set. A generated dataset as the test set is read
with the box policy the model was trained with (its train.json), so a held-out synthetic split is scored on the
boxes the model learnt, or with ``convention`` (a named box convention,
:mod:`synthua_usd.model.box_conventions`) in its place, the model's classes kept. A composite dataset
(`synthua composite`) can be scored on its pasted instances alone or its photos' own boxes alone (``boxes``), the
other group ignored: how a detector trained on real photos takes the pasted renders against the photos' own people.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

from synthua_usd import __version__
from synthua_usd.analytics.class_mapping import build_mapping, parse_map_options
from synthua_usd.analytics.detection_metrics import Detection, DetectionEvaluation, evaluate_detections
from synthua_usd.analytics.detection_report import REPORT_FILES, write_detection_report
from synthua_usd.analytics.detection_sources import detect_format, manifest_sha256, read_detection_set, set_id
from synthua_usd.analytics.detection_targets import DetectionTargets, targets_for
from synthua_usd.pipeline.detector.runner import count_in, find_detector_python, run_job
from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.core.input_guard import check_not_inputs
from synthua_usd.model import detection_limits as L
from synthua_usd.model.box_conventions import CONVENTIONS
from synthua_usd.pipeline.init_weights import run_weights
from synthua_usd.pipeline.train import check_imgsz

#: Confidence below which predictions are dropped before scoring (COCO's AP ranks every detection).
PREDICT_CONFIDENCE = 0.001
PREDICT_IOU = 0.7
MAX_DETECTIONS = 300


@dataclass(frozen=True)
class EvaluateRequest:
    """``model``: a run folder of `synthua train`; ``test_set`` in ``fmt`` (``split`` for YOLO and generated
    datasets, ``images_dir`` for COCO); ``maps``: ``--map`` values; ``confidence``: the one of precision, recall
    and the false negatives; ``imgsz``: prediction size (default: the training's); ``convention``: the box
    convention a generated test set's boxes are drawn by (default: the model's training's); ``boxes``: which
    boxes of a composite dataset are scored (``all``, ``pasted``, ``photo``; the others ignored)."""

    model: Path
    test_set: Path
    out_dir: Path
    maps: tuple[str, ...] = ()
    fmt: str = "auto"
    split: str | None = None
    images_dir: Path | None = None
    confidence: float = L.DEFAULT_CONFIDENCE
    merge_iou: float = 0.7
    imgsz: int | None = None
    device: str = "auto"
    threads: int | None = None
    python: Path | None = None
    convention: str | None = None
    boxes: str = "all"

    def __post_init__(self):
        if self.boxes not in L.SCORED_BOXES:
            raise InputError(f"--boxes: {self.boxes!r}; expected one of {', '.join(L.SCORED_BOXES)}")
        if self.convention is not None and self.convention not in CONVENTIONS:
            raise InputError(f"--convention: {self.convention!r}; expected one of {', '.join(CONVENTIONS)}")
        for name, value in (("--confidence", self.confidence), ("--merge-iou", self.merge_iou)):
            if not L.CONFIDENCE.contains(value) or value >= 1.0:
                raise InputError(f"{name}: {value:g}; expected a number in (0, 1)")
        if self.device not in L.DEVICES:
            raise InputError(f"--device: {self.device!r}; expected one of {', '.join(L.DEVICES)}")
        parse_map_options(self.maps)    # the syntax before anything is read; the names once the classes are known


@dataclass(frozen=True)
class EvaluateResult:
    evaluation: DetectionEvaluation
    document: dict
    out_dir: Path


def evaluate_real(request: EvaluateRequest) -> EvaluateResult:
    """Predict, score and write the report; see the module's docstring."""
    inputs = {"MODEL": request.model, "TEST_SET": request.test_set, "--images": request.images_dir}
    check_not_inputs([Path(request.out_dir) / name for name in REPORT_FILES], inputs)
    weights, about = run_weights(request.model)
    targets = DetectionTargets.from_document(about["targets"]) if about.get("targets") else DetectionTargets()
    fmt = detect_format(Path(request.test_set)) if request.fmt == "auto" else request.fmt
    if request.convention is not None:
        if fmt != "synthua":
            raise InputError(f"--convention {request.convention}: {shown(request.test_set)} is read as a {fmt} set, whose "
                             f"boxes are its own; expected a dataset `synthua generate` wrote, or no --convention")
        targets = targets_for(request.convention, targets.classes, min_height_px=targets.min_height_px)
    split = request.split or ("test" if fmt == "synthua" else None)   # never a generated dataset's train split
    test = read_detection_set(request.test_set, fmt, split, request.images_dir, targets, request.boxes)
    model_classes = tuple(about["classes"])
    mapping = build_mapping(request.maps, test.names, model_classes)
    if request.boxes != "all" and not any(test.counts()[t] for t in mapping.test_classes):
        raise InputError(f"--boxes {request.boxes}: {shown(request.test_set)} has no {request.boxes} boxes of "
                         f"{', '.join(mapping.test_classes)} in {'split ' + split if split else 'any split'}; expected "
                         f"a composite dataset with {'pastes' if request.boxes == 'pasted' else 'labelled photos'} "
                         f"of the classes scored")
    imgsz = check_imgsz(request.imgsz or int(about["budget"]["imgsz"]))
    python = find_detector_python(request.python)
    threads = request.threads or len(os.sched_getaffinity(0))
    with tempfile.TemporaryDirectory(prefix="synthua-predict-") as scratch:
        job = {"action": "predict", "weights": str(weights.resolve()),
               "images": [str(Path(im.path).resolve()) for im in test.images],
               "imgsz": imgsz, "conf": PREDICT_CONFIDENCE, "iou": PREDICT_IOU, "max_det": MAX_DETECTIONS,
               "device": request.device, "threads": threads, "batch": 8,
               "progress": str(Path(scratch) / "predicted.txt")}
        result = run_job(python, job, Path(scratch), "predict",
                         progress={"total": len(test.images), "unit": "image",
                                   "done": lambda seconds: count_in(job["progress"])})
    predicted = {str(v) for v in result["names"].values()}
    if predicted != set(model_classes):
        raise InputError(f"{weights}: predicts {', '.join(sorted(predicted))}; expected the classes of its train.json "
                         f"({', '.join(model_classes)})")
    detections = []
    for d in result["detections"]:
        image = test.images[int(d["image"])]
        x1, y1, x2, y2 = d["xyxy"]
        detections.append(Detection(image.id, d["class_name"], float(d["score"]), x1, y1, x2 - x1, y2 - y1))
    evaluation = evaluate_detections(test, detections, mapping, request.confidence, request.merge_iou,
                                     unmapped_as_regions=request.boxes != "all")
    document = {
        "synthua": __version__,
        "test_set": {"source": test.source, "layout": test.layout, "split": test.split, "images": len(test.images),
                     "sha256": set_id(test), "dataset_id": manifest_sha256(test), "boxes": test.counts(),
                     "targets": targets.document() if test.layout == "synthua" else None,
                     "scored_boxes": request.boxes},
        "model": {"weights": str(weights), "classes": list(model_classes), "train": about},
        "mapping": mapping.document(), "mapping_options": mapping.text(),
        "prediction": {"confidence_floor": PREDICT_CONFIDENCE, "nms_iou": PREDICT_IOU, "max_det": MAX_DETECTIONS,
                       "imgsz": imgsz, "device": result["device"], "seconds": round(result["seconds"], 2),
                       "merge_iou": request.merge_iou},
        "versions": result["versions"], "downloaded": result["downloaded"], "network": result["network"],
    }
    write_detection_report(request.out_dir, test, evaluation, detections, document, inputs)
    return EvaluateResult(evaluation, document | evaluation.document(), Path(request.out_dir))
