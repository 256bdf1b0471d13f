#!/usr/bin/env python
"""Benchmark: what scene randomisation costs per image, against a default-quality frame, measured side by side.

Usage: python tools/bench_randomise.py [--scenario stages/district/scenario.usda] [--width 1280 --height 960]
       [--spp 32] [--scenes 3] [--views 6] [--images-per-scene 4 8 16] [--frames 2] [--variant llvm_ad_rgb]
       [--json docs/measured/bench_randomise.json]

One worker's path, as `synthua generate` runs it (a Randomiser over the stage, a StageReader, a RenderSession):

* a view of the same scene (another camera or time code of one seed): drawing the camera's jitter and the crowd's
  placement, authoring the view layer and moving it into the stage (``apply``), the reader re-placing what moved
  (``read``), the session updating sensor and vertices in place (``update``);
* a new scene (the next seed): drawing and authoring the cast, its prototypes and the twin's material variants,
  the reader reading the new crowd, the session loading the scene afresh (``load``);
* a default-quality frame (update + labels + RGB at --spp, box filter, OIDN), rendered --frames times.

Reported: each part's mean, the per-view cost and the per-scene cost as shares of the frame, and the per-image
cost of a dataset with K images per scene, (scene cost + (K - 1) x view cost) / K, as a share of the frame
(the issue's target: at most 10 %). Not a test: the numbers depend on the machine; the ratios come from one run.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=960)
    parser.add_argument("--spp", type=int, default=None, help="RGB samples of the frame [default: the default quality]")
    parser.add_argument("--scenes", type=int, default=3, help="scenes (seeds) to switch to")
    parser.add_argument("--views", type=int, default=6, help="views of each scene (cameras x time codes)")
    parser.add_argument("--images-per-scene", type=int, nargs="+", default=[4, 8, 16])
    parser.add_argument("--frames", type=int, default=2, help="default-quality frames to time")
    parser.add_argument("--condition", default="clear_day")
    parser.add_argument("--variant", default=None)
    parser.add_argument("--json", type=Path, help="write the measurements here")
    args = parser.parse_args()

    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline.randomiser import Randomiser
    from synthua_usd.randomisation.config import RandomisationConfig
    from synthua_usd.usd.cameras import camera_paths, read_camera
    from synthua_usd.usd.conditions import read_condition
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    class_map = ClassMap.default()
    stage = open_stage(args.scenario)
    reader = StageReader(stage, class_map)
    t0 = time.perf_counter()
    randomiser = Randomiser(stage, RandomisationConfig(), class_map, (args.width, args.height))
    setup = time.perf_counter() - t0
    config = RenderConfig(width=args.width, height=args.height, variant=args.variant,
                          **({} if args.spp is None else {"spp": args.spp}))
    labels = RenderSession(RenderConfig(width=args.width, height=args.height, spp=1, variant=args.variant))
    cameras = camera_paths(stage)
    views = [(cameras[k % len(cameras)], 24.0 if k < len(cameras) else 12.0) for k in range(args.views)]
    print(f"{args.scenario}: {args.width}x{args.height}, frame at {config.spp} spp + OIDN, {labels.variant}; "
          f"randomiser set up in {setup:.2f} s (walkable area, recolourable objects: once per worker)")
    scene_parts: dict[str, list[float]] = {"apply": [], "read": [], "load": []}
    view_parts: dict[str, list[float]] = {"apply": [], "read": [], "update": []}
    for seed in range(args.scenes):
        for k, (path, tc) in enumerate(views):
            t0 = time.perf_counter()
            randomiser.apply(seed, path, tc, args.condition)
            t1 = time.perf_counter()
            snapshot = reader.snapshot(tc)
            t2 = time.perf_counter()
            condition = read_condition(stage, args.condition)
            frame = labels.render(snapshot, read_camera(stage, path, tc), rgb=False, condition=condition, seed=seed)
            moved = frame.seconds.get("load", frame.seconds.get("update", 0.0))
            parts = scene_parts if k == 0 else view_parts
            parts["apply"].append(t1 - t0)
            parts["read"].append(t2 - t1)
            parts["load" if k == 0 else "update"].append(moved)
            kind = "new scene" if k == 0 else "view"
            print(f"seed {seed} {path:38} t {tc:4g} {kind:9}: apply {t1 - t0:6.3f} s, read {t2 - t1:6.3f} s, "
                  f"{'load' if k == 0 else 'update'} {moved:6.3f} s")
    session = RenderSession(config)
    frames = []
    path, tc = views[0]
    randomiser.apply(0, path, tc, args.condition)
    snapshot = reader.snapshot(tc)
    condition = read_condition(stage, args.condition)
    session.render(snapshot, read_camera(stage, path, tc), condition=condition, seed=0)  # the first load, not counted
    for k in range(args.frames):
        path, tc = views[(k + 1) % len(views)]
        randomiser.apply(0, path, tc, args.condition)
        snapshot = reader.snapshot(tc)
        condition = read_condition(stage, args.condition)
        t0 = time.perf_counter()
        rendered = session.render(snapshot, read_camera(stage, path, tc), condition=condition, seed=k)
        frames.append(time.perf_counter() - t0)
        print(f"default-quality frame {path} t {tc:g}: {frames[-1]:.2f} s ({', '.join(f'{a} {b:.2f}' for a, b in rendered.seconds.items())})")
    frame = statistics.mean(frames)
    mean = {f"scene_{k}": statistics.mean(v) for k, v in scene_parts.items()}
    mean |= {f"view_{k}": statistics.mean(v) for k, v in view_parts.items() if v}
    scene_cost = mean["scene_apply"] + mean["scene_read"] + mean["scene_load"]
    view_cost = mean.get("view_apply", 0.0) + mean.get("view_read", 0.0) + mean.get("view_update", 0.0)
    print()
    print(f"{'measure':58} {'seconds':>9} {'of a frame':>11}")
    rows = [("default-quality frame (update + labels + RGB + OIDN)", frame),
            ("view of a scene: apply (draw + author + transfer)", mean.get("view_apply", 0.0)),
            ("view of a scene: read (re-place what moved)", mean.get("view_read", 0.0)),
            ("view of a scene: session update in place", mean.get("view_update", 0.0)),
            ("view of a scene, in all", view_cost),
            ("new scene: apply (cast, prototypes, materials, view)", mean["scene_apply"]),
            ("new scene: read", mean["scene_read"]),
            ("new scene: session load", mean["scene_load"]),
            ("new scene, in all", scene_cost)]
    per_image = {}
    for k in args.images_per_scene:
        cost = (scene_cost + (k - 1) * view_cost) / k
        per_image[k] = cost
        rows.append((f"per image, {k} images per scene", cost))
    for name, value in rows:
        print(f"{name:58} {value:9.3f} {100 * value / frame:10.1f} %")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({
            "scenario": str(args.scenario.relative_to(REPO)) if args.scenario.is_relative_to(REPO) else str(args.scenario),
            "size": [args.width, args.height], "spp": config.spp, "variant": labels.variant,
            "frame_s": frame, "frames_s": frames, "means_s": mean, "view_cost_s": view_cost, "scene_cost_s": scene_cost,
            "per_image_s": {str(k): v for k, v in per_image.items()},
            "per_image_share_of_frame": {str(k): v / frame for k, v in per_image.items()},
            "scene_parts_s": scene_parts, "view_parts_s": view_parts}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
