"""``synthua verify BANK``: a cut-out bank checked against its manifest and its own images, without rendering.

``bank.json`` must be of this version's format (:mod:`synthua_usd.dataset.cutout_bank`, which reads it); every file it
lists present with its size and SHA-256, and no other file; every cut-out's four images of one size, the entry's
``size``; each instance's visible box and area those of its index in ``ids.png``, its amodal box and area those of
its bit in ``amodal.png`` (which holds every visible pixel of it), its visible keypoints inside the crop; the
anchor and ground points inside the crop; ``rgba.png``'s alpha nonzero wherever ``ids.png`` names an instance (but
on at most :data:`COVERAGE_TOLERANCE` of the pixels: a structure thinner than a pixel that the centre ray hits and
every sample misses).
Problems are collected, one line each, as ``synthua verify`` of a dataset lists them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


#: The share of an instance's labelled pixels its coverage may leave at 0 (sub-pixel structures; see below).
COVERAGE_TOLERANCE = 0.01


@dataclass
class BankCheck:
    """What checking a bank found: cut-outs and files checked, and the problems (empty: the bank is whole)."""

    cutouts: int = 0
    files: int = 0
    problems: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.problems


def check_bank(bank: str | Path) -> BankCheck:
    """Check the bank folder ``bank`` (see the module); a ``bank.json`` that is not of this version's format, or
    malformed, is an :class:`InputError` (:func:`synthua_usd.dataset.cutout_bank.read_bank`)."""
    from synthua_usd.core.images import read_image
    from synthua_usd.dataset.cutout_bank import BANK_FILE, FILE_KEYS, read_bank
    from synthua_usd.dataset.manifest import file_entry

    folder = Path(bank)
    read = read_bank(folder)
    out = BankCheck(cutouts=len(read.entries))
    listed: set[str] = set()
    for entry in read.files:
        path = entry["path"]
        listed.add(path)
        if not (folder / path).is_file():
            out.problems.append(f"{path}: missing (listed in {BANK_FILE})")
            continue
        out.files += 1
        if file_entry(folder, path) != entry:
            out.problems.append(f"{path}: size or SHA-256 differs from {BANK_FILE}")
    for path in sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()):
        if path != BANK_FILE and path not in listed:
            out.problems.append(f"{path}: not listed in {BANK_FILE}")
    for cutout in read.entries:
        try:
            arrays = {key: read_image(folder / cutout.files[key])[0] for key in FILE_KEYS}
        except (OSError, KeyError) as exc:
            out.problems.append(f"cut-out {cutout.id}: its images cannot be read ({exc})")
            continue
        out.problems += [f"cut-out {cutout.id}: {p}" for p in _entry_problems(cutout, arrays)]
    return out


def _box(mask: np.ndarray) -> list[float] | None:
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if not len(rows):
        return None
    return [float(cols[0]), float(rows[0]), float(cols[-1] + 1 - cols[0]), float(rows[-1] + 1 - rows[0])]


def _entry_problems(entry, arrays: dict[str, np.ndarray]) -> list[str]:
    problems = []
    w, h = entry.size
    for key, array in arrays.items():
        if array.shape[:2] != (h, w):
            problems.append(f"{key} is {array.shape[1]}x{array.shape[0]}; expected {w}x{h}")
    if problems:
        return problems
    ids, bits, alpha = arrays["ids"][..., 0], arrays["amodal"][..., 0], arrays["rgba"][..., 3]
    indices = {inst.index for inst in entry.instances}
    stray = sorted(set(np.unique(ids).tolist()) - indices - {0})
    if stray:
        problems.append(f"ids.png holds indices {stray} that no instance has")
    # labels come from pixel centres, coverage from the path tracer's samples: on a structure thinner than a
    # pixel (a wheel's spoke) the samples may all miss what the centre hits; more than that is a fault
    bare = int(np.count_nonzero((ids > 0) & (alpha == 0)))
    if bare > max(2, int(COVERAGE_TOLERANCE * np.count_nonzero(ids))):
        problems.append(f"ids.png names an instance on {bare} pixels where rgba.png's alpha is 0")
    for inst in entry.instances:
        k = inst.index
        visible, amodal = ids == k, ((bits >> (k - 1)) & 1).astype(bool)
        box = _box(visible) or [0.0, 0.0, 0.0, 0.0]
        if int(visible.sum()) != inst.area or box != list(inst.bbox):
            problems.append(f"instance {k} ({inst.class_name}): box {list(inst.bbox)} area {inst.area}; its pixels in "
                            f"ids.png give {box} and {int(visible.sum())}")
        if np.any(visible & ~amodal):
            problems.append(f"instance {k}: visible pixels outside its amodal mask")
        if int(amodal.sum()) != inst.amodal_area or (_box(amodal) or []) != list(inst.amodal_bbox):
            problems.append(f"instance {k}: amodal box {list(inst.amodal_bbox)} area {inst.amodal_area}; amodal.png "
                            f"gives {_box(amodal)} and {int(amodal.sum())}")
        for x, y, v in inst.keypoints or ():
            if v and not (0 <= x <= w and 0 <= y <= h):
                problems.append(f"instance {k}: a keypoint at ({x}, {y}) outside the {w}x{h} crop")
    for x, y in [entry.anchor, *entry.ground_points]:
        if not (-0.5 <= x <= w + 0.5 and -0.5 <= y <= h + 0.5):
            problems.append(f"a ground point ({x}, {y}) outside the {w}x{h} crop")
    return problems
