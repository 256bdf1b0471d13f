"""Atomic writes, of one file and of a command's whole set of outputs.

One file: write to a temporary file beside the target, then rename it into place, so that a reader never
sees a half-written file and a failed write leaves the previous file untouched.

A set of files: a command writes everything into an empty staging folder beside its output folder; only
when every file is complete are they moved into place. On any failure the staging folder is removed and
the output folder is exactly as it was: a run never leaves a mix of old and new files.

Failures name what the user asked for, never the temporary file or staging folder: an ``OSError`` about a
temporary path is raised again naming its target. A library that fails a write without an errno
(OpenImageIO, OpenUSD) is asked what the disk says through :func:`write_failure`.
"""

from __future__ import annotations

import errno
import os
import secrets
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from synthua_usd.core.dataset_folders import check_outside_datasets
from synthua_usd.core.errors import OutputError, SynthuaError
from synthua_usd.core.input_guard import Inputs, check_not_inputs


@contextmanager
def atomic_path(path: str | Path, mode: int = 0o644) -> Iterator[Path]:
    """Yield a temporary path with the target's suffix (writers pick formats by extension); on success it
    replaces ``path`` with permissions ``mode``; on any error it is removed."""
    path = Path(path)
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem[:64]}.", suffix=path.suffix, dir=path.parent)
        os.close(fd)
        yield Path(tmp)
        os.chmod(tmp, mode)  # mkstemp creates 0600
        os.replace(tmp, path)
    except OSError as exc:
        # mkstemp names its own random file; the writer and os.replace name ``tmp``
        raise renamed(exc, Path(tmp) if tmp else path.parent, path, whole=tmp is None) from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)


def renamed(exc: OSError, old: Path, new: Path, whole: bool = False) -> OSError:
    """``exc`` naming ``new`` wherever it named ``old`` or a path below it (``whole``: any path directly
    in the folder ``old`` is ``new`` itself, as mkstemp's random names are); ``exc`` itself when it names
    neither."""
    # a library names the file as it made it: tempfile absolute where the folder was given relative
    old_abs = Path(os.path.abspath(old))

    def mapped(name):
        if name is None:
            return None
        name = Path(os.fsdecode(name))
        if whole:
            return new if name.parent in (old, old_abs) else None
        for folder in (old, old_abs):
            if name.is_relative_to(folder):
                return new / name.relative_to(folder)
        return None

    first, second = mapped(exc.filename), mapped(getattr(exc, "filename2", None))
    if first is None and second is None:
        return exc
    args = [exc.errno, exc.strerror, str(first or exc.filename)]
    if exc.filename2 is not None and second != first:
        args += [None, str(second or exc.filename2)]
    try:
        return type(exc)(*args)
    except TypeError:
        return OSError(*args)


@contextmanager
def named_as(folder: Path, shown: Path) -> Iterator[None]:
    """Failures of the block that name ``folder`` (a staging or scratch folder the user never asked for) or a
    path below it name ``shown`` instead: an ``OSError``'s file names, a :class:`SynthuaError`'s text."""
    try:
        yield
    except OSError as exc:
        raise renamed(exc, folder, shown) from None
    except SynthuaError as exc:
        if str(folder) not in str(exc):
            raise
        raise type(exc)(str(exc).replace(str(folder), str(shown))) from None


def write_failure(path: str | Path, tmp: str | Path, reason: str, size: int = 0) -> OSError:
    """The ``OSError`` naming ``path`` for a write into ``tmp`` that a library failed without an errno.

    A full disk (less free space than ``size`` bytes, or appending to ``tmp`` fails with ENOSPC, EDQUOT or
    EFBIG, a file-size limit) gives that errno; any other failure EIO with ``reason`` (the library's words).
    """
    tmp = Path(tmp)
    try:
        if shutil.disk_usage(tmp.parent).free < size:
            return OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        # The library's failed write left ``tmp`` as full as the disk or the size limit allows: one more
        # block (64 KiB) tells which it was. ``tmp`` is removed with the rest of the failed write.
        with open(tmp, "ab") as probe:
            probe.write(bytes(64 * 1024))
            probe.flush()
            os.fsync(probe.fileno())
    except OSError as exc:
        if exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
            return OSError(exc.errno, os.strerror(exc.errno), str(path))
    reason = reason.replace(str(tmp), str(path)).strip()  # libraries name the file they were given
    return OSError(errno.EIO, reason or "could not write it (no reason given)", str(path))


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically."""
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def write_json_atomic(path: str | Path, document, indent: int = 2) -> Path:
    """Write ``document`` as UTF-8 JSON (a final newline; :func:`synthua_usd.core.json_text.dumps`, NumPy scalars as
    their JSON types) to ``path`` atomically."""
    from synthua_usd.core import json_text

    return write_text_atomic(path, json_text.dumps(document, indent=indent) + "\n")


@contextmanager
def output_set(out_dir: str | Path, dataset_part: bool = False, inputs: Inputs | None = None) -> Iterator[Path]:
    """Yield an empty staging folder beside ``out_dir``; write every output into it (subfolders allowed).

    On success, when ``out_dir`` does not exist the staging folder is renamed to it (one atomic step);
    otherwise every staged file replaces its counterpart in ``out_dir`` (files of ``out_dir`` that the set
    does not hold are kept). Every target is checked before the first move, so a file that would land on
    a folder, or below a file, fails with nothing moved. On any error the staging folder is removed. An
    ``out_dir`` in a dataset folder is refused (:func:`synthua_usd.core.dataset_folders.check_outside_datasets`), unless
    ``dataset_part``: ``synthua generate`` writing a part of its own dataset (a district's scenario). A staged
    file that would replace one of the command's ``inputs`` fails before anything is moved
    (:func:`synthua_usd.core.input_guard.check_not_inputs`).
    """
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise OutputError(f"{out_dir}: output folder is a file; expected a folder or a path that does not exist")
    if not dataset_part:
        check_outside_datasets(out_dir)
    parent = out_dir.parent
    staging = parent / f".{out_dir.name[:64]}.partial-{secrets.token_hex(4)}"
    try:
        parent.mkdir(parents=True, exist_ok=True)
        staging.mkdir()
    except FileExistsError:
        raise OutputError(f"{out_dir}: a parent of the output folder is a file; expected folders") from None
    except OSError as exc:  # a read-only or full parent: the folder asked for, never the staging folder
        raise renamed(exc, staging, out_dir) from None
    try:
        with named_as(staging, out_dir):
            yield staging
            _move_into_place(staging, out_dir, inputs or {})
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


def _move_into_place(staging: Path, out_dir: Path, inputs: Inputs) -> None:
    if not out_dir.exists():
        os.rename(staging, out_dir)
        return
    files = sorted(p for p in staging.rglob("*") if not p.is_dir())
    check_not_inputs((out_dir / src.relative_to(staging) for src in files), inputs)
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
