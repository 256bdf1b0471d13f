"""``synthua cutouts``: a bank of rendered cut-outs of aid users and pedestrians, for ``synthua composite``."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_OK, say


@click.command()
@click.option("--config", "config_path", type=click.Path(path_type=Path), required=True,
              help="Bank config (schemas/cutouts.schema.json), e.g. configs/cutouts.json.")
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Bank folder: created (it must not exist, or be empty).")
@click.option("--workers", type=click.IntRange(1, 1024),
              help="Worker processes [default: the config's, else one per 2 cores].")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
def cutouts(config_path: Path, out_dir: Path, workers: int | None, class_map: Path | None) -> int:
    """Render a bank of cut-outs into --out: aid users of every aid (alone, pushed, accompanied) and
    pedestrians, each group seen from several cameras and lights, as RGBA crops with exact masks.

    \b
    Example (120 cut-outs, a few minutes on 2 cores):
      synthua cutouts --config configs/cutouts.json --out out/bank
      synthua verify out/bank
      synthua composite photos/ --bank out/bank --config configs/composite.json --out out/composites
    \b
    Each group is authored as USD layers (the bodies, devices, hair and clothes of randomised scenes) in a
    studio under one of the config's conditions, its sun drawn per view; no ground, no twin. Per cut-out, in
    BANK/cutouts/: ID.rgba.png (sRGB colour, straight alpha: the group's coverage), ID.ids.png (the instance index
    at each pixel centre, exact), ID.amodal.png (16-bit: bit k-1 where instance k lies at any depth),
    ID.shadow.png (255 x the light a ground plane under the group keeps). BANK/bank.json lists every cut-out:
    its people and device with visible and amodal boxes, keypoints, the points where the group touches the
    ground, the camera (height, pitch, focal length, distance, elevation), the light (sun elevation and azimuth
    relative to the camera, overcast share), and every file's SHA-256. The same config gives the same bytes.
    """
    from synthua_usd.pipeline.cutouts import make_bank

    summary = make_bank(config_path, out_dir, workers=workers, class_map_path=class_map,
                        show_progress=sys.stderr.isatty())
    kinds = ", ".join(f"{n} {k.replace('_', ' ')}" for k, n in sorted(summary.by_aid.items()))
    say(f"bank {summary.out_dir}: {summary.cutouts} cut-outs of {summary.groups} groups ({kinds}) in "
        f"{summary.wall_seconds:.0f} s ({60 * summary.cutouts / max(summary.wall_seconds, 1e-9):.1f} a minute)")
    return EXIT_OK
