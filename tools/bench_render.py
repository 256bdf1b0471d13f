#!/usr/bin/env python
"""Benchmark: render the demo scenario's cameras at full size and report where the time goes.

Usage: python tools/bench_render.py [--width 1280 --height 960 --spp 64 --variant llvm_ad_rgb]

Prints, per camera: translate+load, label pass, RGB pass and other (read stage, write files) seconds, and the share of label
pixels that agree with an independent Embree ray cast (needs the test extra `embreex`). Not a test: the
numbers depend on the machine; compare runs on the same one.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "scenario.usda")
    parser.add_argument("--cameras", nargs="+", default=["/World/Cameras/CCTV", "/World/Cameras/PedestrianEye"])
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=960)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--frame", type=float, default=24)
    parser.add_argument("--variant", default=None)
    args = parser.parse_args()

    from reference_raycast import reference_labels
    from synthua_usd.pipeline.frame import FrameRequest, run_frame

    print(f"{'camera':32} {'variant':12} {'load s':>7} {'labels s':>8} {'rgb s':>7} {'other s':>7} {'total s':>7} "
          f"{'class agree':>12} {'inst agree':>11}")
    for camera in args.cameras:
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            result = run_frame(FrameRequest(stage_path=args.scenario, out_dir=Path(tmp), camera_path=camera,
                                            frame=args.frame, width=args.width, height=args.height, spp=args.spp,
                                            variant=args.variant))
            total = time.perf_counter() - t0
        s = result.rendered.seconds
        other = total - sum(s.values())  # opening and reading the stage, writing files
        ref_class, ref_inst = reference_labels(result.snapshot, result.camera, args.width, args.height)
        ca = np.mean(ref_class == result.rendered.class_ids)
        ia = np.mean(ref_inst == result.rendered.instance_ids)
        print(f"{camera:32} {result.rendered.variant:12} {s['translate_load']:7.2f} {s['labels']:8.3f} "
              f"{s['rgb']:7.2f} {other:7.2f} {total:7.2f} {ca:12.6%} {ia:11.6%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
