#!/usr/bin/env python
"""Benchmark: ``synthua composite`` images/min (and ``synthua cutouts`` cut-outs/min) beside ``synthua generate``
on the same machine, in one run.

Usage:
  python tools/bench_composite.py --bank BANK [--backgrounds PHOTOS] [--config configs/composite.json]
         [--images 600] [--workers 2] [--gen-images 6] [--json OUT.json] [--keep DIR]
  python tools/bench_composite.py --cutouts 24 [...]      # makes the bank too (configs/cutouts.json), timed
  python tools/bench_composite.py --drawn-bank [...]      # tests/bank_maker.py's drawn bank (a stand-in)

Runs, one after the other on the same machine: (1) ``synthua generate`` of the demo street
(``stages/scenario.usda``) with ``configs/demo.json`` at 640x480 (``--gen-images`` images, its other settings as
shipped), with ``--cutouts N`` then ``synthua cutouts`` of ``--cutouts-config`` (default ``configs/cutouts.json``)
with its ``count`` N on the command's default workers (the bank the composites then use), (2) ``synthua composite``
of BACKGROUNDS (default: ``../shared/data/real_photos/wheelchair_dev`` when
present, else 40 synthetic 640x480 photos) with ``--config`` (a temporary copy whose ``max_images`` is
``--images`` and output 640x480), and prints each one's images/min end to end (checks, workers' start, assembly
included) and over its make phase (the workers' run), their ratio, where the composite workers' time went, and the
load average before and after, and the CPU seconds each spent an image (this process and its workers): on a machine
shared with other jobs the wall-clock rates fall with the load, the CPU time an image much less. Not a test: compare
runs on the same machine and note its load.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DEV_PHOTOS = REPO.parent / "shared" / "data" / "real_photos" / "wheelchair_dev"


def cpu_seconds() -> float:
    """User + system CPU seconds of this process and its finished children (the workers, once joined)."""
    return sum(getattr(resource.getrusage(who), f) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
               for f in ("ru_utime", "ru_stime"))


class PhaseTimer:
    """Times the workers' phase of a run by wrapping ``run_shards`` (the library is not changed)."""

    def __init__(self) -> None:
        self.seconds = 0.0

    def install(self) -> None:
        from synthua_usd.pipeline import executors

        run_shards, timer = executors.run_shards, self

        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return run_shards(*args, **kwargs)
            finally:
                timer.seconds += time.perf_counter() - t0
        executors.run_shards = timed


def synthetic_photos(folder: Path, count: int = 40) -> Path:
    """``count`` 640x480 photos of a street-like gradient with noise (when no real photos are at hand)."""
    import numpy as np
    from PIL import Image

    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(0)
    rows = np.linspace(0, 1, 480)[:, None, None]
    for k in range(count):
        base = np.where(rows < 0.4, [150, 180, 230], [110 + k, 105, 100]) * (0.8 + 0.2 * rows)
        pixels = np.clip(base + rng.normal(0, 12, (480, 640, 3)), 0, 255).astype(np.uint8)
        Image.fromarray(pixels).save(folder / f"street_{k:03d}.jpg", quality=92)
    return folder


def run_generate(work: Path, images: int, workers: int) -> dict:
    from synthua_usd.pipeline.generate import GenerateRequest, generate

    doc = json.loads((REPO / "configs" / "demo.json").read_text(encoding="utf-8"))
    doc.update(images=images, workers=workers)
    doc["render"] = {**doc.get("render", {}), "width": 640, "height": 480}
    doc.pop("$schema", None)
    config = work / "generate.bench.json"
    config.write_text(json.dumps(doc), encoding="utf-8")
    timer = PhaseTimer()
    timer.install()
    t0, cpu0 = time.perf_counter(), cpu_seconds()
    summary = generate(GenerateRequest(scenario=REPO / "stages" / "scenario.usda", config_path=config,
                                       out_dir=work / "generated", workers=workers), show_progress=False)
    wall, cpu = time.perf_counter() - t0, cpu_seconds() - cpu0
    return {"images": summary.rendered, "wall_s": wall, "make_s": timer.seconds, "cpu_s": cpu,
            "cpu_s_per_image": cpu / max(1, summary.rendered),
            "images_per_min": 60 * summary.rendered / wall,
            "make_images_per_min": 60 * summary.rendered / timer.seconds,
            "render": f"640x480 {doc['render'].get('spp')} spp, configs/demo.json"}


def cutouts_config(work: Path, base: Path, count: int):
    """``base`` with its ``count`` set, written into ``work``: its path and the loaded config (a bad file is
    refused before anything is timed)."""
    from synthua_usd.pipeline.cutouts import CutoutsConfig

    CutoutsConfig.load(base)
    doc = json.loads(base.read_text(encoding="utf-8"))
    doc.pop("$schema", None)
    doc["count"] = count
    config = work / "cutouts.bench.json"
    config.write_text(json.dumps(doc), encoding="utf-8")
    return config, CutoutsConfig.load(config)


def run_cutouts(work: Path, config: Path, loaded) -> dict:
    from synthua_usd.pipeline.cutouts import default_workers, make_bank

    frame = loaded.frame
    workers = loaded.workers or default_workers()
    t0, cpu0 = time.perf_counter(), cpu_seconds()
    summary = make_bank(config, work / "bank", workers=workers)
    wall, cpu = time.perf_counter() - t0, cpu_seconds() - cpu0
    return {"cutouts": summary.cutouts, "workers": workers, "wall_s": wall, "cpu_s": cpu,
            "cpu_s_per_cutout": cpu / max(1, summary.cutouts), "cutouts_per_min": 60 * summary.cutouts / wall,
            "frame": f"{frame.width}x{frame.height} {frame.spp} spp" + (" + OIDN" if frame.denoise else ""),
            "bank": str(work / "bank")}


def run_composite(work: Path, backgrounds: Path, bank: Path, base: Path, images: int, workers: int) -> dict:
    from synthua_usd.pipeline.composite import CompositeRequest, composite

    doc = json.loads(base.read_text(encoding="utf-8"))
    doc.pop("$schema", None)
    doc.update(max_images=images, output={"width": 640, "height": 480})
    config = work / "composite.bench.json"
    config.write_text(json.dumps(doc), encoding="utf-8")
    timer = PhaseTimer()
    timer.install()
    t0, cpu0 = time.perf_counter(), cpu_seconds()
    summary = composite(CompositeRequest(backgrounds=backgrounds, bank=bank, config_path=config,
                                         out_dir=work / "composites", workers=workers), show_progress=False)
    wall, cpu = time.perf_counter() - t0, cpu_seconds() - cpu0
    busy = sum(summary.seconds.values()) or 1.0
    return {"images": summary.images, "pastes": summary.pastes, "wall_s": wall, "make_s": timer.seconds,
            "cpu_s": cpu, "cpu_s_per_image": cpu / max(1, summary.images),
            "images_per_min": 60 * summary.images / wall, "make_images_per_min": 60 * summary.images / timer.seconds,
            "worker_shares": {k: round(v / busy, 3) for k, v in summary.seconds.items()},
            "worker_seconds_per_image": busy / max(1, summary.images)}


def main() -> int:
    lines = __doc__.splitlines()
    parser = argparse.ArgumentParser(description=" ".join(lines[:2]), epilog="\n".join(lines[3:8]),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bank", type=Path, help="a bank written by `synthua cutouts`")
    parser.add_argument("--drawn-bank", action="store_true", help="use tests/bank_maker.py's drawn bank (a stand-in)")
    parser.add_argument("--cutouts", type=int, metavar="N", help="make a bank of N cut-outs first, timed, and use it")
    parser.add_argument("--cutouts-config", type=Path, default=REPO / "configs" / "cutouts.json",
                        help="the bank's config, its count set to --cutouts N [configs/cutouts.json]")
    parser.add_argument("--backgrounds", type=Path, default=None)
    parser.add_argument("--config", type=Path, default=REPO / "configs" / "composite.json")
    parser.add_argument("--images", type=int, default=600, help="composites to make [600]")
    parser.add_argument("--gen-images", type=int, default=6, help="images synthua generate renders [6]")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", type=Path, help="write the figures here too")
    parser.add_argument("--keep", type=Path, help="keep the datasets in this folder (must not exist)")
    args = parser.parse_args()
    if sum([args.bank is not None, args.drawn_bank, args.cutouts is not None]) != 1:
        parser.error("give one of --bank BANK, --cutouts N or --drawn-bank")
    if args.cutouts is not None and args.cutouts < 1:
        parser.error(f"--cutouts {args.cutouts}: expected at least 1")
    if args.cutouts is None and args.cutouts_config != parser.get_default("cutouts_config"):
        parser.error("--cutouts-config is the config of the bank --cutouts N makes: give --cutouts too")
    work = args.keep or Path(tempfile.mkdtemp(prefix="bench_composite_"))
    work.mkdir(parents=True, exist_ok=args.keep is None)
    try:
        bank = args.bank
        if args.cutouts is not None:
            from synthua_usd.core.errors import InputError

            try:
                cut_config, cut_loaded = cutouts_config(work, args.cutouts_config, args.cutouts)
            except (InputError, OSError, ValueError) as exc:
                parser.error(f"--cutouts {args.cutouts} of --cutouts-config {args.cutouts_config}: {exc}")
        if args.drawn_bank:
            sys.path.insert(0, str(REPO / "tests"))
            from bank_maker import write_bank

            bank = write_bank(work / "drawn_bank")
        backgrounds = args.backgrounds or (DEV_PHOTOS if DEV_PHOTOS.is_dir() else synthetic_photos(work / "photos"))
        load_before = os.getloadavg()
        generated = run_generate(work, args.gen_images, args.workers)
        cut = None
        if args.cutouts is not None:
            cut = run_cutouts(work, cut_config, cut_loaded)
            bank = Path(cut["bank"])
            if args.keep is None:
                cut["bank"] = None          # a temporary folder, gone after the run
        composited = run_composite(work, backgrounds, bank, args.config, args.images, args.workers)
        load_after = os.getloadavg()
    finally:
        if args.keep is None:
            shutil.rmtree(work, ignore_errors=True)
    ratio = composited["images_per_min"] / generated["images_per_min"]
    cpu_ratio = generated["cpu_s_per_image"] / composited["cpu_s_per_image"]
    result = {"cpus": os.cpu_count(), "workers": args.workers, "load_before": load_before, "load_after": load_after,
              "bank": "drawn (tests/bank_maker.py)" if args.drawn_bank else (
                  f"made: {args.cutouts} cut-outs" if cut else str(args.bank)), "cutouts": cut,
              "backgrounds": str(backgrounds), "config": str(args.config), "generate": generated,
              "composite": composited, "ratio": ratio, "cpu_ratio": cpu_ratio,
              "composite_images_per_min_on_idle_cores": 60 * os.cpu_count() / composited["cpu_s_per_image"]}
    print(f"{os.cpu_count()} CPUs, {args.workers} workers, load average {load_before[0]:.1f} before, "
          f"{load_after[0]:.1f} after")
    print(f"synthua generate (demo street, {generated['render']}): {generated['images']} images, "
          f"{generated['images_per_min']:.1f} images/min end to end, {generated['make_images_per_min']:.1f} over "
          f"rendering")
    if cut:
        result["cutouts_ratio"] = cut["cutouts_per_min"] / generated["images_per_min"]
        print(f"synthua cutouts ({args.cutouts_config.name}, {cut['frame']}, {cut['workers']} worker"
              f"{'s' if cut['workers'] > 1 else ''}): {cut['cutouts']} cut-outs, {cut['cutouts_per_min']:.1f} a minute "
              f"end to end ({cut['wall_s']:.1f} s), {cut['cpu_s_per_cutout']:.2f} CPU seconds a cut-out; "
              f"{result['cutouts_ratio']:.1f}x generate's images a minute")
    print(f"synthua composite ({result['bank']}, {backgrounds}, {args.config.name}): {composited['images']} "
          f"composites of 640x480 with {composited['pastes']} pastes, {composited['images_per_min']:.0f} images/min "
          f"end to end ({composited['wall_s']:.1f} s), {composited['make_images_per_min']:.0f} over the workers' run; "
          f"worker time {composited['worker_seconds_per_image'] * 1000:.0f} ms an image: "
          + ", ".join(f"{k} {100 * v:.0f} %" for k, v in composited["worker_shares"].items()))
    print(f"CPU seconds an image (all processes, end to end): generate {generated['cpu_s_per_image']:.2f}, composite "
          f"{composited['cpu_s_per_image']:.3f}: {result['composite_images_per_min_on_idle_cores']:.0f} composites/min "
          f"if the {os.cpu_count()} cores were this run's alone")
    print(f"ratio composite / generate: {ratio:.0f}x end to end, {cpu_ratio:.0f}x in CPU time an image")
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
