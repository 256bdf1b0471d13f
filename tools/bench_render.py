#!/usr/bin/env python
"""Benchmark: render a scenario's cameras at several time codes through one render session.

Usage: python tools/bench_render.py [--scenario stages/district/scenario.usda] [--width 1280 --height 960]
       [--spp 64 (0: labels only)] [--time-codes 1 24 48] [--variant llvm_ad_rgb] [--no-check]

Prints, per frame: reading the stage at that time code, the session's first load or its per-frame update
(sensor and moving meshes through Mitsuba's traverse() parameters), the label pass, the RGB pass, and the
share of label pixels that agree with an independent Embree ray cast (tests/reference_raycast.py; skip
with --no-check). Then the first load against the mean update, and the update as a share of a frame.
Not a test: the numbers depend on the machine; compare ratios measured in the same run.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--cameras", nargs="+", help="camera prim paths [default: every camera of the stage]")
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=960)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--time-codes", type=float, nargs="+", default=[1.0, 24.0, 48.0])
    parser.add_argument("--variant", default=None)
    parser.add_argument("--no-check", action="store_true", help="skip the Embree label agreement")
    args = parser.parse_args()

    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.cameras import camera_paths, read_camera
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    t0 = time.perf_counter()
    stage = open_stage(args.scenario)
    reader = StageReader(stage, ClassMap.default())
    opened = time.perf_counter() - t0
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=max(args.spp, 1),
                                         variant=args.variant))
    cameras = args.cameras or camera_paths(stage)
    print(f"{args.scenario}: opened in {opened:.2f} s; {args.width}x{args.height}, {args.spp} spp, {session.variant}")
    print(f"{'camera':34} {'t':>4} {'read s':>7} {'load s':>7} {'update s':>8} {'labels s':>8} {'rgb s':>7} "
          f"{'class agree':>12} {'inst agree':>11}")
    loads, updates, frames = [], [], []
    for tc in args.time_codes:
        for cam_path in cameras:
            t0 = time.perf_counter()
            snapshot = reader.snapshot(tc)
            read = time.perf_counter() - t0
            camera = read_camera(stage, cam_path, tc)
            frame = session.render(snapshot, camera, rgb=args.spp > 0)
            s = frame.seconds
            total = read + sum(s.values())
            frames.append(total)
            (loads if "load" in s else updates).append(read + s.get("load", s.get("update", 0.0)))
            agree = ("", "")
            if not args.no_check:
                from reference_raycast import reference_labels

                ref_class, ref_inst = reference_labels(snapshot, camera, args.width, args.height)
                agree = (f"{np.mean(ref_class == frame.class_ids):.6%}", f"{np.mean(ref_inst == frame.instance_ids):.6%}")
            print(f"{cam_path:34} {tc:4g} {read:7.3f} {s.get('load', 0):7.2f} {s.get('update', 0):8.3f} "
                  f"{s['labels']:8.3f} {s.get('rgb', 0):7.2f} {agree[0]:>12} {agree[1]:>11}")
    if updates:
        mean_update = float(np.mean(updates))
        print(f"first load (read + translate + load): {loads[0]:.2f} s; per-frame update (read moving prims + sensor "
              f"+ meshes): mean {mean_update:.3f} s over {len(updates)} frames = {loads[0] / mean_update:.0f}x less; "
              f"update share of a frame: {mean_update / np.mean(frames[1:]):.1%}; reloads {session.reloads}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
