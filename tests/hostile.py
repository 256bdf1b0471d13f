"""The harness of the hostile-input suite: run ``synthua`` as a user would (a subprocess), and check what
every refusal must look like and that nothing already written changed.

A refusal: exit status 2, no traceback, stderr ends with exactly one ``synthua: error: ...`` line (one-line
warnings may come before it), the message names the file, prim or field. Nothing outside the output
folder is written; an existing output folder is left byte for byte as it was.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

#: Every case must finish within this many seconds (a hang is a failure, not a slow test).
CASE_TIMEOUT_S = 60


@dataclass(frozen=True)
class Result:
    code: int
    stdout: str
    stderr: str
    seconds: float

    @property
    def error_lines(self) -> list[str]:
        return [line for line in self.stderr.splitlines() if line.startswith("synthua: error:")]


def run_synthua(*args, cwd: Path | None = None, timeout: float = CASE_TIMEOUT_S, env: dict | None = None,
                stdin: bytes | None = None) -> Result:
    """``python -m synthua_usd ARGS...`` in a subprocess; a run past ``timeout`` fails the test as a hang."""
    t0 = time.perf_counter()
    try:
        proc = subprocess.run([sys.executable, "-m", "synthua_usd", *map(str, args)], cwd=cwd, capture_output=True,
                              timeout=timeout, env={**os.environ, **(env or {})}, input=stdin or b"")
    except subprocess.TimeoutExpired:
        raise AssertionError(f"synthua {' '.join(map(str, args))} hung: still running after {timeout} s") from None
    return Result(proc.returncode, proc.stdout.decode("utf-8", "replace"), proc.stderr.decode("utf-8", "replace"),
                  time.perf_counter() - t0)


def assert_refused(result: Result, *mentions: str) -> str:
    """Exit 2, no traceback, one error line (the last line of stderr) that mentions every ``mentions``
    (case-insensitive); returns that line."""
    assert "Traceback" not in result.stderr, result.stderr
    assert result.code == 2, f"exit {result.code}, expected 2; stderr:\n{result.stderr}"
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert lines and lines[-1].startswith("synthua: error: "), result.stderr
    assert len(result.error_lines) == 1, result.stderr
    assert all(line.startswith("synthua: ") for line in lines), f"a line not in synthua's format:\n{result.stderr}"
    message = lines[-1]
    for text in mentions:
        assert text.lower() in message.lower(), f"{text!r} not in {message!r}"
    return message


def tree_state(root: Path) -> dict[str, tuple]:
    """Every entry below ``root`` (links not followed): kind, and content hash for files and link targets."""
    out: dict[str, tuple] = {}
    if not root.exists() and not root.is_symlink():
        return out
    for dirpath, dirnames, filenames in os.walk(root, followlinks=False):
        for name in dirnames + filenames:
            path = Path(dirpath) / name
            rel = str(path.relative_to(root))
            if path.is_symlink():
                out[rel] = ("link", os.readlink(path))
            elif path.is_dir():
                out[rel] = ("dir",)
            elif not path.is_file():  # a FIFO, socket or device: its kind, never its content (reading blocks)
                out[rel] = ("special", path.stat().st_mode)
            else:
                out[rel] = ("file", hashlib.sha256(path.read_bytes()).hexdigest(), path.stat().st_mode & 0o777)
    return out


@contextlib.contextmanager
def small_disk(tmp: Path, options: str) -> Iterator[Path]:
    """A tmpfs mounted at ``tmp/mnt`` with ``options`` (``size=160k``, ``size=64k,ro``), unmounted afterwards;
    skips the test where mounting is not allowed (CI runs as root and can)."""
    import pytest

    where = tmp / "mnt"
    where.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(where)], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here ({done.stderr.decode().strip()}); CI runs as root and can")
    try:
        yield where
    finally:
        subprocess.run(["umount", str(where)], check=False)


def size_limited(limit_bytes: int):
    """A ``preexec_fn`` for a subprocess whose files may not grow past ``limit_bytes`` (RLIMIT_FSIZE: writes
    fail with EFBIG, as on a full disk), without needing a mount."""
    def limit() -> None:
        import resource
        import signal

        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return limit
