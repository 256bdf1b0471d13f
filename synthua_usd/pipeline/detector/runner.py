"""Start an Ultralytics job (:mod:`.yolo_job`) in the detector's interpreter and read back its result.

The interpreter is the Python of a virtual environment holding Ultralytics, torch and torchvision
(``tools/setup_train.sh`` makes ``.venv-train`` beside the repository's ``.venv``). :func:`find_detector_python`
looks for it; :class:`DetectorUnavailable` says in one line what is missing and how to install it. Jobs run with
``YOLO_OFFLINE=1`` and Ultralytics' settings folder inside the job's own folder (nothing is written to the home
folder, and nothing is fetched), their output logged to a file beside the job.
"""

from __future__ import annotations

import functools
import json
import logging
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tqdm import tqdm

from synthua_usd.core import json_text
from synthua_usd.core.errors import SynthuaError

log = logging.getLogger(__name__)

REPO = Path(__file__).resolve().parents[3]
SCRIPT = Path(__file__).resolve().with_name("yolo_job.py")
#: Where ``tools/setup_train.sh`` puts the detector's interpreter by default (``TRAIN_VENV`` there).
DEFAULT_VENV = REPO / ".venv-train"
ENV_PYTHON = "SYNTHUA_TRAIN_PYTHON"
INSTALL_HINT = ("run tools/setup_train.sh (Ultralytics 8.4.190, torch 2.14.1 and torchvision 0.29.1 for Python 3.11 "
                "in .venv-train, about 5.9 GB), or set SYNTHUA_TRAIN_PYTHON to an interpreter that imports ultralytics")


class DetectorUnavailable(SynthuaError):
    """No interpreter with Ultralytics was found, or a job in it failed."""


def find_detector_python(explicit: str | Path | None = None) -> Path:
    """The detector's interpreter: ``explicit``, else ``$SYNTHUA_TRAIN_PYTHON``, else ``.venv-train/bin/python``
    of the repository; it must import ``ultralytics``."""
    # absolute (jobs run in their own folder) but not resolved: a venv's python is a link out of the venv
    candidate = Path(os.path.abspath(explicit or os.environ.get(ENV_PYTHON) or DEFAULT_VENV / "bin" / "python"))
    if not candidate.exists():
        raise DetectorUnavailable(f"the detector (Ultralytics) is not installed: no interpreter at {candidate}; "
                                  f"{INSTALL_HINT}")
    _probe(str(candidate))
    return candidate


@functools.lru_cache(maxsize=8)
def _probe(candidate: str) -> None:
    """Import Ultralytics in ``candidate`` once per process: the probe takes about 3 s, and an experiment of many
    trainings (tools/sim2real.py) asks for the interpreter before each one. A failure is not remembered (lru_cache
    keeps no exceptions), so an interpreter installed meanwhile is found on the next call."""
    with tempfile.TemporaryDirectory(prefix="synthua-detector-") as folder:  # Ultralytics writes settings on import
        probe = subprocess.run([candidate, "-c", "import ultralytics, torch, torchvision"], capture_output=True,
                               text=True, timeout=300, env=_environment(Path(folder)))
    if probe.returncode != 0:
        last = (probe.stderr.strip().splitlines() or ["no output"])[-1]
        raise DetectorUnavailable(f"the detector (Ultralytics) is not installed in {candidate} ({last}); "
                                  f"{INSTALL_HINT}")


def _environment(folder: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env |= {"YOLO_OFFLINE": "1", "YOLO_CONFIG_DIR": str(folder / "ultralytics-settings"), "PYTHONUNBUFFERED": "1",
            "MPLBACKEND": "Agg"}
    return env


def count_in(path: str | Path) -> int:
    """Progress a job reports in a file: the lines of ``path`` less a header (results.csv: epochs done), 0 while
    it does not exist."""
    try:
        return max(0, len(Path(path).read_text(encoding="utf-8").splitlines()) - 1)
    except OSError:
        return 0


def run_job(python: Path, job: dict, folder: Path, name: str, timeout_s: float | None = None,
            progress: dict | None = None) -> dict:
    """Run ``job`` (a :mod:`.yolo_job` document without ``result``) in ``python``, its files in ``folder``
    (``{name}.json``, ``{name}.log``, ``{name}_result.json``); return the result document.

    ``progress``: {"total": n, "unit": "s" | "epoch" | "image", "done": callable} shows a progress bar on stderr,
    ``done(seconds since the start)`` polled twice a second."""
    folder = Path(folder).resolve()
    folder.mkdir(parents=True, exist_ok=True)
    result_path = folder / f"{name}_result.json"
    job_path = folder / f"{name}.json"
    job_path.write_text(json_text.dumps(job | {"result": str(result_path)}, indent=1, ascii_only=True), encoding="utf-8")
    log_path = folder / f"{name}.log"
    log.info("detector job %s: %s (log %s)", name, job["action"], log_path)
    t0 = time.monotonic()
    with log_path.open("w", encoding="utf-8") as log_file:
        proc = subprocess.Popen([str(python), str(SCRIPT), str(job_path)], stdout=log_file, stderr=subprocess.STDOUT,
                                env=_environment(folder), cwd=folder)
        bar = None
        if progress is not None:
            bar = tqdm(total=progress["total"], unit=progress["unit"], desc=f"detector {name}",
                       disable=not sys.stderr.isatty(), leave=False)
        try:
            while proc.poll() is None:
                time.sleep(0.5)
                if bar is not None:
                    bar.update(min(bar.total, progress["done"](time.monotonic() - t0)) - bar.n)
                if timeout_s is not None and time.monotonic() - t0 > timeout_s:
                    proc.kill()
                    proc.wait()
                    raise DetectorUnavailable(f"detector job {name} ran past {timeout_s:.0f} s and was stopped")
        finally:
            if bar is not None:
                bar.close()
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    if proc.returncode != 0 or not result_path.exists():
        text = log_path.read_text(encoding="utf-8", errors="replace").strip()
        log.debug("detector job %s output:\n%s", name, text)
        tail = "; ".join(line.strip() for line in text.splitlines()[-3:])
        raise DetectorUnavailable(f"detector job {name} failed (exit {proc.returncode}): {tail[-400:]} (synthua -vv "
                                  f"shows its whole output)")
    return json.loads(result_path.read_text(encoding="utf-8"))
