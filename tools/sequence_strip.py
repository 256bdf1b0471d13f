#!/usr/bin/env python
"""A strip of frames of one tracking sequence with its ground-truth boxes, for the README.

Usage: python tools/sequence_strip.py DATASET SEQUENCE [--frames 4] [--width 1600] [--out docs/sequence_strip.jpg]

Frames spread evenly over the sequence (first and last included), each with the amodal box, track id and class of
every tracked object drawn as the sequence's preview video draws them (a device in its user's colour), side by side,
scaled to --width, written as a JPEG. The frame numbers are printed, for a caption.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dataset", type=Path)
    parser.add_argument("sequence", help="a folder name under DATASET/sequences, e.g. CCTV-Largo_clear-day_s0")
    parser.add_argument("--frames", type=int, default=4)
    parser.add_argument("--width", type=int, default=1600)
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "sequence_strip.jpg")
    args = parser.parse_args()

    from PIL import Image

    from synthua_usd.dataset.layout import Layout
    from synthua_usd.dataset.record import SEQUENCE_FRAME, read_record
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline.sequences import boxed_frame

    layout = Layout(args.dataset)
    class_map = ClassMap.load(args.dataset / Layout.CLASS_MAP)
    records = sorted((args.dataset / "sequences" / args.sequence / "records").glob("*.json"))
    if not records:
        print(f"{args.dataset}: no records of sequence {args.sequence!r}", file=sys.stderr)
        return 2
    picks = sorted(set(np.linspace(0, len(records) - 1, args.frames).round().astype(int).tolist()))
    tiles = [boxed_frame(layout, read_record(records[k], SEQUENCE_FRAME), class_map) for k in picks]
    strip = Image.fromarray(np.concatenate(tiles, axis=1))
    strip = strip.resize((args.width, round(strip.height * args.width / strip.width)), Image.LANCZOS)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    strip.save(args.out, quality=85)
    print(f"wrote {args.out}: frames {', '.join(str(k + 1) for k in picks)} of {len(records)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
