"""Atomic writes, of one file and of a command's whole set of outputs.

One file: write to a temporary file beside the target, then rename it into place, so that a reader never
sees a half-written file and a failed write leaves the previous file untouched.

A set of files: a command writes everything into an empty staging folder beside its output folder; only
when every file is complete are they moved into place. On any failure the staging folder is removed and
the output folder is exactly as it was: a run never leaves a mix of old and new files.
"""

from __future__ import annotations

import os
import secrets
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from synthua_usd.errors import OutputError


@contextmanager
def atomic_path(path: str | Path, mode: int = 0o644) -> Iterator[Path]:
    """Yield a temporary path with the target's suffix (writers pick formats by extension); on success it
    replaces ``path`` with permissions ``mode``; on any error it is removed."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem[:64]}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, mode)  # mkstemp creates 0600
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically."""
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def write_json_atomic(path: str | Path, document, indent: int = 2) -> Path:
    """Write ``document`` as UTF-8 JSON (a final newline) to ``path`` atomically."""
    import json

    return write_text_atomic(path, json.dumps(document, indent=indent, ensure_ascii=False) + "\n")


@contextmanager
def output_set(out_dir: str | Path) -> Iterator[Path]:
    """Yield an empty staging folder beside ``out_dir``; write every output into it (subfolders allowed).

    On success, when ``out_dir`` does not exist the staging folder is renamed to it (one atomic step);
    otherwise every staged file replaces its counterpart in ``out_dir`` (files of ``out_dir`` that the set
    does not hold are kept). Every target is checked before the first move, so a file that would land on
    a folder, or below a file, fails with nothing moved. On any error the staging folder is removed.
    """
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise OutputError(f"{out_dir}: output folder is a file; expected a folder or a path that does not exist")
    parent = out_dir.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        staging = parent / f".{out_dir.name[:64]}.partial-{secrets.token_hex(4)}"
        staging.mkdir()
    except FileExistsError:
        raise OutputError(f"{out_dir}: a parent of the output folder is a file; expected folders") from None
    try:
        yield staging
        _move_into_place(staging, out_dir)
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


def _move_into_place(staging: Path, out_dir: Path) -> None:
    if not out_dir.exists():
        os.rename(staging, out_dir)
        return
    files = sorted(p for p in staging.rglob("*") if not p.is_dir())
    for src in files:
        target = out_dir / src.relative_to(staging)
        if target.is_dir() and not target.is_symlink():
            raise OutputError(f"{target}: is a folder where the output file goes; move it away and run again")
        for ancestor in target.relative_to(out_dir).parents:
            folder = out_dir / ancestor
            if folder.exists() and not folder.is_dir():
                raise OutputError(f"{folder}: is a file where an output folder goes; move it away and run again")
    for src in files:
        target = out_dir / src.relative_to(staging)
        target.parent.mkdir(parents=True, exist_ok=True)
        os.replace(src, target)
