#!/usr/bin/env python
"""Benchmark: how long ``synthua stats`` takes, per 1,000 images.

Usage:
  python tools/bench_stats.py DATASET [DATASET ...] [--repeat 3]

For each dataset (folders written by ``synthua generate``): the whole command once as a user runs it (a fresh
process: imports, class-map check, records, statistics, figures, gallery, HTML), then in one process, best of
``--repeat``: reading the manifest and the per-image records, computing the statistics (which reads every RGB
once, for contrast and edges), and writing the report. Reading and computing grow with the number of images; the
figures and the gallery (8 images) do not. The last line gives the time per 1,000 images of reading + computing,
and the fixed cost. Not a test: note the machine's load.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("datasets", nargs="+", type=Path)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    sys.path.insert(0, str(REPO))
    from synthua_usd.analytics.dataset_index import load_index
    from synthua_usd.analytics.report import write_report
    from synthua_usd.analytics.statistics import compute

    print(f"load average {os.getloadavg()[0]:.2f}")
    print("| dataset | images | `synthua stats` (fresh process) | read records | compute | report (figures, gallery, HTML) "
          "| read + compute per 1,000 images |")
    print("|---|---|---|---|---|---|---|")
    per_image = []
    for root in args.datasets:
        with tempfile.TemporaryDirectory() as tmp:
            env = dict(os.environ, PYTHONPATH=str(REPO))
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "synthua_usd", "stats", str(root), "--out", f"{tmp}/cli"], check=True,
                           env=env, capture_output=True)
            cli = time.perf_counter() - t0
            load_index(root)                                      # warm: imports and the class-map check
            best = [float("inf")] * 3
            for k in range(args.repeat):
                t0 = time.perf_counter()
                index = load_index(root)
                t1 = time.perf_counter()
                stats = compute(index)
                t2 = time.perf_counter()
                write_report(index, stats, f"{tmp}/r{k}")
                t3 = time.perf_counter()
                best = [min(b, v) for b, v in zip(best, (t1 - t0, t2 - t1, t3 - t2))]
        n = len(index.images)
        per_image.append((best[0] + best[1]) / n)
        print(f"| {root} | {n} | {cli:.2f} s | {best[0]:.3f} s | {best[1]:.3f} s | {best[2]:.2f} s | "
              f"{1000 * (best[0] + best[1]) / n:.2f} s |")
    print(f"per 1,000 images: {1000 * max(per_image):.2f} s of reading and computing (the largest of the datasets' "
          f"rates), plus the fixed cost of the figures and gallery and of starting the command")
    return 0


if __name__ == "__main__":
    sys.exit(main())
