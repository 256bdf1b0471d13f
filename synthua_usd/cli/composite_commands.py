"""``synthua composite``: cut-outs of a bank pasted onto real photos, an exactly labelled dataset out."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_OK, say
from synthua_usd.cli.dataset_commands import worker_time_shares
from synthua_usd.model.photo_sets import DEFAULT_SPLIT, SPLIT_CHOICES


@click.command()
@click.argument("backgrounds", type=click.Path(path_type=Path))
@click.option("--bank", type=click.Path(path_type=Path), required=True,
              help="A bank of cut-outs written by `synthua cutouts` (its bank.json: format synthua-cutouts/1).")
@click.option("--config", "config_path", type=click.Path(path_type=Path), required=True,
              help="Composite config (schemas/composite.schema.json), e.g. configs/composite.json.")
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Dataset folder: created (an existing one must be empty).")
@click.option("--workers", type=click.IntRange(1, 1024),
              help="Worker processes [default: the config's, else one per CPU core].")
@click.option("--split", type=click.Choice(SPLIT_CHOICES), default=DEFAULT_SPLIT,
              show_default=True,
              help="Which photos of a labelled YOLO set: default is its train split where it names one (its val and "
                   "test photos are what a detector trained on the composites is scored on: pasting into them "
                   "would leak), else all.")
@click.option("--images", "images_dir", type=click.Path(path_type=Path),
              help="The folder of a COCO .json's photos, its file_name paths relative to it [default: the .json's "
                   "folder], e.g. train2017/ beside annotations/instances_train2017.json.")
def composite(backgrounds: Path, bank: Path, config_path: Path, out_dir: Path, workers: int | None,
              split: str, images_dir: Path | None) -> int:
    """Paste the cut-outs of --bank onto the photos of BACKGROUNDS, as --config says, into the dataset --out.

    \b
    Examples:
      synthua composite photos/ --bank bank/ --config configs/composite.json --out out/composites
      synthua composite ../shared/data/real_photos/wheelchair_dev --bank bank/ \\
          --config configs/composite.json --out out/wheelchair_composites
      synthua verify out/composites
      synthua replay out/composites 7          # make composite 7 again: byte-identical
    \b
    BACKGROUNDS is a folder of photos without labels (empty streets, corridors, CCTV frames), or a labelled
    YOLO set (data.yaml, or images/ + labels/: its train split unless --split says otherwise) or COCO .json
    (its photos beside it or in --images) whose boxes are kept. Photos are read in place; below a folder of
    photos, hidden files and the datasets synthua wrote there are left out, linked folders followed.
    \b
    Per composite: the photo scaled down and cut to the config's output size; a camera model (horizon row,
    camera height, focal length: from the config, its per-folder defaults, or the photo's EXIF; the horizon
    from a labelled photo's people where camera.person_height_m (standing people) or
    camera.wheelchair_height_m (wheelchair users) is set); cut-outs standing on that
    camera's ground plane, sized by their distance (a share of the frame height drawn from the config), chosen
    for a camera elevation (and light) like the paste's; their shadows, exposure and white balance matched to
    the photo around them, blend edges mixed (hard, feathered, blurred, Poisson); camera effects where the
    config asks; a grey photo's composite made grey. Labels are exact: nearer pastes occlude farther ones
    (visible masks and keypoint visibility follow, amodal masks kept); the photo's pixels are void (class 0). A
    labelled photo's boxes are kept in the YOLO labels and the records, except those the pastes cover (dropped,
    recorded).
    \b
    The dataset has synthua generate's layout: images, class and instance PNGs, COCO instances (pasted
    instances, RLE masks, keypoints), panoptic and Cityscapes files, YOLO labels (boxes in the config's box
    convention), data.yaml, records, metadata.csv/.parquet and manifest.json. Nothing is written unless all of
    it is; the same inputs and config give the same bytes on any number of workers.
    """
    from synthua_usd.pipeline.composite import CompositeRequest, composite as run_composite

    s = run_composite(CompositeRequest(backgrounds=backgrounds, bank=bank, config_path=config_path,
                                       out_dir=out_dir, workers=workers, split=split, images=images_dir),
                     show_progress=sys.stderr.isatty())
    kind = "labelled" if s.labelled else "unlabelled (their pixels void, no boxes of their own)"
    say(f"dataset {s.out_dir}: {s.images - s.rejected} composites ({s.flagged} flagged by QA) and {s.rejected} "
        f"rejected by QA, from {s.backgrounds} {kind} photos; {s.pastes} pastes")
    if s.without_pastes:
        say(f"{s.without_pastes} of {s.images} composites hold no paste ({s.photos_without_pastes} "
            f"photo{'s' * (s.photos_without_pastes != 1)} none in any): no room within pastes.max_overlap and "
            f"max_background_cover (when_no_room skip), a cut-out wider than the frame, no ground below the "
            f"horizon, or pastes.per_image drawing 0; such a composite is its photo alone with the camera effects")
    if s.skipped:
        say(f"left out {len(s.skipped)} dataset{'s' * (len(s.skipped) > 1)} written by synthua below BACKGROUNDS "
            f"({', '.join(s.skipped[:3])}{', ...' * (len(s.skipped) > 3)}): their images are no photos")
    if s.grey:
        say(f"{s.grey} composite{'s' * (s.grey > 1)} made grey: {'their photos are' if s.grey > 1 else 'its photo is'} "
            f"grey (composite.background.monochrome)")
    if s.horizon_from_people:
        say(f"{s.horizon_from_people} of {s.images} composites with the horizon placed by their photo's people "
            f"(camera.person_height_m, wheelchair_height_m; the others by camera.horizon_row_share or pitch_deg)")
    if s.labelled:
        say(f"the photos' boxes: {s.boxes_kept} kept, {s.boxes_dropped} dropped (covered by pastes, cut off by the "
            f"output size, unmapped, empty or crowd regions: see each record's composite.background_boxes)")
    if s.images:
        say(f"{s.images / s.wall_seconds * 60:.0f} images/min over {s.wall_seconds:.1f} s on {s.workers} workers; "
            f"worker time: {worker_time_shares(s.seconds)}")
    return EXIT_OK
