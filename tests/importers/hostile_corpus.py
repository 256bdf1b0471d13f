"""Shared pieces of the hostile-input suite of the importers, documents and helper commands.

Hostile files are made by the tests in ``tmp_path`` from the small valid files of ``tests/data/valid``.
Most cases run ``synthua`` in-process (``synthua_usd.cli.main.main``, milliseconds instead of the 1-2 s of
a subprocess) under an alarm and a memory cap; a representative subset, and the hangs a signal cannot
interrupt (a regex inside the C engine), run as subprocesses (``run_limited``: like tests/hostile.py's
``run_synthua``, under a memory cap).
"""

from __future__ import annotations

import copy
import json
import resource
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import DATA
from hostile import CASE_TIMEOUT_S, Result, assert_refused, tree_state
from synthua_usd.cli.main import main

CITYJSON = DATA / "valid" / "lod2_house.city.json"
GEOJSON = DATA / "valid" / "footprints.geojson"
CLASSMAP = DATA / "valid" / "classmap_small.json"
RULES = DATA / "valid" / "mesh_rules.json"
OBJ = DATA / "valid" / "street.obj"
MTL = DATA / "valid" / "street.mtl"
GCP_SURVEYED = DATA / "valid" / "gcp_surveyed.csv"
GCP_MODEL = DATA / "valid" / "gcp_model.csv"

#: Address space a subprocess case may use: a runaway allocation fails instead of swapping the machine.
MEMORY_CAP_BYTES = 6 * 2**30


def doc(path: Path) -> dict:
    """A fresh copy of a valid JSON document to spoil."""
    return copy.deepcopy(json.loads(path.read_text(encoding="utf-8")))


def write(path: Path, content) -> Path:
    """Write ``content`` (bytes, str, or a JSON-able value) to ``path``; returns ``path``."""
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif isinstance(content, str):
        path.write_text(content, encoding="utf-8")
    else:
        path.write_text(json.dumps(content, allow_nan=True), encoding="utf-8")
    return path


def mesh_input(folder: Path) -> Path:
    """The small valid OBJ (with its MTL) copied into ``folder``."""
    shutil.copy(MTL, folder / MTL.name)
    return Path(shutil.copy(OBJ, folder / OBJ.name))


class Hang(BaseException):
    """Raised by the alarm of an in-process case that ran past its time limit."""


#: Address space an in-process case may add to the test process's: a runaway allocation (reading
#: /dev/zero, believing a header's point count) fails fast with MemoryError instead of swapping.
INPROCESS_EXTRA_BYTES = 3 * 2**30


def _address_space() -> int:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[0]) * resource.getpagesize()


def run_inprocess(capsys, *args, timeout: float = CASE_TIMEOUT_S) -> Result:
    """``synthua ARGS...`` in this process, under an alarm and a memory cap: a case still running after
    ``timeout`` fails as a hang (blocking system calls such as opening a FIFO are interrupted too), one
    that allocates without bound fails with MemoryError (reported as a message that names no file)."""
    fired = []

    def alarm(signum, frame):
        fired.append(True)
        raise Hang(f"still running after {timeout} s")

    capsys.readouterr()
    previous = signal.signal(signal.SIGALRM, alarm)
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = _address_space() + INPROCESS_EXTRA_BYTES
    resource.setrlimit(resource.RLIMIT_AS, (cap if hard == resource.RLIM_INFINITY else min(cap, hard), hard))
    signal.setitimer(signal.ITIMER_REAL, timeout)
    t0 = time.perf_counter()
    try:
        code = main([str(a) for a in args])
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
    seconds = time.perf_counter() - t0
    captured = capsys.readouterr()
    if fired:
        raise AssertionError(f"synthua {' '.join(map(str, args))} hung: still running after {timeout} s")
    return Result(code, captured.out, captured.err, seconds)


def run_limited(*args, timeout: float = CASE_TIMEOUT_S, cwd: Path | None = None) -> Result:
    """``python -m synthua_usd ARGS...`` in a subprocess with at most :data:`MEMORY_CAP_BYTES` of address
    space; a run past ``timeout`` fails as a hang."""
    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP_BYTES, MEMORY_CAP_BYTES))

    t0 = time.perf_counter()
    try:
        proc = subprocess.run([sys.executable, "-m", "synthua_usd", *map(str, args)], cwd=cwd, capture_output=True,
                              timeout=timeout, preexec_fn=cap, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        raise AssertionError(f"synthua {' '.join(map(str, args))} hung: still running after {timeout} s") from None
    return Result(proc.returncode, proc.stdout.decode("utf-8", "replace"), proc.stderr.decode("utf-8", "replace"),
                  time.perf_counter() - t0)


def refused(run, root: Path, *args, mentions=()) -> str:
    """Run ``synthua ARGS`` with ``run`` and check a refusal that changed nothing under ``root`` (which holds
    the inputs, the current folder and any output folder); returns the error line."""
    before = tree_state(root)
    result = run(*args)
    message = assert_refused(result, *mentions)
    assert tree_state(root) == before, f"{root} changed although synthua refused: {message}"
    return message


@pytest.fixture(scope="session")
def earlier_import(tmp_path_factory) -> Path:
    """An import made before the hostile cases run: a refused import must leave a copy of it as it was."""
    out = tmp_path_factory.mktemp("earlier") / "out"
    code = main(["twin", "import", "footprints", str(GEOJSON), "--out", str(out)])
    assert code == 0 and (out / "scenario.usda").is_file()
    return out


@pytest.fixture
def workdir(tmp_path, monkeypatch, earlier_import) -> Path:
    """``tmp_path`` as the current folder, with ``out/`` holding a copy of an earlier import."""
    monkeypatch.chdir(tmp_path)
    shutil.copytree(earlier_import, tmp_path / "out")
    return tmp_path


@pytest.fixture
def refuse(capsys, workdir):
    """``refuse(*args, mentions=(...))``: an in-process run that must be refused, changing nothing."""
    def check(*args, mentions=()):
        return refused(lambda *a: run_inprocess(capsys, *a), workdir, *args, mentions=mentions)
    return check
