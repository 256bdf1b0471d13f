"""Run one Ultralytics YOLO job inside the detector's interpreter (``.venv-train``): train, or predict.

Started by :mod:`synthua_usd.pipeline.detector.runner` as ``python yolo_job.py JOB.json``; it imports only the
standard library, torch and Ultralytics (never synthua, whose dependencies that interpreter does not hold), reads
the job, writes the result document the job names, and exits 0, or 1 with the reason as its last line of stderr.

Nothing is downloaded: a model is built from an architecture file that ships inside the Ultralytics wheel
(``yolo26n.yaml``: no weights), or loaded from a ``.pt`` file on this machine (a previous job's, or a user's
checkpoint, always passed as an absolute path that exists: a bare name such as ``yolo11n.pt`` would make Ultralytics
fetch it); ``YOLO_OFFLINE`` is set by the runner, plots are off, on CUDA mixed precision is bfloat16, which skips
Ultralytics' AMP check (that check downloads pretrained weights), and the font Ultralytics' dataset check looks for
(``Arial.ttf``, which it would otherwise try to fetch on every training) is matplotlib's bundled DejaVu Sans, linked
into the job's settings folder. As a last guard, the job refuses every network connection and name lookup
(``socket.getaddrinfo``, ``connect`` on an internet socket) and lists each attempt in its result (``network``,
expected: empty), beside every file that appeared in Ultralytics' weights folder (``downloaded``, expected: none).

Job documents (JSON)::

    {"action": "train", "data": "data.yaml", "model": "yolo26n.yaml" | "weights.pt", "imgsz": 320,
     "epochs": 100, "minutes": 30 | null, "batch": 16, "close_mosaic": 10, "workers": 2, "device": "cpu" | "cuda" | "auto",
     "seed": 0, "threads": 2, "project": "DIR", "result": "train_result.json"}
    {"action": "predict", "weights": "last.pt", "images": ["a.png", ...], "imgsz": 320, "conf": 0.001,
     "iou": 0.7, "max_det": 300, "device": "cpu", "threads": 2, "batch": 8, "progress": "done.txt" | null,
     "result": "detections.json"}
    {"action": "inspect", "weights": "/abs/yolo11n.pt", "result": "inspect.json"}
    {"action": "versions", "result": "versions.json"}

``inspect`` loads a checkpoint as training would and reports what it is (task, classes, architecture, the
Ultralytics version and date it was saved with, the data it was trained on), or ``error``: why Ultralytics cannot
load it.
"""

from __future__ import annotations

import csv
import json
import logging
import re
import socket
import sys
import time
from importlib import metadata
from pathlib import Path

PACKAGES = ("ultralytics", "torch", "torchvision", "numpy", "opencv-python-headless")


def versions() -> dict:
    """Installed versions of the packages the detector runs on, and what accelerator torch sees."""
    import torch

    out = {}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    out["python"] = sys.version.split()[0]
    out["cuda_available"] = bool(torch.cuda.is_available())
    out["cuda_device"] = torch.cuda.get_device_name(0) if torch.cuda.is_available() else None
    return out


def _device(asked: str) -> str:
    import torch

    if asked == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    if asked == "cuda" and not torch.cuda.is_available():
        raise SystemExit("device cuda asked for, but torch sees no CUDA device")
    return asked


def refuse_network() -> list[dict]:
    """Refuse every name lookup and internet connection of this process from now on; the returned list fills with
    one entry per attempt (what was asked, the host), so that a job reports what Ultralytics tried to fetch.
    Local sockets (``AF_UNIX``: the data loader's workers) are left alone."""
    attempts: list[dict] = []
    lookup, connect = socket.getaddrinfo, socket.socket.connect

    def refused_lookup(host, *args, **kwargs):
        attempts.append({"call": "getaddrinfo", "host": str(host)})
        raise socket.gaierror(socket.EAI_NONAME, f"network refused by synthua's detector job (lookup of {host})")

    def refused_connect(self, address):
        if self.family in (socket.AF_INET, socket.AF_INET6):
            attempts.append({"call": "connect", "host": str(address[0])})
            raise OSError(f"network refused by synthua's detector job (connect to {address[0]})")
        return connect(self, address)

    socket.getaddrinfo, socket.socket.connect = refused_lookup, refused_connect
    return attempts


def local_fonts() -> None:
    """Ultralytics' dataset check looks for ``Arial.ttf`` (``Arial.Unicode.ttf`` for other scripts) in its settings
    folder and fetches it when absent: link matplotlib's bundled DejaVu Sans there under both names."""
    import matplotlib
    from ultralytics.utils import USER_CONFIG_DIR

    font = Path(matplotlib.get_data_path()) / "fonts" / "ttf" / "DejaVuSans.ttf"
    USER_CONFIG_DIR.mkdir(parents=True, exist_ok=True)
    for name in ("Arial.ttf", "Arial.Unicode.ttf"):
        link = USER_CONFIG_DIR / name
        if font.is_file() and not link.exists():
            link.symlink_to(font)


class _Transferred(logging.Handler):
    """Catches Ultralytics' own count of the tensors a model took from its initial weights."""

    PATTERN = re.compile(r"Transferred (\d+)/(\d+) items")

    def __init__(self):
        super().__init__(logging.INFO)
        self.counts: list[int] | None = None

    def emit(self, record):
        found = self.PATTERN.search(record.getMessage())
        if found:
            self.counts = [int(found.group(1)), int(found.group(2))]


def _weights_files() -> set[str]:
    from ultralytics.utils import SETTINGS

    folder = Path(SETTINGS["weights_dir"])
    return {str(p) for p in folder.rglob("*") if p.is_file()} if folder.is_dir() else set()


def train(job: dict) -> dict:
    import torch
    from ultralytics import YOLO
    from ultralytics.utils import LOGGER

    torch.set_num_threads(int(job["threads"]))
    device = _device(job["device"])
    local_fonts()
    model = YOLO(job["model"])
    # Ultralytics 8.4 drops a loaded checkpoint's weights when told pretrained=False: say True exactly when the
    # model comes from weights (an architecture file has none, and True would not fetch any for it either way)
    from_weights = str(job["model"]).lower().endswith(".pt")
    minutes = job.get("minutes")
    transferred = _Transferred()
    LOGGER.addHandler(transferred)
    t0 = time.perf_counter()
    model.train(data=job["data"], imgsz=int(job["imgsz"]), epochs=int(job["epochs"]),
                time=None if minutes is None else float(minutes) / 60.0, batch=int(job["batch"]),
                workers=int(job["workers"]), device=device, seed=int(job["seed"]), deterministic=True,
                pretrained=from_weights, amp="bf16" if device == "cuda" else False, plots=False, val=False,
                project=str(Path(job["project"]).resolve()), name="train", exist_ok=True, verbose=False,
                cache=bool(job.get("cache", False)), patience=0,
                close_mosaic=int(job["close_mosaic"]))
    seconds = time.perf_counter() - t0
    LOGGER.removeHandler(transferred)
    trainer = model.trainer
    run_dir = Path(trainer.save_dir)
    rows = []
    results_csv = run_dir / "results.csv"
    if results_csv.exists():
        with results_csv.open(newline="") as f:
            rows = [{k.strip(): v.strip() for k, v in row.items()} for row in csv.DictReader(f)]
    return {"weights": str(Path(trainer.last).resolve()), "device": device, "seconds": seconds,
            "epochs_done": len(rows), "epochs_planned": int(trainer.epochs), "results": rows,
            "close_mosaic": int(trainer.args.close_mosaic),
            "parameters": sum(p.numel() for p in model.model.parameters()),
            "transferred": transferred.counts if from_weights else None}


def inspect(job: dict) -> dict:
    """What the checkpoint ``job["weights"]`` holds, loaded as :func:`train` loads it; ``error`` if it cannot be."""
    from ultralytics import YOLO

    try:
        model = YOLO(job["weights"])
    except Exception as exc:  # noqa: BLE001 - any failure of Ultralytics' loader is the answer
        return {"error": f"{type(exc).__name__}: {str(exc).strip().splitlines()[0] if str(exc).strip() else ''}"[:300]}
    ckpt = model.ckpt or {}
    yaml = getattr(model.model, "yaml", None) or {}
    train_args = ckpt.get("train_args") or {}
    return {"task": model.task, "names": {int(k): str(v) for k, v in model.names.items()},
            "architecture": Path(str(yaml.get("yaml_file", ""))).name or None, "scale": yaml.get("scale"),
            "parameters": sum(p.numel() for p in model.model.parameters()),
            "saved_with": ckpt.get("version"), "date": ckpt.get("date"),
            "trained_on": Path(str(train_args["data"])).name if train_args.get("data") else None,
            "epochs": train_args.get("epochs")}


def predict(job: dict) -> dict:
    import torch
    from ultralytics import YOLO

    torch.set_num_threads(int(job["threads"]))
    device = _device(job["device"])
    model = YOLO(job["weights"])
    names = {int(k): str(v) for k, v in model.names.items()}
    images = list(job["images"])
    batch = max(1, int(job.get("batch", 8)))
    detections = []
    t0 = time.perf_counter()
    progress = Path(job["progress"]) if job.get("progress") else None
    if progress is not None:
        progress.write_text("images done\n", encoding="utf-8")
    for start in range(0, len(images), batch):
        chunk = images[start:start + batch]
        results = model.predict(chunk, imgsz=int(job["imgsz"]), conf=float(job["conf"]), iou=float(job["iou"]),
                                max_det=int(job["max_det"]), device=device, verbose=False)
        for offset, result in enumerate(results):
            boxes = result.boxes
            xyxy = boxes.xyxy.cpu().numpy().tolist()
            for (x1, y1, x2, y2), score, cls in zip(xyxy, boxes.conf.cpu().tolist(), boxes.cls.cpu().tolist()):
                detections.append({"image": start + offset, "class_name": names[int(cls)], "score": float(score),
                                   "xyxy": [float(x1), float(y1), float(x2), float(y2)]})
        if progress is not None:  # one line an image: the runner's progress bar counts them
            with progress.open("a", encoding="utf-8") as f:
                f.write("".join(f"{start + k}\n" for k in range(len(chunk))))
    return {"names": names, "device": device, "seconds": time.perf_counter() - t0, "detections": detections}


ACTIONS = {"train": train, "predict": predict, "inspect": inspect, "versions": lambda job: {}}


def main(argv: list[str]) -> int:
    job = json.loads(Path(argv[1]).read_text(encoding="utf-8"))
    attempts = refuse_network()
    before = _weights_files() if job["action"] != "versions" else set()
    result = ACTIONS[job["action"]](job)
    result["versions"] = versions()
    result["downloaded"] = sorted(_weights_files() - before) if job["action"] != "versions" else []
    result["network"] = attempts
    Path(job["result"]).write_text(json.dumps(result, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
