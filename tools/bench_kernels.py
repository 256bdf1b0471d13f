#!/usr/bin/env python
"""Benchmark: what a new randomised scene costs Dr.Jit: kernel compiles, kernel size, tracing, for each image.

Usage:
  python tools/bench_kernels.py [--scenario stages/district/scenario.usda] [--config configs/sim2real.json]
      [--views 0:clear_day 1:clear_day 1:snow 2:day_rain_fog ...] [--width 320 --height 240 --spp 4] [--json OUT]

Each view (``seed:condition``) is given its randomisation (the config's ``randomise`` block) on one stage, read and
rendered (RGB + OIDN) by one render session in this process, as a dataset worker renders its images, with Dr.Jit's
kernel history on: per view the seconds of LLVM kernel compiles (cache misses: codegen + backend time), the largest
kernel's operations (the path tracer's megakernel), the BSDFs and shapes of the loaded scene, and the seconds of one
more render of the same view through a 4x4 film (tracing and launching the kernels: what every image pays before a
ray is traced), and of tracing one full ``scene.ray_intersect`` of 16 rays (``si s``: the surface interaction is a
call over every shape, traced once per shape, so it grows with the scene's shapes; the preliminary intersection of
the label pass is not). Run it with an empty kernel cache (a fresh ``HOME``) to see a first run's compiles; run it
with the code of another revision (``PYTHONPATH=<a worktree of REV>``) to compare. Not a test.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog="\n".join(__doc__.splitlines()[2:5]))
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--config", type=Path, default=REPO / "configs" / "sim2real.json")
    parser.add_argument("--camera", default="/World/Cameras/PedestrianEye_AidUser")
    parser.add_argument("--views", nargs="+", default=["0:clear_day", "0:clear_day", "1:clear_day", "1:snow",
                                                       "2:day_rain_fog", "3:sunset"])
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--spp", type=int, default=4)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()

    import drjit as dr

    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.dataset.config import GenerationConfig
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline.randomiser import Randomiser
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.conditions import read_condition
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    config = GenerationConfig.load(args.config)
    class_map = ClassMap.default()
    stage = open_stage(args.scenario)
    reader = StageReader(stage, class_map)
    randomiser = Randomiser(stage, config.randomise, class_map, (args.width, args.height))
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=args.spp, denoise=True,
                                         max_depth=config.render.max_depth or 6))
    mi = session.mi
    small = mi.load_dict({"type": "perspective", "film": {"type": "hdrfilm", "width": 4, "height": 4,
                                                          "rfilter": {"type": "box"}},
                          "sampler": {"type": "independent", "sample_count": args.spp}})
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    rows = []
    print(f"{'view':18} {'render s':>9} {'compile s':>10} {'misses':>7} {'kernel ops':>11} {'BSDFs':>6} "
          f"{'shapes':>7} {'trace s':>8} {'si s':>6}")
    for view in args.views:
        seed, condition = view.split(":")
        randomiser.apply(int(seed), args.camera, 24.0, condition, None)
        snapshot = reader.snapshot(24.0)
        camera = read_camera(stage, args.camera, 24.0)
        dr.kernel_history()
        t0 = time.perf_counter()
        session.render(snapshot, camera, condition=read_condition(stage, condition), seed=int(seed))
        seconds = time.perf_counter() - t0
        history = [k for k in dr.kernel_history() if "hash" in k]
        misses = [k for k in history if not k.get("cache_hit")]
        compile_s = sum(k.get("codegen_time", 0.0) + k.get("backend_time", 0.0) for k in misses) / 1000
        operations = max((k.get("operation_count", 0) for k in history), default=0)
        scene = session.mitsuba_scene
        bsdfs = len({str(s.bsdf()) for s in scene.shapes()})
        t0 = time.perf_counter()
        dr.eval(mi.render(scene, sensor=small, spp=args.spp, seed=1))
        dr.sync_thread()
        trace_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        si = scene.ray_intersect(dr.zeros(mi.Ray3f, 16))
        dr.eval(si.t, si.n, si.uv)
        dr.sync_thread()
        si_s = time.perf_counter() - t0
        rows.append({"view": view, "render_s": seconds, "compile_s": compile_s, "misses": len(misses),
                     "kernel_operations": operations, "bsdfs": bsdfs, "shapes": len(scene.shapes()),
                     "trace_s": trace_s, "surface_interaction_trace_s": si_s})
        print(f"{view:18} {seconds:9.2f} {compile_s:10.2f} {len(misses):7d} {operations:11,d} {bsdfs:6d} "
              f"{len(scene.shapes()):7d} {trace_s:8.2f} {si_s:6.2f}", flush=True)
    if args.json is not None:
        args.json.write_text(json.dumps({"views": rows, "size": [args.width, args.height], "spp": args.spp},
                                        indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
