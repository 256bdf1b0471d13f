#!/usr/bin/env python
"""Build the body bank (synthua_usd/assets/data/bodies.npz) from the body model anny.

Usage: python tools/build_body_bank.py [--seed 0]

Needs torch (CPU build) and anny; the first run on a machine spends ~3-4 min while anny builds its model
data (cached under ~/.cache/anny). See synthua_usd/assets/body_bank.py for what is sampled and why.
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from synthua_usd.assets.body_bank import BANK_PATH, build_bank  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    bank = build_bank(args.seed, BANK_PATH)
    print(f"{len(bank['points'])} bodies, {bank['points'].shape[1]} vertices, {len(bank['triangles'])} triangles "
          f"-> {BANK_PATH} ({BANK_PATH.stat().st_size / 1e6:.2f} MB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
