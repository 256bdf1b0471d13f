"""A detection set written in Ultralytics' detection layout, for training::

    DIR/data.yaml                    path (absolute), train, val, names (the classes trained, in index order)
    DIR/images/{split}/{n}{suffix}   symbolic links to the set's image files (no image is copied)
    DIR/labels/{split}/{n}.txt       one box a line: index cx cy w h, normalised by the image's size

Files are numbered (``n`` = 000001, ...), so images of two sources with the same name cannot collide. Boxes marked
``ignore`` are left out (Ultralytics has no ignore region: a box too small to learn is better absent than taught),
as are boxes of classes not trained. Ultralytics writes its label cache (``labels/{split}.cache``) here too,
never beside a user's data.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from synthua_usd.analytics.detection_sets import DetectionSet
from synthua_usd.core.atomic import write_text_atomic

#: Decimals of normalised coordinates (1e-7 of the image: far below a pixel).
DECIMALS = 7


def label_lines(image, index: dict[str, int]) -> list[str]:
    """The Ultralytics label lines of one :class:`~synthua_usd.analytics.detection_sets.SetImage`."""
    lines = []
    for b in image.boxes:
        if b.ignore or b.label not in index or b.w <= 0 or b.h <= 0:
            continue
        cx, cy = (b.x + b.w / 2) / image.width, (b.y + b.h / 2) / image.height
        values = (cx, cy, b.w / image.width, b.h / image.height)
        lines.append(f"{index[b.label]} " + " ".join(f"{v:.{DECIMALS}f}" for v in values))
    return lines


def write_yolo_boxes(out_dir: str | Path, splits: dict[str, DetectionSet], names: tuple[str, ...]) -> Path:
    """Write ``splits`` (``train``, ``val``, ...) with the classes ``names`` into ``out_dir``; return data.yaml."""
    out_dir = Path(out_dir).resolve()
    index = {n: k for k, n in enumerate(names)}
    for split, dataset in splits.items():
        (out_dir / "images" / split).mkdir(parents=True, exist_ok=True)
        (out_dir / "labels" / split).mkdir(parents=True, exist_ok=True)
        for n, image in enumerate(dataset.images, 1):
            stem = f"{n:06d}"
            link = out_dir / "images" / split / f"{stem}{image.path.suffix.lower()}"
            if link.is_symlink() or link.exists():
                link.unlink()
            os.symlink(Path(image.path).resolve(), link)
            write_text_atomic(out_dir / "labels" / split / f"{stem}.txt", "".join(
                line + "\n" for line in label_lines(image, index)))
    lines = ["# Ultralytics detection set written by synthua-usd (synthua train)", f"path: {json.dumps(str(out_dir))}"]
    lines += [f"{split}: images/{split}" for split in splits]
    lines += [f"nc: {len(names)}", "names:"] + [f"  {k}: {json.dumps(n)}" for k, n in enumerate(names)]
    return write_text_atomic(out_dir / "data.yaml", "\n".join(lines) + "\n")
