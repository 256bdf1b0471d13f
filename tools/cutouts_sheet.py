#!/usr/bin/env python
"""A contact sheet of a cut-out bank: each cut-out over a grey ground plane darkened by its shadow layer, beside
its labels (each instance a colour over the image; keypoints white where visible, orange where occluded; the
ground points cyan, the anchor magenta). For the docs (docs/images/cutouts.jpg) and for looking at a bank.

Usage:
  python tools/cutouts_sheet.py BANK [--out docs/images/cutouts.jpg] [--count 12] [--columns 4] [--height 220]
         [--one-per-group]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

#: An instance index's colour in the label view.
PALETTE = np.array([[0, 0, 0], [230, 25, 75], [60, 180, 75], [255, 225, 25], [0, 130, 200], [245, 130, 48],
                    [145, 30, 180], [70, 240, 240]], float)


def tile(bank: Path, entry: dict, height: int) -> np.ndarray:
    """One cut-out: (composite | labels) side by side, ``height`` pixels high."""
    from PIL import Image

    from synthua_usd.core.images import read_image

    rgba = read_image(bank / entry["files"]["rgba"])[0].astype(float)
    shadow = read_image(bank / entry["files"]["shadow"])[0][..., 0].astype(float) / 255
    ids = read_image(bank / entry["files"]["ids"])[0][..., 0]
    alpha = rgba[..., 3:4] / 255
    ground = np.full(rgba.shape[:2] + (3,), 185.0) * shadow[..., None]
    image = rgba[..., :3] * alpha + ground * (1 - alpha)
    labels = np.where(ids[..., None] > 0, PALETTE[np.minimum(ids, len(PALETTE) - 1)] * 0.6 + image * 0.4, image)

    def dot(x: float, y: float, colour, r: int = 2) -> None:
        xi, yi = int(x), int(y)
        labels[max(0, yi - r):yi + r + 1, max(0, xi - r):xi + r + 1] = colour

    for inst in entry["instances"]:
        for x, y, v in inst["keypoints"] or []:
            if v:
                dot(x, y, [255, 255, 255] if v == 2 else [255, 140, 0], 1)
    for x, y in entry["ground_points"]:
        dot(x, y, [0, 255, 255])
    dot(*entry["anchor"], [255, 0, 255], 3)
    both = np.concatenate([image, labels], axis=1).astype(np.uint8)
    scale = height / both.shape[0]
    return np.asarray(Image.fromarray(both).resize((max(1, round(both.shape[1] * scale)), height), Image.LANCZOS))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bank", type=Path)
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "images" / "cutouts.jpg")
    parser.add_argument("--count", type=int, default=12)
    parser.add_argument("--columns", type=int, default=4)
    parser.add_argument("--height", type=int, default=220)
    parser.add_argument("--one-per-group", action="store_true", help="only each group's first view")
    args = parser.parse_args()
    from PIL import Image

    entries = json.loads((args.bank / "bank.json").read_text(encoding="utf-8"))["cutouts"]
    if args.one_per_group:
        entries = [e for e in entries if e["id"].endswith("v00")]
    entries = entries[:args.count]
    tiles = [tile(args.bank, e, args.height) for e in entries]
    rows = [tiles[i:i + args.columns] for i in range(0, len(tiles), args.columns)]
    width = max(sum(t.shape[1] for t in row) + 8 * (len(row) - 1) for row in rows)
    sheet = np.full((len(rows) * (args.height + 8) - 8, width, 3), 255, np.uint8)
    for r, row in enumerate(rows):
        x = 0
        for t in row:
            sheet[r * (args.height + 8):r * (args.height + 8) + args.height, x:x + t.shape[1]] = t
            x += t.shape[1] + 8
    args.out.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(sheet).save(args.out, quality=88)
    print(f"wrote {args.out} ({len(tiles)} cut-outs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
