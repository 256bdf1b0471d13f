#!/usr/bin/env python
"""Benchmark: what people's looks cost in randomised images (hair, faces, fabrics with folds, shoes, smooth shading,
the skin's clear coat), measured side by side against the same images without them.

Usage: python tools/bench_looks.py [--scenario stages/district/scenario.usda] [--width 1280 --height 960]
       [--spp 32] [--scenes 2] [--views 3] [--rounds 2] [--settings plain,hair,looks]
       [--json docs/measured/bench_looks.json]

Three settings of the `randomise` block, everything else the same draws: ``plain`` (``looks`` and ``hair`` off: flat
colours, bald, faceted), ``hair`` (hair on, looks off) and ``looks`` (both on, the defaults). Each round runs one
fresh process per setting, the order rotating from round to round, and each process renders the same --scenes x --views images as
`synthua generate`'s worker does (a Randomiser, a StageReader, a RenderSession at the default quality: box filter,
OIDN): per image the randomisation (apply), the reader (read), the session's load (a new scene) or update (a view
of it), the label pass and the RGB pass. Reported: the medians over the rounds of each process's total and per-part
seconds, the hair/plain and looks/plain ratios, each process's peak resident memory, and CPU seconds (all threads; the figure to
trust on a shared machine). Not a test: the numbers depend on the machine; the ratios come from one run.
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

REPO = Path(__file__).resolve().parents[1]
SETTINGS = {"plain": {"looks": {"enabled": False}, "hair": {"enabled": False}}, "hair": {"looks": {"enabled": False}},
            "looks": {}}


def run_one(args) -> dict:
    """One process's measurements for ``args.setting``."""
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline.randomiser import Randomiser
    from synthua_usd.randomisation.config import RandomisationConfig
    from synthua_usd.usd.cameras import camera_paths, read_camera
    from synthua_usd.usd.conditions import read_condition
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    cpu0 = time.process_time()
    class_map = ClassMap.default()
    stage = open_stage(args.scenario)
    reader = StageReader(stage, class_map)
    config = RandomisationConfig.from_document({"seed": 0, **SETTINGS[args.setting]})
    randomiser = Randomiser(stage, config, class_map, (args.width, args.height))
    session = RenderSession(RenderConfig(width=args.width, height=args.height,
                                         **({} if args.spp is None else {"spp": args.spp})))
    cameras = camera_paths(stage)
    parts: dict[str, float] = {"apply": 0.0, "read": 0.0, "load": 0.0, "update": 0.0, "labels": 0.0, "rgb": 0.0}
    people = meshes = textured = 0
    t_start = time.perf_counter()
    for seed in range(args.scenes):
        for k in range(args.views):
            path = cameras[(seed + k) % len(cameras)]
            t0 = time.perf_counter()
            drawn = randomiser.apply(seed, path, 24.0, "clear_day")
            t1 = time.perf_counter()
            snapshot = reader.snapshot(24.0)
            t2 = time.perf_counter()
            frame = session.render(snapshot, read_camera(stage, path, 24.0), condition=read_condition(stage, "clear_day"),
                                   seed=seed)
            parts["apply"] += t1 - t0
            parts["read"] += t2 - t1
            for name in ("load", "update", "labels", "rgb"):
                parts[name] += frame.seconds.get(name, 0.0)
            if k == 0:
                people += len(drawn.scene.cast)
                crowd = [m for m in snapshot.meshes if "/Randomisation/Crowd/" in m.prim_path]
                meshes += len(crowd)
                textured += sum(m.uvs is not None for m in crowd)
    total = time.perf_counter() - t_start
    return {"setting": args.setting, "images": args.scenes * args.views, "total_s": total, "parts_s": parts,
            "cpu_s": time.process_time() - cpu0, "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "people_per_scene": people / args.scenes, "crowd_meshes_per_scene": meshes / args.scenes,
            "textured_meshes_per_scene": textured / args.scenes, "spp": session.config.spp}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=960)
    parser.add_argument("--spp", type=int, default=None, help="RGB samples [default: the default quality]")
    parser.add_argument("--scenes", type=int, default=2)
    parser.add_argument("--views", type=int, default=3)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--settings", default=",".join(SETTINGS),
                        help=f"which settings to run, comma-separated, plain first [default: {','.join(SETTINGS)}]")
    parser.add_argument("--json", type=Path, help="write the measurements here")
    parser.add_argument("--setting", choices=sorted(SETTINGS), help=argparse.SUPPRESS)  # one process's side
    args = parser.parse_args()
    order = tuple(s for s in args.settings.split(",") if s)
    if order[:1] != ("plain",) or not set(order) <= set(SETTINGS) or len(order) < 2:
        parser.error(f"--settings: {args.settings!r}; expected plain and one or more of hair, looks")
    if args.setting:
        print(json.dumps(run_one(args)))
        return 0

    runs: dict[str, list[dict]] = {name: [] for name in order}
    for r in range(args.rounds):
        for setting in order[r % len(order):] + order[:r % len(order)]:
            command = [sys.executable, __file__, "--setting", setting, "--scenario", str(args.scenario), "--width",
                       str(args.width), "--height", str(args.height), "--scenes", str(args.scenes), "--views",
                       str(args.views), *(["--spp", str(args.spp)] if args.spp else [])]
            out = subprocess.run(command, check=True, capture_output=True, text=True)
            result = json.loads(out.stdout.strip().splitlines()[-1])
            runs[setting].append(result)
            print(f"round {r} {setting:5}: {result['total_s']:7.1f} s for {result['images']} images, "
                  f"cpu {result['cpu_s']:7.1f} s, peak {result['peak_rss_mib']:6.0f} MiB, "
                  + ", ".join(f"{k} {v:.1f}" for k, v in result["parts_s"].items()), flush=True)

    def median(setting: str, key: str, part: str | None = None) -> float:
        return statistics.median(r["parts_s"][part] if part else r[key] for r in runs[setting])

    print(f"\n{args.scenario.name}, {args.width}x{args.height}, {runs['looks'][0]['spp']} spp + OIDN, "
          f"{args.scenes} scenes x {args.views} views, medians of {args.rounds} rounds")
    others = order[1:]
    print(f"{'measure':34} " + " ".join(f"{s:>10}" for s in order) + " " + " ".join(f"{s + '/plain':>12}" for s in others))
    rows = [("wall seconds, all images", "total_s", None), ("CPU seconds (all threads)", "cpu_s", None),
            ("peak resident memory, MiB", "peak_rss_mib", None)]
    rows += [(f"  of which {part}", "parts_s", part) for part in ("apply", "read", "load", "update", "labels", "rgb")]
    table = {}
    for name, key, part in rows:
        values = {setting: median(setting, key, part) for setting in order}
        a = values["plain"]
        ratios = {f"{s}_ratio": values[s] / a if a else None for s in others}
        table[name.strip()] = {**values, **ratios}
        print(f"{name:34} " + " ".join(f"{values[s]:10.2f}" for s in order) + " "
              + " ".join(f"{r:12.3f}" if r is not None else f"{'-':>12}" for r in ratios.values()))
    for key in ("people_per_scene", "crowd_meshes_per_scene", "textured_meshes_per_scene"):
        print(f"{key:34} " + " ".join(f"{runs[setting][0][key]:10.1f}" for setting in order))
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"scenario": args.scenario.name, "size": [args.width, args.height],
                                         "scenes": args.scenes, "views": args.views, "rounds": args.rounds,
                                         "table": table, "runs": runs}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
