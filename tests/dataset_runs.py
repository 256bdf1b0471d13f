"""What the dataset tests share: the files of a dataset folder by content, its records, and a ``synthua generate``
subprocess of the tiny config killed at a chosen moment."""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from conftest import SCENARIO, TINY_CONFIG


def tree_bytes(root: Path) -> dict[str, str]:
    """SHA-256 of every file below ``root`` by relative path."""
    return {p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def records(root: Path) -> list[dict]:
    return [json.loads(p.read_text(encoding="utf-8")) for p in sorted((root / "records").glob("*.json"))]


def generate_command(out: Path, config: Path = TINY_CONFIG) -> list[str]:
    return [sys.executable, "-m", "synthua_usd", "generate", str(SCENARIO), "--config", str(config), "--out", str(out)]


def kill_when(out: Path, ready, timeout: float = 120.0, config: Path = TINY_CONFIG) -> bool:
    """Start generate of ``config``, SIGKILL it and its workers as soon as ``ready(out)``; True if it was killed in
    time."""
    proc = subprocess.Popen(generate_command(out, config), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline = time.monotonic() + timeout
    try:
        while proc.poll() is None and time.monotonic() < deadline:
            if ready(out):
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                return True
            time.sleep(0.02)
        return False
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
