#!/usr/bin/env python
"""Benchmark: one frame under every condition a scenario offers, side by side, through one render session.

Usage: python tools/bench_conditions.py [--scenario stages/district/scenario.usda]
       [--camera /World/Cameras/CCTV_Largo] [--time-code 24] [--width 1280 --height 960] [--spp 16]
       [--variant llvm_ad_rgb]

Prints, per condition in display order: whether the session loaded the scene (first load), reloaded it
(the sun went up or down, or wetness or snow cover changed: see synthua_usd.backends.mitsuba.weather_scene)
or swapped the condition in place (traverse() parameters), and the seconds of that step, of the label pass,
of the RGB pass and of the image-space weather (fog, rain, exposure); then the frame's EV100. Then swaps in
place once more (sunset -> clear_day -> day_fog) and the mean reload against the mean in-place swap.
Not a test: the numbers depend on the machine; compare those measured in the same run.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--camera", default="/World/Cameras/CCTV_Largo")
    parser.add_argument("--time-code", type=float, default=24.0)
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=960)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--variant", default=None)
    args = parser.parse_args()

    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.conditions import display_order
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.conditions import condition_names, read_condition
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(args.scenario)
    snapshot = StageReader(stage, ClassMap.default()).snapshot(args.time_code)
    camera = read_camera(stage, args.camera, args.time_code)
    conditions = {name: read_condition(stage, name) for name in display_order(condition_names(stage))}
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=args.spp, variant=args.variant))
    print(f"{args.scenario} {args.camera} at {args.time_code:g}: {args.width}x{args.height}, {args.spp} spp, "
          f"{session.variant}, {snapshot.triangle_count():,} triangles, {len(snapshot.meshes)} meshes")
    print(f"{'condition':16} {'step':>7} {'step s':>7} {'labels s':>8} {'rgb s':>7} {'weather s':>9} {'frame s':>8} "
          f"{'EV100':>6}")
    reloads, swaps, first_labels = [], [], None

    def frame(name: str) -> None:
        nonlocal first_labels
        loads = session.loads
        t0 = time.perf_counter()
        rendered = session.render(snapshot, camera, condition=conditions[name])
        total = time.perf_counter() - t0
        s = rendered.seconds
        if "update" in s:
            step, seconds = "swap", s["update"]
            swaps.append(seconds)
        else:
            step, seconds = ("load" if loads == 0 else "reload"), s["load"]
            if loads:
                reloads.append(seconds)
        labels = rendered.class_ids.tobytes() + rendered.instance_ids.tobytes()
        first_labels = first_labels or labels
        same = "" if labels == first_labels else "  LABELS DIFFER"
        print(f"{name:16} {step:>7} {seconds:7.3f} {s['labels']:8.3f} {s['rgb']:7.2f} {s['weather']:9.3f} "
              f"{total:8.2f} {rendered.exposure.ev100:6.2f}{same}")

    for name in conditions:
        frame(name)
    print("in-place swaps again:")
    for name in ("sunset", "clear_day", "day_fog"):
        if name in conditions:
            frame(name)
    if reloads and swaps:
        print(f"reload mean {statistics.mean(reloads):.3f} s ({len(reloads)}) vs in-place swap mean "
              f"{statistics.mean(swaps):.3f} s ({len(swaps)}); loads {session.loads}, reloads {session.reloads}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
