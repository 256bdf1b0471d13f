#!/usr/bin/env python
"""A sheet of composites of a ``synthua composite`` dataset: each row the background as cut to the output size, the
composite, and its class labels over it (each pasted instance's class colour; the photo's pixels are void).

Usage: python tools/composite_sheet.py DATASET [--images 3] [--width 1500] --out sheet.jpg

The backgrounds are read where the dataset's generate.json says they are. Photos whose licence does not allow
publishing them must not go into a sheet that is published (docs/ uses rendered empty district frames).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dataset", type=Path)
    parser.add_argument("--images", type=int, default=3, help="rows (the first composites by id) [3]")
    parser.add_argument("--ids", type=int, nargs="*", help="these composites' ids instead")
    parser.add_argument("--width", type=int, default=1500, help="sheet width in pixels [1500]")
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()

    from PIL import Image

    from synthua_usd.backends.photos import read_photo
    from synthua_usd.dataset.composite_config import CompositeConfig
    from synthua_usd.dataset.record import COMPOSITE, read_record

    job = json.loads((args.dataset / "generate.json").read_text(encoding="utf-8"))
    config = CompositeConfig.from_document(job["job_key"]["config"])
    folder = Path(job["backgrounds"])
    folder = folder if folder.is_dir() else folder.parent
    records = sorted((read_record(p, COMPOSITE) for p in (args.dataset / "records").glob("*.json")),
                     key=lambda r: r["id"])
    chosen = [r for r in records if r["id"] in args.ids] if args.ids else records[:args.images]
    rows = []
    for record in chosen:
        background = read_photo(folder / record["composite"]["background"]["path"], config.output).pixels
        rgb = np.asarray(Image.open(args.dataset / record["files"]["rgb_png"]).convert("RGB"))
        colours = np.asarray(Image.open(args.dataset / record["files"]["semantic"]).convert("RGB"))
        labelled = np.asarray(Image.open(args.dataset / record["files"]["class"])) > 0
        overlay = rgb.copy()
        overlay[labelled] = (0.35 * rgb[labelled] + 0.65 * colours[labelled]).astype(np.uint8)
        overlay[~labelled] = (0.6 * rgb[~labelled]).astype(np.uint8)
        gap = np.full((rgb.shape[0], 8, 3), 255, np.uint8)
        rows.append(np.concatenate([background, gap, rgb, gap, overlay], axis=1))
        rows.append(np.full((8, rows[-1].shape[1], 3), 255, np.uint8))
    sheet = Image.fromarray(np.concatenate(rows[:-1], axis=0))
    sheet = sheet.resize((args.width, round(sheet.height * args.width / sheet.width)), Image.Resampling.LANCZOS)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(args.out, quality=88)
    print(f"wrote {args.out} ({len(chosen)} composites)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
