"""The weights a detector's training starts from (``synthua train --init``, ``tools/sim2real.py --init``).

Three kinds, each recorded in the run's train.json (``init``) with the file's path and SHA-256:

``scratch``
    no weights: the architecture (``yolo26n.yaml``) ships inside the Ultralytics wheel and starts from random
    values. What the project's own sim-to-real figures use, since the machines they are measured on cannot download.
``run``
    a run folder of ``synthua train`` (or its ``weights.pt``): fine-tuning; its train.json is kept in the record.
``checkpoint``
    any Ultralytics detection checkpoint (``.pt``) on this machine, e.g. a user's COCO-pretrained ``yolo11n.pt`` or
    ``yolo26n.pt``: the usual start of a training. Its architecture is the checkpoint's; the detector's interpreter
    loads it once before training (:func:`inspect_checkpoint`) to say what it is (task, classes, architecture, the
    Ultralytics version that saved it, the data it was trained on) and to refuse, in one line, a file Ultralytics
    cannot load or that is not a detector.

Nothing is downloaded: a named file that is not on this machine is refused before anything runs (Ultralytics would
otherwise try to fetch ``yolo11n.pt`` by its name). Loading a ``.pt`` file unpickles it, as Ultralytics always does:
start only from checkpoints you trust.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from synthua_usd.pipeline.detector.runner import run_job
from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import read_json
from synthua_usd.dataset.manifest import sha256_file
from synthua_usd.model import detection_limits as L

KINDS = ("scratch", "run", "checkpoint")
_EXPECTED = ("expected a run folder of `synthua train` or an Ultralytics checkpoint file (.pt, e.g. a COCO-pretrained "
             "yolo11n.pt) on this machine")


def run_weights(path: str | Path) -> tuple[Path, dict]:
    """The weights and train.json of a run folder of `synthua train` (or of its weights.pt)."""
    path = Path(path)
    folder = path.parent if path.suffix == ".pt" else path
    weights, about = folder / "weights.pt", folder / "train.json"
    if not weights.is_file() or not about.is_file():
        raise InputError(f"{shown(path)}: no weights.pt and train.json; expected a run folder written by "
                         f"`synthua train`")
    return weights, read_json(about, "a run's train.json")


@dataclass(frozen=True)
class InitWeights:
    """Where a training starts: ``kind`` one of :data:`KINDS`; ``weights`` the ``.pt`` file (absolute; None from
    scratch) and its ``sha256``; ``architecture`` the model file of a start from scratch (else None: the weights
    carry theirs); ``run`` a run's train.json; ``checkpoint`` what :func:`inspect_checkpoint` found."""

    kind: str
    weights: Path | None = None
    sha256: str | None = None
    architecture: str | None = None
    run: dict | None = None
    checkpoint: dict | None = None

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind {self.kind!r}; expected one of {', '.join(KINDS)}")

    @property
    def model(self) -> str:
        """What Ultralytics builds the model from: the architecture file, or the weights' absolute path."""
        return self.architecture if self.weights is None else str(self.weights)

    def document(self, transferred: list[int] | None = None) -> dict | None:
        """train.json's ``init``: None from scratch (its ``model`` names the architecture), else the kind, file,
        SHA-256, what it is, and ``transferred``: Ultralytics' count of the tensors the model took from it."""
        if self.kind == "scratch":
            return None
        doc = {"kind": self.kind, "weights": str(self.weights), "sha256": self.sha256}
        doc |= {"run": self.run} if self.kind == "run" else {"checkpoint": self.checkpoint}
        return doc | {"transferred": transferred}


def describe(init: dict | None, model: str | None = None) -> str:
    """A train.json's ``init`` (and ``model``) in a few words, for tables: ``scratch (yolo26n.yaml)``,
    ``run a_synthetic_s0 (sha256 1a2b3c4d)``, ``checkpoint yolo11n.pt (yolo11n.yaml, 80 classes, sha256 ...)``."""
    if init is None:
        return f"scratch ({model or L.DEFAULT_MODEL})"
    sha = (init.get("sha256") or "")[:8]
    if init["kind"] == "run":
        return f"run {Path(init['weights']).parent.name} (sha256 {sha})"
    about = init.get("checkpoint") or {}
    what = ", ".join(x for x in (about.get("architecture"), f"{len(about.get('names') or {})} classes",
                                 f"trained on {about['trained_on']}" if about.get("trained_on") else None) if x)
    return f"checkpoint {Path(init['weights']).name} ({what}, sha256 {sha})"


def locate_init(path: str | Path | None, architecture: str = L.DEFAULT_MODEL) -> InitWeights:
    """The kind of start ``path`` names (None: from scratch with ``architecture``), its file and SHA-256; a path that
    is not on this machine, or neither a run folder nor a ``.pt`` file, raises :class:`InputError` (nothing is
    fetched). A checkpoint still needs :func:`inspect_checkpoint`."""
    if path is None:
        return InitWeights("scratch", architecture=architecture)
    path = Path(path)
    if not path.exists():
        raise InputError(f"--init: {shown(path)}: not found; {_EXPECTED} (nothing is downloaded: put the file there "
                         f"first)")
    if path.is_dir() or (path.name == "weights.pt" and (path.parent / "train.json").is_file()):
        weights, about = run_weights(path)
        return InitWeights("run", weights.resolve(), sha256_file(weights), run=about)
    if not path.is_file() or path.suffix.lower() != ".pt":
        raise InputError(f"--init: {shown(path)}: {'not a regular file' if not path.is_file() else 'not a .pt file'}; "
                         f"{_EXPECTED}")
    return InitWeights("checkpoint", path.resolve(), sha256_file(path))


def inspect_checkpoint(init: InitWeights, python: Path, scratch: Path) -> InitWeights:
    """``init`` (a ``checkpoint``) with what the detector's interpreter ``python`` finds in it (job files in
    ``scratch``); one that Ultralytics cannot load, or that is not a detector, raises :class:`InputError`."""
    if init.kind != "checkpoint" or init.checkpoint is not None:      # nothing to inspect, or inspected already
        return init
    found = run_job(python, {"action": "inspect", "weights": str(init.weights)}, scratch, "inspect")
    if "error" in found:
        raise InputError(f"--init: {shown(init.weights)}: Ultralytics cannot load it ({found['error']}); expected an "
                         f"Ultralytics checkpoint file (.pt) such as yolo11n.pt")
    if found["task"] != "detect":
        raise InputError(f"--init: {shown(init.weights)}: an Ultralytics {found['task']} checkpoint; expected a "
                         f"detection checkpoint (task detect, e.g. yolo11n.pt, not -seg, -cls or -pose)")
    about = {k: found[k] for k in ("task", "names", "architecture", "scale", "parameters", "saved_with", "date",
                                   "trained_on", "epochs")}
    about["names"] = [about["names"][k] for k in sorted(about["names"], key=int)]
    return replace(init, checkpoint=about)
