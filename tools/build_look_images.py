#!/usr/bin/env python
"""Rebuild the images people wear, shipped in synthua_usd/assets/data/looks/ (fabrics with their folds, shoes, the
face; synthua_usd/assets/look_images.py): every one from its seed, so the same code writes the same pixels.

Usage: python tools/build_look_images.py [--out synthua_usd/assets/data/looks]

tests/assets/test_look_images.py checks that the shipped files hold exactly what the code makes.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    from synthua_usd.assets.look_images import LOOKS_DIR, look_images
    from synthua_usd.core.images import write_color_png

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=LOOKS_DIR)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for stem, pixels in sorted(look_images().items()):
        path = write_color_png(args.out / f"{stem}.png", pixels)
        print(f"wrote {path} ({path.stat().st_size // 1024} KiB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
