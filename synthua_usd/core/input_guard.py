"""The guard that keeps a command's outputs off its own inputs: ``synthua randomise s.usda --out s.usda`` must not
replace the scenario it read, ``synthua train SET --init RUN --out RUN`` the weights it starts from.

Every command that writes names its inputs by how the user gave them (``SCENARIO``, ``--config``, ...) and asks
:func:`check_not_inputs` about the files it is going to write, before it does any work where it can, and
:func:`synthua_usd.core.atomic.output_set` asks it again about every file of the finished set before the first
one is moved into place: whatever the command wrote, none of it replaces an input.

An output is an input when it is the same file (``..``, symbolic and hard links included), or an existing file
inside an input folder (a dataset, a run folder, a folder of images); for a folder the command fills as a whole
(``synthua generate``'s dataset), when an input lies anywhere inside it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Iterable, Mapping

from synthua_usd.core.errors import InputError, echo

#: Inputs of a command: how the user gave each (``SCENARIO``, ``--config``) -> its path, paths, or None.
Inputs = Mapping[str, "str | os.PathLike | Iterable[str | os.PathLike] | None"]


def _flat(inputs: Inputs) -> list[tuple[str, Path]]:
    out = []
    for role, value in inputs.items():
        if value is None:
            continue
        paths = [value] if isinstance(value, (str, os.PathLike)) else list(value)
        out += [(role, Path(p)) for p in paths if p is not None]
    return out


def _same(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:  # either is missing or unreadable: not the same existing file
        return False


def _inside(path: Path, folder: Path) -> bool:
    try:
        return path.resolve().is_relative_to(folder.resolve())
    except (OSError, RuntimeError):  # a symbolic-link loop: not inside anything we can name
        return False


def clash(output: str | os.PathLike, inputs: Inputs, whole_folder: bool = False) -> tuple[str, Path] | None:
    """(role, path) of the input that writing ``output`` would replace, or None. ``whole_folder``: ``output``
    is a folder the command owns as a whole, so any input inside it clashes."""
    output = Path(output)
    for role, path in _flat(inputs):
        if whole_folder:
            if path.exists() and _inside(path, output):
                return role, path
        elif output.exists() and not output.is_dir():
            if _same(output, path) or (path.is_dir() and _inside(output, path)):
                return role, path
    return None


def check_not_inputs(outputs: Iterable[str | os.PathLike], inputs: Inputs, whole_folder: bool = False) -> None:
    """Raise :class:`InputError` naming the first of ``outputs`` that would replace one of ``inputs`` (see
    :func:`clash`): ``<output>: is the input <role> itself; expected ...``."""
    for output in outputs:
        found = clash(output, inputs, whole_folder)
        if found is None:
            continue
        role, path = found
        if whole_folder:
            what = f"holds the input {role} ({echo(path)}), which the output could replace"
        elif _same(output, path):
            what = f"is the input {role} itself" + (f" ({echo(path)})" if str(path) != str(output) else "")
        else:
            what = f"lies in the input folder {role} ({echo(path)})"
        raise InputError(f"{echo(output)}: {what}; expected an output path that is none of the command's inputs "
                         f"(write it elsewhere)")
