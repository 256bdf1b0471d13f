#!/usr/bin/env python
"""Benchmark: two scenarios rendered side by side, interleaved, with the ratio of their times and memory.

Usage: python tools/bench_render_pair.py BEFORE.usda AFTER.usda [--camera /World/Cameras/CCTV_Largo]
       [--width 640 --height 480] [--spp 16] [--time-codes 1 24 48] [--rounds 3] [--variant llvm_ad_rgb]

Each round runs one fresh process per scenario, alternating (before, after, before, ...), so both see the
same machine load. A process opens the scenario, loads it at the first time code (read + translate + load),
then renders the camera at every time code through one render session (labels and RGB) and reports, per
frame, the wall seconds of the read, the per-frame update, the label pass and the RGB pass, the frame's CPU
seconds (all threads: less sensitive than wall time to other processes on a shared machine), and its own
peak resident set size. Printed: per scenario the median over rounds of each measure, the triangles and
meshes of the snapshot (agents' share apart), and the after/before ratios. Not a test: numbers depend on
the machine; the ratios are what to compare.
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

AGENTS = "/World/Agents"


def child(args: argparse.Namespace) -> dict:
    """Measure one scenario in this process (see the module's docstring)."""
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(args.child)
    reader = StageReader(stage, ClassMap.default())
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=args.spp, variant=args.variant))
    frames = []
    for tc in args.time_codes:
        c0, t0 = time.process_time(), time.perf_counter()
        snapshot = reader.snapshot(tc)
        read = time.perf_counter() - t0
        frame = session.render(snapshot, read_camera(stage, args.camera, tc))
        frames.append({"time_code": tc, "read": read, **frame.seconds, "cpu": time.process_time() - c0})
    agents = [m for m in snapshot.meshes if m.prim_path.startswith(AGENTS + "/")]
    return {"frames": frames, "meshes": len(snapshot.meshes), "triangles": sum(len(m.triangles) for m in snapshot.meshes),
            "agent_meshes": len(agents), "agent_triangles": sum(len(m.triangles) for m in agents),
            "persons": sum(1 for i in snapshot.instances if i.class_name == "person"),
            "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def summary(run: dict) -> dict[str, float]:
    """One process's measures: first load (read + load), then means over the later frames."""
    first, later = run["frames"][0], run["frames"][1:] or run["frames"]
    mean = lambda key: statistics.fmean(f.get(key, 0.0) for f in later)  # noqa: E731
    return {"first load s": first["read"] + first["load"], "update s": mean("read") + mean("update"),
            "  of which read s": mean("read"),
            "labels s": mean("labels"), "rgb s": mean("rgb"),
            "frame s": statistics.fmean(f["read"] + f.get("update", 0.0) + f["labels"] + f["rgb"] for f in later),
            "frame cpu s": mean("cpu"), "peak RSS MiB": run["peak_rss_mib"]}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", type=Path, nargs="*", help="BEFORE and AFTER scenario files")
    parser.add_argument("--camera", default="/World/Cameras/CCTV_Largo")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--time-codes", type=float, nargs="+", default=[1.0, 24.0, 48.0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--variant", default=None)
    parser.add_argument("--child", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(args)))
        return 0
    if len(args.scenarios) != 2:
        parser.error("give two scenarios: BEFORE AFTER")
    common = ["--camera", args.camera, "--width", str(args.width), "--height", str(args.height), "--spp", str(args.spp),
              "--time-codes", *map(str, args.time_codes)] + (["--variant", args.variant] if args.variant else [])
    runs: dict[Path, list[dict]] = {s: [] for s in args.scenarios}
    for r in range(args.rounds):
        for scenario in (args.scenarios if r % 2 == 0 else args.scenarios[::-1]):
            out = subprocess.run([sys.executable, __file__, "--child", str(scenario), *common], check=True,
                                 capture_output=True, text=True).stdout
            runs[scenario].append(json.loads(out.strip().splitlines()[-1]))
            s = summary(runs[scenario][-1])
            print(f"round {r + 1} {scenario}: " + ", ".join(f"{k} {v:.2f}" for k, v in s.items()), flush=True)
    medians = {}
    for scenario, rs in runs.items():
        per = [summary(x) for x in rs]
        medians[scenario] = {k: statistics.median(p[k] for p in per) for k in per[0]}
        last = rs[-1]
        print(f"{scenario}: {last['meshes']} meshes, {last['triangles']:,} triangles; agents {last['agent_meshes']} "
              f"meshes, {last['agent_triangles']:,} triangles, {last['persons']} persons")
    before, after = (medians[s] for s in args.scenarios)
    print(f"{'median over ' + str(args.rounds) + ' rounds':24} {'before':>9} {'after':>9} {'ratio':>7}")
    for key in before:
        print(f"{key:24} {before[key]:9.2f} {after[key]:9.2f} {after[key] / before[key]:7.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
