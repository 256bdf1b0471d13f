#!/usr/bin/env python
"""Benchmark: memory over many renders through one render session (it must stay flat).

Usage: python tools/bench_memory.py [--scenario stages/scenario.usda] [--renders 200] [--width 320 --height 240]

Renders the scenario's cameras at time codes cycling through its range (RGB at 1 spp and labels, as a
dataset worker does) and records the resident set size after each render. Prints the least-squares
slope of RSS over renders after a warm-up (KiB per render) and the total growth. Not a test: compare
runs on the same machine.
"""

from __future__ import annotations

import argparse
import gc
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def rss_kib() -> int:
    with open("/proc/self/status", encoding="ascii") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS in /proc/self/status")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "scenario.usda")
    parser.add_argument("--renders", type=int, default=200)
    parser.add_argument("--warm-up", type=int, default=20)
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--variant", default=None)
    args = parser.parse_args()

    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.cameras import camera_paths, read_camera
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage, time_range

    stage = open_stage(args.scenario)
    reader = StageReader(stage, ClassMap.default())
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=1, variant=args.variant))
    start, end = time_range(stage) or (1.0, 1.0)
    cameras = camera_paths(stage)
    rss = []
    for k in range(args.renders):
        tc = start + k % int(end - start + 1)
        snapshot = reader.snapshot(tc)
        session.render(snapshot, read_camera(stage, cameras[k % len(cameras)], tc))
        gc.collect()  # count what is still referenced, not garbage waiting for the collector
        rss.append(rss_kib())
    x = np.arange(args.warm_up, args.renders)
    slope = np.polyfit(x, np.array(rss[args.warm_up:], float), 1)[0]
    print(f"{args.scenario}: {args.renders} renders at {args.width}x{args.height} through one session "
          f"({session.variant}, {session.loads} load, {session.reloads} reloads)")
    print(f"RSS after warm-up ({args.warm_up} renders) {rss[args.warm_up - 1] / 1024:.1f} MiB, at the end "
          f"{rss[-1] / 1024:.1f} MiB; slope {slope:.1f} KiB/render")
    return 0


if __name__ == "__main__":
    sys.exit(main())
