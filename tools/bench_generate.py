#!/usr/bin/env python
"""Benchmark: ``synthua generate`` end to end: throughput, where worker time goes, dataset size, memory.

Usage:
  python tools/bench_generate.py [--scenario stages/district/scenario.usda] [--config configs/district.json]
         [--images K] [--workers W] [--variant llvm_ad_rgb] [--out DIR] [--keep] [--no-progress]
  python tools/bench_generate.py --memory N [--scenario stages/scenario.usda] [--width 160 --height 120]
         [--workers W] [--out DIR] [--keep]
  python tools/bench_generate.py --base REV [--rounds R] --config configs/sim2real.json --images 48 --seeds 4
         --width 640 --height 480 --spp 8 --workers 2

Default mode: runs ``generate`` on a scenario with a generation config (a temporary copy whose ``images`` is
``--images K``, when given, with explicit per-condition / per-rig-type quota counts scaled down by the same
factor, largest remainder, so the config stays valid) and prints images/min (end to end, and over the render
phase alone), the phases' wall times (planning: the label pass scoring every view; rendering on the workers;
assembling the dataset files), the share of summed worker time in render (RGB + labels + amodal traces),
annotate and write (written on a thread while the next image renders, so it overlaps), the dataset's bytes
per image, and the peak memory of each worker.

``--memory N``: generates N images of the demo street (a temporary config from configs/demo.json: images N,
WIDTHxHEIGHT at 1 spp, time codes 1:48:1, as many seeds as N needs, quotas relaxed to balanced conditions,
QA flagging only, so that no rejected image is replaced by images of a later round)
and prints, per worker, its memory after 10 %, 50 % and 100 % of the images and the growth from 10 % to
100 %, which must stay near zero.

``--base REV``: the same job run with the code of git revision REV (a temporary worktree, through ``PYTHONPATH``,
with its own schemas) and with this tree, one after the other, ``--rounds`` times alternating, each run in a fresh
process with an empty Dr.Jit kernel cache (a fresh ``HOME``: a first run's compile costs count); prints each run's
images/min, wall and CPU seconds, the ratios (this tree against REV) and whether the two datasets are the same
bytes (sha256 of every file; ``generate.json``'s recorded scenario path aside). ``--width``, ``--height``, ``--spp``
and ``--seeds K`` (seeds 0..K-1) override the config's render size, samples and seeds in every mode.

Memory is given two ways: the peak each worker reports with its results (``GenerateSummary.peak_rss_mib``
and ``rss_trace``: its ``VmHWM`` on Linux), and each worker's ``/proc/PID/status`` read from here after
each of its results (VmRSS now, VmHWM; local executor only), which must agree. Not a test: compare runs on the same machine and note its load.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import resource
import shutil
import socket
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
MIB = 1024 * 1024


def proc_status_kib(pid: int) -> dict[str, int]:
    """VmRSS and VmHWM (KiB) of a process of this machine, or {} when it is gone."""
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as f:
            return {k: int(v.split()[0]) for k, v in (line.split(":", 1) for line in f)
                    if k in ("VmRSS", "VmHWM")}
    except (OSError, ValueError):
        return {}


class Probe:
    """Times the phases of ``generate`` and samples each worker's own memory after each of its results, by
    wrapping ``score_views``, ``run_shards`` and ``assemble`` (the library is not changed)."""

    def __init__(self) -> None:
        self.phase: dict[str, float] = {}
        #: After each result: (images delivered so far, worker, the worker's own images so far, its VmRSS KiB,
        #: its VmHWM KiB, the peak MiB GenerateSummary reports)
        self.samples: list[tuple[int, str, int, int, int, float]] = []
        self.delivered = 0
        self.own: dict[str, int] = {}
        self.rounds = 0
        #: Sum over render rounds of the round's wall seconds x its worker processes: the workers' capacity.
        self.capacity = 0.0

    def install(self) -> None:
        from synthua_usd.pipeline import executors
        from synthua_usd.pipeline import generate as gen
        from synthua_usd.pipeline.worker_protocol import ExecutorConfig

        probe = self

        def timed(name, fn):
            def wrapper(*args, **kwargs):
                t0 = time.perf_counter()
                try:
                    return fn(*args, **kwargs)
                finally:
                    probe.phase[name] = probe.phase.get(name, 0.0) + time.perf_counter() - t0
            return wrapper

        run_shards = executors.run_shards
        host = socket.gethostname()

        def run_shards_probed(shards, init, work, on_result, config=ExecutorConfig(), more=None):
            probe.rounds += 1

            def more_probed():
                following = more()
                probe.rounds += bool(any(following))
                return following

            t0, seen = time.perf_counter(), set()

            def on_result_probed(result):
                on_result(result)
                seen.add(result.worker)
                probe.delivered += len(result.value)
                probe.own[result.worker] = probe.own.get(result.worker, 0) + len(result.value)
                name, _, pid = result.worker.rpartition(":")
                status = proc_status_kib(int(pid)) if name == host and pid.isdigit() else {}
                probe.samples.append((probe.delivered, result.worker, probe.own[result.worker],
                                      status.get("VmRSS", 0), status.get("VmHWM", 0), result.peak_rss_mib))
            try:
                rounds = {} if more is None else {"more": more_probed}  # (a library from before rounds had none)
                return run_shards(shards, init, work, on_result_probed, config, **rounds)
            finally:
                probe.capacity += (time.perf_counter() - t0) * len(seen)

        executors.run_shards = timed("render", run_shards_probed)  # generate() imports it at call time
        try:  # the view scores' module; a --base revision before it scored in generate itself
            from synthua_usd.pipeline import view_scores
        except ImportError:
            gen.score_views = timed("plan", gen.score_views)
        else:
            view_scores.score_views = timed("plan", view_scores.score_views)
        gen.assemble = timed("assemble", gen.assemble)


def scaled_counts(counts: dict, factor: float) -> dict:
    """Explicit quota counts scaled by ``factor`` (< 1), largest remainder, summing to floor(sum × factor)."""
    exact = {k: v * factor for k, v in counts.items()}
    out = {k: math.floor(x) for k, x in exact.items()}
    left = math.floor(sum(exact.values()) + 1e-9) - sum(out.values())
    for k in sorted(exact, key=lambda k: -(exact[k] - out[k]))[:max(0, left)]:
        out[k] += 1
    return out


def district_config(base: Path, images: int | None, width: int | None = None, height: int | None = None,
                    spp: int | None = None, seeds: int | None = None) -> tuple[dict, list[str]]:
    doc = json.loads(base.read_text(encoding="utf-8"))
    notes = []
    render = dict(doc.get("render") or {})
    for key, value in (("width", width), ("height", height), ("spp", spp)):
        if value is not None and render.get(key) != value:
            render[key] = value
            notes.append(f"render.{key} {value}")
    doc["render"] = render
    if seeds is not None:
        doc["seeds"] = list(range(seeds))
        notes.append(f"seeds 0..{seeds - 1}")
    if images is not None and images != doc["images"]:
        factor = images / doc["images"]
        notes.append(f"images {doc['images']} -> {images}")
        for key in ("per_condition", "per_rig_type"):
            value = doc.get("quotas", {}).get(key)
            if isinstance(value, dict) and factor < 1:
                doc["quotas"][key] = scaled_counts(value, factor)
                notes.append(f"quotas.{key} scaled x{factor:g}: {doc['quotas'][key]}")
        doc["images"] = images
    return doc, notes


def memory_config(base: Path, scenario: Path, images: int, width: int, height: int) -> tuple[dict, list[str]]:
    from synthua_usd.usd.cameras import camera_paths
    from synthua_usd.usd.stage_io import open_stage

    doc = json.loads(base.read_text(encoding="utf-8"))
    cameras = len(doc.get("cameras") or camera_paths(open_stage(scenario)))
    conditions = doc.get("conditions") or [None]
    n_conditions = 7 if conditions == "all" else len(conditions)  # "all": an upper bound is enough here
    per_seed = max(1, cameras * 48 * n_conditions)
    seeds = list(range(math.ceil(images / per_seed)))
    doc.update(images=images, time_codes="1:48:1", seeds=seeds)
    doc["render"] = {**doc.get("render", {}), "width": width, "height": height, "spp": 1}
    doc["quotas"] = {"aid_users": None, "per_condition": "balanced" if conditions != [None] else None,
                     "per_rig_type": None}
    # QA flags instead of rejecting: at 1 spp many clear-day eye-level frames fail the highlights check, and
    # rejected images are replaced in further rounds; N images it is.
    doc["qa"] = {**doc.get("qa", {}), "reject": []}
    notes = [f"from {base.name}: images {images}, {width}x{height} at 1 spp, time codes 1:48:1, seeds {seeds[0]}.."
             f"{seeds[-1]} ({cameras} cameras x 48 x {n_conditions} conditions per seed), quotas: balanced conditions only, QA flags only"]
    return doc, notes


def at_share(rows: list, share: float, column: int):
    """A worker's value in ``column`` (of :attr:`Probe.samples`) when it had delivered ``share`` of its own
    images: its last sample at or below that count."""
    mark = max(1, math.ceil(rows[-1][2] * share - 1e-9))
    below = [r for r in rows if r[2] <= mark]
    return below[-1][column] if below else None


def fmt(x, unit="", nd=1) -> str:
    return "-" if x is None else f"{x:.{nd}f}{unit}"


def use_tree_schemas(tree: Path) -> None:
    """Make ``synthua_usd.schema_files`` (which an editable install maps to the installed checkout's schemas) the
    schemas of ``tree``, whose package ``PYTHONPATH`` puts first: a revision's code with its own schemas."""
    import importlib.util

    class TreeSchemas:
        @classmethod
        def find_spec(cls, fullname, path=None, target=None):
            if fullname != "synthua_usd.schema_files":
                return None
            return importlib.util.spec_from_file_location(fullname, str(Path(tree) / "schemas" / "__init__.py"))

    sys.meta_path.insert(0, TreeSchemas)


def tree_digests(folder: Path) -> dict[str, str]:
    """sha256 of every file below ``folder`` by relative path (``generate.json`` names the scenario's absolute
    path, which is the same here: it is compared too)."""
    import hashlib

    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def compare(args) -> int:
    """``--base REV``: REV's code and this tree's, side by side (see the module's docstring)."""
    import subprocess

    work = Path(tempfile.mkdtemp(prefix="bench_generate_base_"))
    base_tree = work / "base"
    subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(base_tree), args.base], check=True,
                   capture_output=True)
    # both runs read the same scenario and config files (absolute paths: generate.json records the scenario's)
    memory = args.memory is not None
    scenario = (args.scenario or REPO / "stages" / ("scenario.usda" if memory else "district/scenario.usda")).resolve()
    config = (args.config or REPO / "configs" / ("demo.json" if memory else "district.json")).resolve()
    passed = ["--scenario", str(scenario), "--config", str(config)]
    for flag, value in (("--images", args.images), ("--memory", args.memory), ("--width", args.width),
                        ("--height", args.height), ("--spp", args.spp), ("--seeds", args.seeds),
                        ("--workers", args.workers), ("--variant", args.variant)):
        if value is not None:
            passed += [flag, str(value)]
    runs: list[tuple[str, int, dict]] = []
    try:
        for r in range(args.rounds):
            for name, tree in (("base", base_tree), ("this", REPO)) if r % 2 == 0 else (("this", REPO), ("base", base_tree)):
                out, measures = work / f"{name}_{r}", work / f"{name}_{r}.json"
                home = work / f"home_{name}_{r}"  # an empty Dr.Jit kernel cache
                home.mkdir()
                env = {**os.environ, "PYTHONPATH": str(tree), "HOME": str(home)}
                print(f"round {r + 1}: {name} ({args.base if name == 'base' else 'this tree'})", flush=True)
                subprocess.run([sys.executable, str(Path(__file__).resolve()), *passed, "--no-progress", "--keep",
                                "--out", str(out), "--json", str(measures), "--tree", str(tree)],
                               env=env, cwd=str(tree), check=True)
                runs.append((name, r, json.loads(measures.read_text(encoding="utf-8"))))
        first = {name: tree_digests(work / f"{name}_0") for name in ("base", "this")}
        differ = sorted(p for p in first["base"].keys() | first["this"].keys()
                        if first["base"].get(p) != first["this"].get(p))
        print(f"\n{'run':14} {'images':>7} {'wall s':>8} {'CPU s':>8} {'images/min':>11} {'plan s':>8}")
        for name, r, m in runs:
            print(f"{name + ' ' + str(r + 1):14} {m['rendered']:7d} {m['wall_s']:8.1f} {m['cpu_s']:8.1f} "
                  f"{m['images_per_min']:11.2f} {m['plan_s']:8.1f}")
        mean = {name: {k: np.mean([m[k] for n, _, m in runs if n == name]) for k in ("wall_s", "cpu_s", "images_per_min")}
                for name in ("base", "this")}
        print(f"this tree against {args.base}: images/min x{mean['this']['images_per_min'] / mean['base']['images_per_min']:.2f}, "
              f"wall x{mean['this']['wall_s'] / mean['base']['wall_s']:.2f}, CPU x{mean['this']['cpu_s'] / mean['base']['cpu_s']:.2f}")
        verdict = (f"the same bytes, all {len(first['this'])} files" if not differ
                   else f"{len(differ)} of {len(first['this'])} files differ: {', '.join(differ[:8])}")
        print(f"datasets (first round): {verdict}")
        if args.json is not None:
            args.json.write_text(json.dumps({"base": args.base, "runs": [{"code": n, "round": r, **m} for n, r, m in runs],
                                             "same_bytes": not differ, "differ": differ}, indent=1) + "\n",
                                 encoding="utf-8")
    finally:
        subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(base_tree)], capture_output=True)
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
        else:
            print(f"kept: {work}")
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog="\n".join(__doc__.splitlines()[2:7]))
    parser.add_argument("--scenario", type=Path, default=None,
                        help="[default: stages/district/scenario.usda; with --memory: stages/scenario.usda]")
    parser.add_argument("--config", type=Path, default=None,
                        help="[default: configs/district.json; with --memory: configs/demo.json]")
    parser.add_argument("--images", type=int, default=None, help="override the config's image count")
    parser.add_argument("--memory", type=int, metavar="N", default=None,
                        help="memory mode: N small images of the demo street")
    parser.add_argument("--width", type=int, default=None, help="render width [default: the config's; 160 in --memory mode]")
    parser.add_argument("--height", type=int, default=None, help="render height [default: the config's; 120 in --memory]")
    parser.add_argument("--spp", type=int, default=None, help="samples per pixel [default: the config's]")
    parser.add_argument("--seeds", type=int, default=None, help="seeds 0..K-1 [default: the config's]")
    parser.add_argument("--base", default=None, metavar="REV",
                        help="compare with the code of git revision REV, side by side (see above)")
    parser.add_argument("--rounds", type=int, default=1, help="with --base: runs of each, alternating")
    parser.add_argument("--json", type=Path, default=None, help="write the run's measures to this JSON file")
    parser.add_argument("--tree", type=Path, default=None, help=argparse.SUPPRESS)  # a --base run's code
    parser.add_argument("--workers", type=int, default=None, help="[default: the config's, else generate's]")
    parser.add_argument("--variant", default=None)
    parser.add_argument("--out", type=Path, default=None,
                        help="dataset folder (must not exist; removed afterwards unless --keep) [default: a temp dir]")
    parser.add_argument("--keep", action="store_true", help="keep the dataset (and the temp config) afterwards")
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args()

    if args.base is not None:
        return compare(args)
    if args.tree is not None:
        use_tree_schemas(args.tree)
    memory = args.memory is not None
    scenario = args.scenario or REPO / "stages" / ("scenario.usda" if memory else "district/scenario.usda")
    base = args.config or REPO / "configs" / ("demo.json" if memory else "district.json")
    if memory:
        doc, notes = memory_config(base, scenario, args.memory, args.width or 160, args.height or 120)
    else:
        doc, notes = district_config(base, args.images, args.width, args.height, args.spp, args.seeds)

    from synthua_usd.pipeline.generate import GenerateRequest, generate

    work_dir = Path(tempfile.mkdtemp(prefix="bench_generate_"))
    config_path = work_dir / f"{base.stem}.bench.json"
    config_path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    out = args.out or work_dir / "dataset"
    out_existed = out.exists()  # never delete a folder this run did not create
    probe = Probe()
    probe.install()
    load_before = os.getloadavg()
    try:
        # count_compiles: workers report kernel compile time; a revision before it (a --base) has no such field
        counting = {"count_compiles": True} if "count_compiles" in {f.name for f in dataclasses.fields(GenerateRequest)} \
            else {}
        summary = generate(GenerateRequest(scenario=scenario, config_path=config_path, out_dir=out,
                                           workers=args.workers, variant=args.variant, **counting),
                           show_progress=not args.no_progress)
        load_after = os.getloadavg()
        job = json.loads((out / "generate.json").read_text(encoding="utf-8"))
    finally:
        if not args.keep:
            shutil.rmtree(work_dir, ignore_errors=True)
            if args.out is not None and not out_existed:
                shutil.rmtree(out, ignore_errors=True)
    driver_peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    render = job["render"]
    images = summary.planned
    kept = images - summary.rejected
    workers = sorted(summary.peak_rss_mib)
    print(f"{scenario.relative_to(REPO) if scenario.is_relative_to(REPO) else scenario} with {base.name} "
          f"({'; '.join(notes) or 'as is'})")
    print(f"{render['width']}x{render['height']}, {render['spp']} spp, max depth {render['max_depth']}, "
          f"{render.get('variant')}; {images} images planned (QA replacements included), {summary.rendered} rendered, "
          f"{summary.resumed} resumed, {summary.rejected} rejected, {summary.flagged} flagged; {probe.rounds} render "
          f"round(s), {len(workers)} worker process(es) in all; {os.cpu_count()} CPUs")
    print(f"load average (1/5/15 min) before {' '.join(f'{x:.2f}' for x in load_before)}, "
          f"after {' '.join(f'{x:.2f}' for x in load_after)}")
    if summary.shortfalls:
        print(f"quota shortfalls: {summary.shortfalls}")
    if args.keep:
        print(f"kept: {out} (config {config_path})")

    wall = summary.wall_seconds
    phases = {"plan (score views)": probe.phase.get("plan", 0.0), "render (workers)": probe.phase.get("render", 0.0),
              "assemble": probe.phase.get("assemble", 0.0)}
    phases["other (open, setup)"] = wall - sum(phases.values())
    print(f"\n{'phase':24} {'seconds':>9} {'share':>7}")
    for name, sec in phases.items():
        print(f"{name:24} {sec:9.1f} {sec / wall:7.1%}")
    print(f"{'wall':24} {wall:9.1f}")
    render_wall = phases["render (workers)"] or float("nan")
    print(f"images/min: {60 * summary.rendered / wall:.2f} rendered end to end ({60 * kept / wall:.2f} kept, i.e. "
          f"not rejected), {60 * summary.rendered / render_wall:.2f} rendered over the render phase")

    if args.json is not None:
        cpu = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        args.json.write_text(json.dumps({
            "images": images, "rendered": summary.rendered, "wall_s": wall, "plan_s": phases["plan (score views)"],
            "render_s": phases["render (workers)"], "cpu_s": sum(r.ru_utime + r.ru_stime for r in cpu),
            "images_per_min": 60 * summary.rendered / wall, "worker_seconds": summary.seconds,
            "peak_rss_mib": summary.peak_rss_mib}, indent=1) + "\n", encoding="utf-8")

    s = summary.seconds
    total = sum(s.values()) or 1.0
    n = max(1, summary.rendered)
    print(f"\n{'worker time (all workers)':34} {'seconds':>9} {'share':>7} {'per image':>10}")
    for key, label in (("render", "render (RGB + labels + amodal)"), ("annotate", "annotate"),
                       ("write", "write (overlaps next render)")):
        print(f"{label:34} {s[key]:9.1f} {s[key] / total:7.1%} {s[key] / n:9.2f}s")
    busy = s["render"] + s["annotate"]
    if probe.capacity:
        print(f"render + annotate over the workers' time (each round's wall x its workers): "
              f"{busy / probe.capacity:.1%} (the rest: scene loads, waits on writes, idle at the ends of rounds)")
    print(f"dataset: {summary.bytes_per_image / MIB:.3f} MiB per image ({summary.bytes_per_image * max(1, images) / MIB:.1f} "
          f"MiB in all, {images} records)")

    trace_ok = len(summary.rss_trace) == len(probe.samples) and all(
        t[1] == p[1] and t[2] == p[5] for t, p in zip(summary.rss_trace, probe.samples))
    own = {w: [t for t in probe.samples if t[1] == w] for w in workers}
    print(f"\ndriver (this process) peak RSS {driver_peak:.0f} MiB; summary.rss_trace "
          f"{'matches' if trace_ok else 'does NOT match'} the probe's samples")
    print(f"{'worker':28} {'images':>7} {'reported peak':>15} {'own peak VmHWM':>15} {'VmRSS at end':>13}")
    for w in workers:
        rows = own[w]
        print(f"{w:28} {rows[-1][2] if rows else 0:7d} {summary.peak_rss_mib[w]:11.0f} MiB "
              f"{fmt(rows[-1][4] / 1024 if rows else None, ' MiB', 0):>15} "
              f"{fmt(rows[-1][3] / 1024 if rows else None, ' MiB', 0):>13}")

    if memory:
        print("\nmemory of each worker, MiB, after 10 % / 50 % / 100 % of ITS OWN images; growth = 100 % minus 10 %")
        print(f"{'worker':28} {'images':>7} {'measure':16} {'10 %':>8} {'50 %':>8} {'100 %':>8} {'growth':>8} "
              f"{'slope':>15}")
        for w in workers:
            rows = own[w]
            if not rows:
                continue
            for k, (label, col, scale) in enumerate((("reported peak", 5, 1.0), ("own VmHWM", 4, 1024.0),
                                                     ("VmRSS", 3, 1024.0))):
                vals = [at_share(rows, f, col) for f in (0.1, 0.5, 1.0)]
                vals = [None if v is None else v / scale for v in vals]
                growth = None if None in (vals[0], vals[2]) else vals[2] - vals[0]
                slope = ""
                pts = [(r[2], r[3]) for r in rows if r[2] >= math.ceil(rows[-1][2] * 0.1)]
                if label == "VmRSS" and len(pts) >= 20:
                    slope = f"{np.polyfit(*zip(*pts), 1)[0]:.1f} KiB/img"
                print(f"{w if k == 0 else '':28} {rows[-1][2] if k == 0 else '':>7} {label:16} {fmt(vals[0]):>8} "
                      f"{fmt(vals[1]):>8} {fmt(vals[2]):>8} {fmt(growth):>8} {slope:>15}")
        print("slope: least squares of VmRSS over the worker's own images after its first 10 % (workers with 20+ "
              "results)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
