"""``synthua generate``, ``synthua verify`` and ``synthua replay``: datasets from scenarios, checked."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_FINDINGS, EXIT_OK, say


def worker_time_shares(seconds: dict[str, float]) -> str:
    """"render 80 % (rgb 50 %, ...), annotate 10 %, write 10 %": the workers' time by phase. ``render`` holds its
    ``render_*`` parts (where the render time went), so the whole is the phases without the parts (``write_*``, the
    encoders' seconds per file, overlap the next render: they are left to the benchmarks)."""
    def part(key: str) -> bool:
        return key.startswith(("render_", "write_"))

    busy = sum(v for k, v in seconds.items() if not part(k)) or 1.0
    parts = ", ".join(f"{k[len('render_'):]} {100 * v / busy:.0f} %" for k, v in seconds.items()
                      if k.startswith("render_") and v > 0)
    return ", ".join(f"{k} {100 * v / busy:.0f} %" + (f" ({parts})" if k == "render" and parts else "")
                     for k, v in seconds.items() if not part(k))


@click.command()
@click.argument("scenario", type=click.Path(path_type=Path))
@click.option("--config", "config_path", type=click.Path(path_type=Path), required=True,
              help="Generation config (schemas/generate.schema.json), e.g. configs/demo.json.")
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Dataset folder: created, or an earlier run of the same job to resume.")
@click.option("--executor", type=click.Choice(["local", "ray"]), default="local", show_default=True,
              help="local: a pool of worker processes on this machine; ray: workers on a Ray cluster.")
@click.option("--workers", type=click.IntRange(1, 1024),
              help="Render workers, each with one scene load [default: the config's, else one per 8 cores].")
@click.option("--address", help="Ray cluster address (HOST:6379) for --executor ray [default: a local Ray instance].")
@click.option("--cpus-per-worker", type=click.FloatRange(0.01, 1024), default=1.0, show_default=True,
              help="CPUs Ray reserves for each worker (--executor ray): give each a node's share of cores.")
@click.option("--variant", help="Mitsuba variant (cuda_ad_rgb, llvm_ad_rgb, scalar_rgb) [default: best available].")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--allow-external-assets", is_flag=True,
              help="Accept layers outside the stage's folder tree (refused by default).")
def generate(scenario: Path, config_path: Path, out_dir: Path, executor: str, workers: int | None,
             address: str | None, cpus_per_worker: float, variant: str | None, class_map: Path | None,
             allow_external_assets: bool) -> int:
    """Generate a dataset from SCENARIO as --config says, into --out.

    \b
    Example (the demo street, under a minute on 2 cores):
      synthua generate stages/scenario.usda --config configs/demo.json --out out/dataset
      synthua verify out/dataset
    \b
    The config sweeps cameras x time codes x conditions x seeds; a label pass scores every view, and the
    sampler picks images that meet the quotas (share of images with a visible mobility-aid user, images
    per condition and per rig type) and splits them train/val/test by camera. Per image: RGB, class ids,
    class colours, instance ids and a coloured preview, panoptic PNG, depth, amodal masks, occlusion and
    truncation, person keypoints and device contact points with visibility flags, QA verdicts. Per dataset:
    COCO instances (with keypoints), person keypoints and panoptic JSON, Cityscapes gtFine, YOLO labels and
    data.yaml, metadata.csv/.parquet, coverage.json, rejected.csv and manifest.json.
    \b
    With a randomise block (configs/district_random.json) every image is a scene of its own: a new crowd, looks,
    material variants and district per seed, the crowd placed anew and the camera moved per view, the light
    drawn per image, all as USD layers composed over SCENARIO (synthua randomise writes an image's layers).
    \b
    With a sequences block (configs/district_sequences.json) it also renders tracking sequences: each camera x
    condition x seed for duration_s at fps from one loaded scene, in the MOTChallenge layout (img1/, gt/gt.txt,
    seqinfo.ini) with tracks.csv, per-frame instance maps, a preview video and COCO video annotations.
    \b
    Killed or failed runs resume: run the same command again; finished images are kept.
    The same config, scenario and variant give the same bytes (check one image: synthua replay).
    """
    from synthua_usd.pipeline.generate import GenerateRequest, generate as run_generate

    summary = run_generate(GenerateRequest(scenario=scenario, config_path=config_path, out_dir=out_dir,
                                           executor=executor, workers=workers, address=address,
                                           cpus_per_worker=cpus_per_worker, variant=variant,
                                           class_map_path=class_map, allow_external_assets=allow_external_assets),
                           show_progress=sys.stderr.isatty())
    s = summary
    say(f"dataset {s.out_dir}: {s.planned - s.rejected} images ({s.flagged} flagged by QA) and {s.rejected} "
               f"rejected by QA, replaced where the pool allowed (rejected.csv); {s.rendered} rendered now, "
               f"{s.resumed} found from an earlier run")
    if s.splits:
        asked = "/".join(f"{v['share']:g}" for v in s.splits.values())
        say("split by camera: " + ", ".join(f"{split} {v['images']} images from {v['cameras']} camera"
                                            f"{'s' if v['cameras'] != 1 else ''}" for split, v in s.splits.items())
            + f" (asked {asked})")
    if s.rendered:
        shares = worker_time_shares(s.seconds)
        peak = max(s.peak_rss_mib.values()) if s.peak_rss_mib else 0.0
        say(f"{s.rendered / s.wall_seconds * 60:.1f} images/min over {s.wall_seconds:.0f} s; worker time: "
                   f"{shares}; peak memory per worker {peak:.0f} MiB; {s.bytes_per_image / 2**20:.2f} MiB per image")
    if s.sequences:
        say(f"{s.sequences} tracking sequences of {s.frames} frames: {s.frames_rendered} rendered now, "
            f"{s.frames_resumed} found from an earlier run (MOTChallenge layout in {s.out_dir / 'sequences'})")
    for line in s.shortfalls:
        say(f"quota not met: {line}")
    return EXIT_OK


@click.command()
@click.argument("dataset", type=click.Path(path_type=Path))
def verify(dataset: Path) -> int:
    """Check DATASET against its manifest: every file present with its size and SHA-256 and no file it does
    not list, every planned image complete, each image record against its own label PNGs (its class pixel
    counts, instance ids, pixel counts, boxes and classes against class.png and instance.png; semantic.png
    their colours), every COCO annotation equal to its instance's pixels (a visible keypoint within 2 pixels of
    them), every panoptic segment equal to its PNG, Cityscapes and YOLO files consistent. Nothing is rendered
    (replay does that). Exit 1 on any problem, listed one per line; 2 when the manifest or generate.json is
    malformed. A cut-out bank (synthua cutouts; its bank.json) is checked against its manifest and its own
    masks instead."""
    from synthua_usd.pipeline.verify import MAX_LISTED, verify as run_verify

    if (dataset / "bank.json").is_file():
        from synthua_usd.pipeline.bank_check import check_bank

        bank = check_bank(dataset)
        for problem in bank.problems[:MAX_LISTED]:
            say(f"problem: {problem}")
        if len(bank.problems) > MAX_LISTED:
            say(f"... and {len(bank.problems) - MAX_LISTED} more problems")
        say(f"{dataset}: {bank.cutouts} cut-outs, {bank.files} files checked: "
            f"{'ok' if bank.ok else f'{len(bank.problems)} problems'}")
        return EXIT_OK if bank.ok else EXIT_FINDINGS

    result = run_verify(dataset, show_progress=sys.stderr.isatty())
    for problem in result.problems[:MAX_LISTED]:
        say(f"problem: {problem}")
    if len(result.problems) > MAX_LISTED:
        say(f"... and {len(result.problems) - MAX_LISTED} more problems")
    verdict = "ok" if result.ok else f"{len(result.problems)} problems"
    sequences = (f", {result.sequences} sequences of {result.frames} frames" if result.sequences else "")
    say(f"{dataset}: {result.images} images{sequences}, {result.files} files checked: {verdict}")
    return EXIT_OK if result.ok else EXIT_FINDINGS


@click.command()
@click.argument("dataset", type=click.Path(path_type=Path))
@click.argument("image")
def replay(dataset: Path, image: str) -> int:
    """Render IMAGE (an image id or name) of DATASET again, as its generate.json says (a dataset of synthua
    composite: make the composite again from the photos and bank it names), and compare every file with the
    dataset's file on disk byte for byte (each one that differs or is missing is listed). Exit 0 when all are
    identical, 1 otherwise."""
    from synthua_usd.pipeline.verify import replay as run_replay

    result = run_replay(dataset, image)
    for path in result.different:
        say(f"differs: {path}")
    verdict = "byte-identical" if result.ok else f"{len(result.different)} of " \
              f"{len(result.different) + len(result.identical)} files differ"
    say(f"image {result.image_id} ({result.name}): {verdict}")
    return EXIT_OK if result.ok else EXIT_FINDINGS
