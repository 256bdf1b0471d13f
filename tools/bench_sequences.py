#!/usr/bin/env python
"""Benchmark: what a frame of a tracking sequence costs against a lone image, measured side by side.

Usage: python tools/bench_sequences.py [--scenario stages/district/scenario.usda] [--camera /World/Cameras/CCTV_Largo]
       [--width 640 --height 480] [--spp 8] [--frames 12] [--images 3] [--json docs/measured/bench_sequences.json]

Both through the workers `synthua generate` runs (render, amodal masks, annotation, files):

* a sequence: one worker renders --frames consecutive frames (a crowd populated for them, 10 fps) from one loaded
  scene: the first frame loads it, every later one only updates the sensor and what moved;
* lone images: --images times, a fresh worker (a new stage, reader and render session) renders one frame of the same
  view, as a dataset image does when it is the only one of its shard; interleaved with the sequence's frames, so
  that a change of the machine's load touches both alike.

Reported: the mean frame after the first, the mean lone image, their ratio, and where the time went. Not a test:
the numbers depend on the machine; the ratio comes from one run.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--camera", default="/World/Cameras/CCTV_Largo")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--spp", type=int, default=8)
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--images", type=int, default=3)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()

    from synthua_usd.dataset.config import GenerationConfig
    from synthua_usd.dataset.layout import cityscapes_city
    from synthua_usd.dataset.sequences import PlannedFrame
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline import sequences as seqs
    from synthua_usd.pipeline.dataset_worker import FLUSH, WorkerJob
    from synthua_usd.usd.stage_io import open_stage

    class_map = ClassMap.default()
    config = GenerationConfig.from_document({
        "name": "bench", "images": 0, "render": {"width": args.width, "height": args.height, "spp": args.spp},
        "sequences": {"cameras": [args.camera], "seeds": [0], "duration_s": args.frames / 10.0, "fps": 10.0}})
    stage = open_stage(args.scenario)
    plan = seqs.plan_stage_sequences(stage, config)[0]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "ds"
        t0 = time.perf_counter()
        crowds = seqs.write_crowds(stage, config, class_map, out, plan.time_codes[0], plan.time_codes)
        crowd_s = time.perf_counter() - t0
        render = RenderConfig(width=args.width, height=args.height, spp=args.spp)
        worker = WorkerJob(scenario=str(args.scenario.resolve()), out_dir=str(out), render=render, config=config,
                           class_map_document=class_map.document(), city=cityscapes_city("bench"))
        job = seqs.sequence_job(worker, crowds, plan.time_codes[-1])
        print(f"{args.scenario.name} {args.camera} {args.width}x{args.height} {args.spp} spp + OIDN; the sequence's crowd "
              f"populated and authored in {crowd_s:.1f} s ({args.frames} frames at 10 fps)")
        frames, lone = [], []
        state = seqs.init_sequence_worker(job)
        # Lone images interleaved with the sequence's frames (after frames 2, 2 + step, ...): a change of the
        # machine's load touches both alike.
        step = max(1, (args.frames - 1) // max(args.images, 1))
        lone_after = {2 + j * step for j in range(args.images)}
        for k in range(1, args.frames + 1):
            t0 = time.perf_counter()
            seqs.work_frame(state, PlannedFrame(plan, k))
            if k == args.frames:
                seqs.work_frame(state, FLUSH)
            frames.append(time.perf_counter() - t0)
            print(f"sequence frame {k:3d}: {frames[-1]:6.2f} s", flush=True)
            if k in lone_after or (k == args.frames and len(lone) < args.images):
                t0 = time.perf_counter()
                fresh = seqs.init_sequence_worker(job)
                seqs.work_frame(fresh, PlannedFrame(plan, k))
                seqs.work_frame(fresh, FLUSH)
                lone.append(time.perf_counter() - t0)
                del fresh
                print(f"lone image {len(lone)}: {lone[-1]:6.2f} s (a fresh worker: stage, reader, scene load)",
                      flush=True)
    steady = statistics.mean(frames[1:]) if len(frames) > 1 else frames[0]
    alone = statistics.mean(lone)
    print(f"\nmean sequence frame after the first: {steady:.2f} s; mean lone image: {alone:.2f} s; a frame costs "
          f"{steady / alone:.2f} of a lone image ({alone / steady:.2f}x faster); the first frame {frames[0]:.2f} s")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"scenario": args.scenario.name, "camera": args.camera,
                                         "size": [args.width, args.height], "spp": args.spp,
                                         "frames_s": frames, "lone_images_s": lone, "crowd_s": crowd_s,
                                         "mean_frame_s": steady, "mean_lone_image_s": alone,
                                         "frame_share_of_lone_image": steady / alone}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
