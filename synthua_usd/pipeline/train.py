"""``synthua train``: an Ultralytics YOLO detector trained on a detection set, within a bounded budget.

The set is a dataset ``synthua generate`` wrote (its boxes derived by
:class:`~synthua_usd.analytics.detection_targets.DetectionTargets`: a wheelchair's box covers its user by default),
or any Ultralytics YOLO or COCO set (a few real photos, say). Its ``train`` split is trained on; its ``val`` split is
what Ultralytics validates the last epoch on (the train split when there is none). The model is built from an
architecture that ships inside the Ultralytics wheel (``yolo26n.yaml``, from scratch: nothing is downloaded), or
starts from weights (``init``, :mod:`.init_weights`): an earlier run's (fine-tuning) or an Ultralytics checkpoint
file a user has, such as a COCO-pretrained ``yolo11n.pt``. Ultralytics carries over every tensor whose name and shape
fit (a head with other classes starts anew, but for the rows of classes both name) and says how many (recorded).

The run folder, written as a set (nothing of it appears unless training finished)::

    weights.pt     the model at the end of the budget (Ultralytics' last.pt)
    train.json     what was trained on what: the set (its path, SHA-256 of what it holds, for a generated dataset
                   the SHA-256 of its manifest, its generation config and name), the classes and box policy, the
                   model and its initial weights (kind, path, SHA-256; a run's train.json or what a checkpoint
                   holds; the tensors taken from them), the budget (minutes or epochs, image size, batch), seed,
                   device, library versions, epochs done, seconds, final losses, every file Ultralytics fetched
                   (none) and every network use it tried (none: the job refuses them)
    results.csv    Ultralytics' losses per epoch
    train.log      Ultralytics' output
"""

from __future__ import annotations

import logging
import os
import platform
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from synthua_usd import __version__
from synthua_usd.analytics.detection_sets import DetectionSet, MissingSplit
from synthua_usd.analytics.detection_sources import manifest_sha256, read_detection_set, set_id
from synthua_usd.analytics.detection_targets import DetectionTargets
from synthua_usd.pipeline.detector.runner import count_in, find_detector_python, run_job
from synthua_usd.pipeline.detector.yolo_data import write_yolo_boxes
from synthua_usd.core.atomic import output_set, write_json_atomic
from synthua_usd.core.errors import InputError
from synthua_usd.core.input_guard import check_not_inputs
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import read_json
from synthua_usd.model import detection_limits as L
from synthua_usd.pipeline.init_weights import InitWeights, inspect_checkpoint, locate_init

log = logging.getLogger(__name__)

#: The files of a run folder (the module's docstring says what each is).
RUN_FILES = ("weights.pt", "train.json", "results.csv", "train.log")


def check_imgsz(imgsz: int) -> int:
    """``imgsz`` when it is in :data:`IMGSZ` and a multiple of 32 (the model's stride), else :class:`InputError`."""
    L.IMGSZ.check(imgsz, "--imgsz")
    if imgsz % 32:
        raise InputError(f"--imgsz: {imgsz}; expected a multiple of 32 in [32, 4096] (the model's stride)")
    return imgsz


@dataclass(frozen=True)
class Budget:
    """How long training may run: ``minutes`` of wall time (Ultralytics' ``time``: it stops mid-epoch when spent
    and fits its learning-rate schedule to it), or ``epochs`` when ``minutes`` is None; images resized to ``imgsz``
    pixels (long side), ``batch`` images a step; the last ``close_mosaic`` epochs without mosaic augmentation
    (Ultralytics' schedule: an epoch count, so two trainings of the same image-steps over sets of other sizes keep
    mosaic for other shares of their steps unless told)."""

    minutes: float | None = L.DEFAULT_MINUTES
    epochs: int = 300
    imgsz: int = L.DEFAULT_IMGSZ
    batch: int = L.DEFAULT_BATCH
    close_mosaic: int = L.DEFAULT_CLOSE_MOSAIC

    def __post_init__(self):
        if self.minutes is not None:
            L.MINUTES.check(self.minutes, "--minutes")
        L.EPOCHS.check(self.epochs, "--epochs")
        check_imgsz(self.imgsz)
        L.BATCH.check(self.batch, "--batch")
        L.CLOSE_MOSAIC.check(self.close_mosaic, "--close-mosaic")

    def document(self) -> dict:
        return {"minutes": self.minutes, "epochs": None if self.minutes is not None else self.epochs,
                "imgsz": self.imgsz, "batch": self.batch, "close_mosaic": self.close_mosaic}


@dataclass(frozen=True)
class TrainRequest:
    """``train_set``: a generated dataset, a YOLO data.yaml folder or a COCO .json (``fmt``, ``images_dir`` for
    COCO); ``model``: the architecture trained from scratch; ``init``: weights to start from instead, a run folder
    (or its weights.pt) or an Ultralytics checkpoint file, or an :class:`~.init_weights.InitWeights` already
    located and inspected (an experiment of many runs from one checkpoint inspects it once); ``threads``: torch threads
    (default: the cores this process may use)."""

    train_set: Path
    out_dir: Path
    budget: Budget = field(default_factory=Budget)
    targets: DetectionTargets = field(default_factory=DetectionTargets)
    model: str = L.DEFAULT_MODEL
    init: Path | InitWeights | None = None
    fmt: str = "auto"
    images_dir: Path | None = None
    device: str = "auto"
    seed: int = 0
    workers: int = 2
    threads: int | None = None
    python: Path | None = None


def _splits(request: TrainRequest) -> tuple[dict[str, DetectionSet], DetectionSet]:
    def read(split):
        return read_detection_set(request.train_set, request.fmt, split, request.images_dir, request.targets)

    train = read("train")
    if not any(not b.ignore for im in train.images for b in im.boxes):
        raise InputError(f"{shown(request.train_set)}: no boxes of {', '.join(train.names)} to train on in its "
                         f"train split; expected a set whose train split shows them")
    try:
        val = read("val")
    except MissingSplit as exc:  # no val split: Ultralytics validates the last epoch on the train split
        log.warning("%s; Ultralytics validates on the train split instead", str(exc).split("; expected")[0])
        val = train  # any other refusal of the val split (a class index out of range, a broken image) stands
    return {"train": train, "val": val}, train


def _set_document(dataset: DetectionSet, splits: dict[str, DetectionSet]) -> dict:
    doc = {"source": dataset.source, "layout": dataset.layout, "sha256": set_id(dataset),
           "images": {s: len(d.images) for s, d in splits.items()}, "boxes": dataset.counts()}
    manifest = manifest_sha256(dataset)
    if manifest is not None:
        provenance = read_json(Path(dataset.source) / "manifest.json", "a dataset manifest").get("provenance", {})
        doc |= {"dataset_id": manifest, "generation_config": provenance.get("config"),
                "generation_config_digest": provenance.get("config_digest"),
                "generated_by": {k: provenance.get(k) for k in ("synthua", "usd-core", "mitsuba", "mitsuba_variant")}}
    return doc


def train(request: TrainRequest) -> dict:
    """Train, write the run folder (see the module's docstring) and return its train.json document."""
    if request.device not in L.DEVICES:
        raise InputError(f"--device: {request.device!r}; expected one of {', '.join(L.DEVICES)}")
    given = request.init.weights if isinstance(request.init, InitWeights) else request.init
    inputs = {"TRAIN_SET": request.train_set, "--init": given, "--images": request.images_dir}
    check_not_inputs([Path(request.out_dir) / name for name in RUN_FILES], inputs)  # before the training
    splits, train_set = _splits(request)
    init = request.init if isinstance(request.init, InitWeights) else locate_init(request.init, request.model)
    python = find_detector_python(request.python)
    threads = request.threads or len(os.sched_getaffinity(0))
    names = train_set.names
    with tempfile.TemporaryDirectory(prefix="synthua-inspect-") as scratch:
        init = inspect_checkpoint(init, python, Path(scratch))
    with output_set(request.out_dir, inputs=inputs) as stage, tempfile.TemporaryDirectory(prefix="synthua-train-") as scratch:
        data_yaml = write_yolo_boxes(Path(scratch) / "data", splits, names)
        b = request.budget
        job = {"action": "train", "data": str(data_yaml), "model": init.model,
               "imgsz": b.imgsz, "epochs": b.epochs, "minutes": b.minutes, "batch": b.batch,
               "close_mosaic": b.close_mosaic, "workers": request.workers,
               "device": request.device, "seed": request.seed, "threads": threads,
               "project": str(Path(scratch) / "runs")}
        results = Path(scratch) / "runs" / "train" / "results.csv"
        progress = ({"total": round(b.minutes * 60), "unit": "s", "done": lambda seconds: round(seconds)}
                    if b.minutes is not None else
                    {"total": b.epochs, "unit": "epoch", "done": lambda seconds: count_in(results)})
        result = run_job(python, job, Path(scratch), "train", progress=progress)
        shutil.copyfile(result["weights"], stage / "weights.pt")
        results_csv = Path(result["weights"]).parents[1] / "results.csv"
        if results_csv.exists():
            shutil.copyfile(results_csv, stage / "results.csv")
        shutil.copyfile(Path(scratch) / "train.log", stage / "train.log")
        document = {
            "synthua": __version__, "python": platform.python_version(),
            "train_set": _set_document(train_set, splits), "classes": list(names),
            "targets": request.targets.document() if train_set.layout == "synthua" else None,
            "model": init.architecture, "init": init.document(result.get("transferred")),
            # close_mosaic as the trainer ran it (what was asked, unless Ultralytics changed it)
            "budget": {**b.document(), "close_mosaic": result["close_mosaic"]}, "seed": request.seed, "device": result["device"], "threads": threads,
            "versions": result["versions"], "epochs_done": result["epochs_done"],
            "epochs_planned": result["epochs_planned"], "seconds": round(result["seconds"], 1),
            "parameters": result["parameters"], "final": result["results"][-1] if result["results"] else None,
            "downloaded": result["downloaded"], "network": result["network"],
        }
        write_json_atomic(stage / "train.json", document)
    if result["network"]:
        log.warning("Ultralytics tried to reach the network during training (refused): %s",
                    ", ".join(sorted({a["host"] for a in result["network"]})))
    log.info("trained %s in %.0f s (%d epochs) -> %s", ", ".join(names), result["seconds"], result["epochs_done"],
             request.out_dir)
    return document

