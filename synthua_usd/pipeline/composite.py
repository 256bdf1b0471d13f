"""``synthua composite BACKGROUNDS --bank BANK --config CFG --out DATASET``: cut-outs pasted onto real photos, a
dataset with ``synthua generate``'s layout and formats out.

1. Check every input before anything is written: the config (``schemas/composite.schema.json``), the bank
   (format ``synthua-cutouts/1``, every file's size and SHA-256), the photos (:mod:`.backgrounds`: readable, large
   enough, labels that fit), the background classes against the bank's class map, an empty ``--out``.
2. Plan: ``images_per_background`` composites of every photo (the first of each photo first, up to
   ``max_images``), split train/val/test by photo (:func:`synthua_usd.dataset.sampling.split_of`).
3. Make them on the project's executor (:func:`synthua_usd.pipeline.executors.run_shards`, a local pool of worker
   processes; :mod:`.composite_worker`), each writing its composites' files on a background thread.
4. Assemble from the records, as generate does (:func:`synthua_usd.pipeline.generate.assemble`): COCO instances,
   person keypoints and panoptic JSON, YOLO's ``data.yaml``, the metadata table, coverage, the rejected list, the
   class map, the manifest.

Everything is written into a staging folder beside ``--out`` and moved into place when complete
(:func:`synthua_usd.core.atomic.output_set`): a failure (a truncated photo found while decoding it, a full disk)
leaves nothing. A composite's bytes depend on the inputs, the config and its plan entry only: the same command
gives the same dataset on any number of workers. ``generate.json`` holds the job (the absolute paths of BACKGROUNDS
and the bank, the config, the plan) for ``synthua verify`` and ``synthua replay``.
"""

from __future__ import annotations

import functools
import os
import time
from dataclasses import dataclass, field
from importlib.metadata import version
from pathlib import Path

from synthua_usd import __version__
from synthua_usd.core.atomic import output_set, write_json_atomic
from synthua_usd.core.errors import InputError, OutputError
from synthua_usd.core.input_files import shown
from synthua_usd.dataset.composite_config import CompositeConfig
from synthua_usd.dataset.cutout_bank import BANK_FORMAT, check_bank_files, read_bank
from synthua_usd.dataset.composite_plan import eligible
from synthua_usd.dataset.formats import cityscapes
from synthua_usd.dataset.layout import Layout, cityscapes_city, composite_name
from synthua_usd.dataset.manifest import document_digest
from synthua_usd.dataset.record import CompositeRecord, is_rejected
from synthua_usd.dataset.sampling import split_of
from synthua_usd.pipeline.backgrounds import DEFAULT_SPLIT, BackgroundSet, listed_backgrounds, read_backgrounds
from synthua_usd.pipeline.composite_worker import CompositeJob, PlannedComposite

#: Composites a worker makes before its shard ends and it takes the next.
SHARD_IMAGES = 32
#: What generate.json's ``command`` says of a composite dataset.
COMMAND = "composite"


@dataclass(frozen=True)
class CompositeRequest:
    backgrounds: Path
    bank: Path
    config_path: Path
    out_dir: Path
    workers: int | None = None
    #: Which photos of a labelled YOLO set (model.photo_sets.SPLIT_CHOICES; default: its train split where it has one).
    split: str = DEFAULT_SPLIT
    #: The folder of a COCO .json's photos (default: the file's folder).
    images: Path | None = None


@dataclass
class CompositeSummary:
    """What a run made: composites, of which QA flagged and rejected; pastes, composites without one and photos
    without one in any composite; the photo's boxes kept and dropped; composites made grey and those whose horizon
    the photo's people placed; the photos and whether they were labelled; seconds per phase summed over the workers;
    wall time."""

    out_dir: Path
    images: int = 0
    flagged: int = 0
    rejected: int = 0
    pastes: int = 0
    #: Composites that hold no paste (no room for one, or no ground in view: the photo alone, with its effects).
    without_pastes: int = 0
    #: Photos none of whose composites holds a paste.
    photos_without_pastes: int = 0
    boxes_kept: int = 0
    boxes_dropped: int = 0
    #: Composites made grey: their photo is (``composite.background.monochrome``).
    grey: int = 0
    #: Composites whose horizon the photo's people placed (``camera.sources.horizon_row_px`` ``people:N``).
    horizon_from_people: int = 0
    backgrounds: int = 0
    labelled: bool = False
    #: Datasets synthua wrote below a folder of photos, left out (paths relative to it).
    skipped: tuple[str, ...] = ()
    workers: int = 1
    seconds: dict = field(default_factory=dict)
    wall_seconds: float = 0.0


def default_workers() -> int:
    """One worker per core: a composite is single-threaded numpy and Pillow work."""
    return max(1, os.cpu_count() or 1)


def plan_composites(backgrounds: BackgroundSet, config: CompositeConfig) -> list[PlannedComposite]:
    """The composites to make: the first of every photo (in path order), then the second, ... up to
    ``max_images``; each photo's composites in one split."""
    splits = split_of([b.relative for b in backgrounds.images], config.split)
    pairs = [(k, b.relative) for k in range(config.images_per_background) for b in backgrounds.images]
    if config.max_images is not None:
        pairs = pairs[:config.max_images]
    return [PlannedComposite(n, composite_name(n, relative, k), splits[relative], k, relative)
            for n, (k, relative) in enumerate(pairs, 1)]


#: How many unmapped class names an error names (a COCO set has 80).
UNKNOWN_SHOWN = 8


def _check_classes(backgrounds: BackgroundSet, config: CompositeConfig, bank, source: str) -> None:
    things = {c.name for c in bank.class_map.classes if c.isthing}
    labels = config.background_labels
    unknown = [name for name in (backgrounds.names if backgrounds.labelled else ())
               if (ours := labels.our_class(name)) is not None and ours not in things]
    if unknown:
        named = ", ".join(repr(n) if labels.our_class(n) == n else f"{n!r} -> {labels.our_class(n)!r}"
                          for n in unknown[:UNKNOWN_SHOWN])
        named += f" and {len(unknown) - UNKNOWN_SHOWN} more" if len(unknown) > UNKNOWN_SHOWN else ""
        one = len(unknown) == 1
        raise InputError(f"{source}: background_labels.classes: {named} ({'a class' if one else 'classes'} of "
                         f"{shown(backgrounds.source)}): {'not a thing class' if one else 'not thing classes'} of the "
                         f"bank's class map; expected each mapped to one of {', '.join(sorted(things))}, or to null "
                         f"to leave its boxes out (\"*\": null leaves out every class not listed)")
    pools = eligible(bank.entries, config)
    if not any(pools.values()):
        raise InputError(f"{source}: pastes.aids / pastes.groups: no cut-out of the bank is left; expected aids and "
                         f"groups the bank holds")


def _check_out(out: Path) -> None:
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise OutputError(f"{shown(out)}: {'a file' if not out.is_dir() else 'not empty'}; expected an empty folder or a "
                          f"path that does not exist (a composite dataset is written whole, never resumed)")


def versions() -> dict:
    """The software whose versions can change a composite's bytes."""
    return {"synthua": __version__, **{name: version(name) for name in ("numpy", "scipy", "pillow", "OpenImageIO")}}


def composite(request: CompositeRequest, show_progress: bool = False) -> CompositeSummary:
    """Check the inputs, plan, make and assemble the dataset (see the module docstring)."""
    from tqdm import tqdm

    from synthua_usd.pipeline.executors import cut_shards, run_shards
    from synthua_usd.pipeline.generate import assemble
    from synthua_usd.pipeline.worker_protocol import ExecutorConfig
    from synthua_usd.pipeline.composite_worker import FLUSH, init_worker, work

    started = time.perf_counter()
    config = CompositeConfig.load(request.config_path)
    bank = read_bank(request.bank)
    check_bank_files(bank)
    cityscapes.check_class_map(bank.class_map)
    out = Path(request.out_dir)
    _check_out(out)
    backgrounds = read_backgrounds(request.backgrounds, config.output, request.split, request.images)
    _check_classes(backgrounds, config, bank, str(request.config_path))
    plan = plan_composites(backgrounds, config)
    workers = request.workers or config.workers or default_workers()
    config_document = config.to_document()
    config_document.pop("workers")
    job_key = {"config": config_document, "class_map": bank.class_map.document(), "bank": bank.id,
               "backgrounds": [[b.relative, b.width, b.height] for b in backgrounds.images], "grey_photos": True,
               "open_cuts": True, "visible_overlap": True, "overlap_by_depth": True, "seamless_poisson": True,
               **({"people_in_photo": True} if config.sets_people_heights() else {})}   # earlier job keys hold
    job_document = {"synthua": __version__, "command": COMMAND, "job_key": job_key,
                    "job_key_digest": document_digest(job_key), "backgrounds": str(Path(request.backgrounds).resolve()),
                    "backgrounds_layout": backgrounds.layout, "backgrounds_split": request.split,
                    "backgrounds_images": None if request.images is None else str(Path(request.images).resolve()),
                    "bank": str(Path(request.bank).resolve()),
                    "plan": [p.to_dict() for p in plan]}
    summary = CompositeSummary(out_dir=out, backgrounds=len(backgrounds.images), labelled=backgrounds.labelled,
                               skipped=backgrounds.skipped, workers=workers)
    done: dict[int, CompositeRecord] = {}
    seconds: dict[str, float] = {}
    with output_set(out) as staging:
        write_json_atomic(staging / Layout.CONFIG, job_document, indent=1)
        job = CompositeJob(out_dir=str(staging), config_document=config_document,
                           class_map_document=bank.class_map.document(), bank_root=str(bank.root.resolve()),
                           backgrounds=backgrounds, city=cityscapes_city(config.name),
                           open_cuts=job_key["open_cuts"] is True, visible_overlap=job_key["visible_overlap"] is True,
                           overlap_by_depth=job_key["overlap_by_depth"] is True,
                           seamless_poisson=job_key["seamless_poisson"] is True)
        bar = tqdm(total=len(plan), desc="composite", unit="img", disable=not show_progress)

        def collect(result) -> None:
            for item in result.value:
                done[item["record"]["id"]] = item["record"]
                bar.update(1)
                for key, value in item["seconds"].items():
                    seconds[key] = seconds.get(key, 0.0) + value

        shards = [s + [FLUSH] for s in cut_shards(plan, lambda p: p.id, workers, SHARD_IMAGES)]
        run_shards(shards, functools.partial(init_worker, job), work, collect, ExecutorConfig(workers=workers))
        bar.close()
        missing = [p.id for p in plan if p.id not in done]
        if missing:
            raise OutputError(f"{shown(out)}: {len(missing)} composites were not written (e.g. id {missing[0]}); "
                              f"expected every planned composite's record")
        records = [done[p.id] for p in plan]
        provenance = {**versions(), "command": COMMAND, "config": config_document,
                      "config_digest": document_digest(config_document), "bank": {"id": bank.id, "format": BANK_FORMAT},
                      "backgrounds": {"layout": backgrounds.layout, "labelled": backgrounds.labelled,
                                      "images": len(backgrounds.images)}}
        assemble(Layout(staging), records, bank.class_map, None, job_document, provenance=provenance)
    summary.images = len(records)
    summary.flagged = sum(r["qa"]["verdict"] == "flagged" for r in records)
    summary.rejected = sum(is_rejected(r) for r in records)
    summary.pastes = sum(len(r["composite"]["pastes"]) for r in records)
    summary.without_pastes = sum(not r["composite"]["pastes"] for r in records)
    pasted_into = {r["composite"]["background"]["path"] for r in records if r["composite"]["pastes"]}
    summary.photos_without_pastes = len({r["composite"]["background"]["path"] for r in records} - pasted_into)
    boxes = [b for r in records for b in r["composite"]["background_boxes"]]
    summary.boxes_kept = sum(b["kept"] for b in boxes)
    summary.boxes_dropped = len(boxes) - summary.boxes_kept
    summary.grey = sum(bool(r["composite"]["background"].get("monochrome")) for r in records)
    summary.horizon_from_people = sum(r["camera"]["sources"]["horizon_row_px"].startswith("people:") for r in records)
    summary.seconds = seconds
    summary.wall_seconds = time.perf_counter() - started
    return summary


def is_composite_job(job_document: dict) -> bool:
    """Whether a dataset's ``generate.json`` is a composite job's."""
    return isinstance(job_document, dict) and job_document.get("command") == COMMAND


def remake(job_document: dict, planned: dict, out_dir: Path) -> dict:
    """Make one planned composite of a dataset again (``synthua replay``) into ``out_dir``, from the inputs its
    ``generate.json`` names; returns its record. The bank and photos are read where the job found them."""
    from synthua_usd.pipeline.composite_worker import FLUSH, init_worker, work

    try:
        config = CompositeConfig.from_document(job_document["job_key"]["config"], source="generate.json")
        backgrounds = listed_backgrounds(read_backgrounds(job_document["backgrounds"], config.output,
                                                          job_document.get("backgrounds_split", DEFAULT_SPLIT),
                                                          job_document.get("backgrounds_images")),
                                         job_document["job_key"]["backgrounds"])
        item = PlannedComposite(**planned)
        job = CompositeJob(out_dir=str(out_dir), config_document=job_document["job_key"]["config"],
                           class_map_document=job_document["job_key"]["class_map"], bank_root=job_document["bank"],
                           backgrounds=backgrounds, city=cityscapes_city(config.name),
                           grey_photos=job_document["job_key"].get("grey_photos") is True,
                           people_in_photo=job_document["job_key"].get("people_in_photo") is True,
                           open_cuts=job_document["job_key"].get("open_cuts") is True,
                           visible_overlap=job_document["job_key"].get("visible_overlap") is True,
                           overlap_by_depth=job_document["job_key"].get("overlap_by_depth") is True,
                           seamless_poisson=job_document["job_key"].get("seamless_poisson") is True)
    except (KeyError, TypeError) as exc:
        raise InputError(f"generate.json: {type(exc).__name__} {exc}; expected the job `synthua composite` "
                         f"writes") from None
    state = init_worker(job)
    if state.bank.id != job_document["job_key"]["bank"]:
        raise InputError(f"{shown(job_document['bank'])}: bank.json differs from the bank the dataset was made with "
                         f"(its SHA-256); expected the same bank to replay")
    results = work(state, item) + work(state, FLUSH)
    return results[-1]["record"]
