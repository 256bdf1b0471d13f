"""One composite worker: it reads the bank once, then makes each planned composite and writes its files.

Per composite (:func:`make_composite`): the photo read and cut to the output size
(:func:`synthua_usd.backends.photos.read_photo`); its camera model and pastes drawn from the ``composite`` stream
of (config seed, composite number, background path) (:mod:`synthua_usd.dataset.composite_plan`); the pastes
painted with their labels (:func:`synthua_usd.backends.compositing.compose`); camera effects from the ``effects``
stream, then the whole made grey where the photo is (:func:`synthua_usd.backends.photos.is_monochrome`); every
visible pasted instance annotated as generate annotates (:func:`synthua_usd.dataset.annotations.annotate`:
visible and amodal masks, boxes, occlusion, truncation, relations; keypoints with their visibility updated); the
photo's own boxes kept or dropped; QA; and the files of a dataset image (the same writer as ``synthua generate``'s,
:func:`synthua_usd.pipeline.dataset_worker.write_image`, on a background thread while the next composite is made),
the record last. A composite depends on its plan entry, the inputs and the config only: never on the worker.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from synthua_usd.analytics.detection_targets import background_boxes, image_boxes, targets_for
from synthua_usd.core import images
from synthua_usd.backends import frame_files
from synthua_usd.backends.camera_effects import apply_effects
from synthua_usd.backends.compositing import PasteInput, compose, composite_depth
from synthua_usd.backends.cutout_pixels import CutoutPixels, read_cutout
from synthua_usd.backends.photos import read_photo, to_monochrome
from synthua_usd.dataset import keypoints, qa
from synthua_usd.dataset.annotations import annotate, mark_ignored, panoptic
from synthua_usd.dataset.composite_config import CompositeConfig
from synthua_usd.dataset.composite_plan import draw_camera, eligible, plan_pastes
from synthua_usd.dataset.cutout_bank import BANK_FORMAT, Bank, BankEntry, read_bank
from synthua_usd.dataset.formats import yolo
from synthua_usd.dataset.layout import CityscapesName
from synthua_usd.dataset.record import REJECTED, CompositeRecord, QAResult
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline.background import BackgroundWriter
from synthua_usd.pipeline.backgrounds import Background, BackgroundSet
from synthua_usd.pipeline.dataset_worker import FLUSH, ImageBuffers, label_files, write_image
from synthua_usd.randomisation.effects import draw_effects
from synthua_usd.randomisation.streams import stream

#: Decoded cut-outs a worker keeps (about 1 MB each at a few hundred pixels a side).
CUTOUT_CACHE = 128
#: A composite's files are written as generate's, its PNGs at zlib level 1 (:data:`images.FAST_PNG`): writing is
#: most of a composite's cost, and level 6 takes 3x as long for 6 % smaller files.
WRITERS = frame_files.file_writers(png_compression=images.FAST_PNG)


@dataclass(frozen=True)
class PlannedComposite:
    """One composite of the plan: ``id``, file ``name``, ``split``, ``seed`` (which composite of its background,
    from 0) and ``background`` (its path relative to the set's folder)."""

    id: int
    name: str
    split: str
    seed: int
    background: str

    def to_dict(self) -> dict:
        return {"id": self.id, "name": self.name, "split": self.split, "seed": self.seed,
                "background": self.background}


@dataclass(frozen=True)
class CompositeJob:
    """What a worker needs, as plain picklable data: where to write, the config and class map documents, the bank
    folder and the background set."""

    out_dir: str
    config_document: dict
    class_map_document: dict
    bank_root: str
    backgrounds: BackgroundSet
    city: str = "composite"
    #: Whether a grey photo's composite is made grey: jobs made before 6 December 2026 did not (their ``job_key``
    #: has no ``grey_photos``), and replay makes them as they were.
    grey_photos: bool = True
    #: Whether a photo's people place its horizon where the photo holds them whole (else: person boxes whole in the
    #: frame only): jobs made before 7 December 2026 that set ``camera.person_height_m`` did the latter (their
    #: ``job_key`` has no ``people_in_photo``), and replay makes them as they were.
    people_in_photo: bool = True
    #: Whether blurred and Poisson pastes go on beyond the frame's edge where it cuts them: jobs whose ``job_key`` has
    #: no ``open_cuts`` (made up to 7 December 2026) faded them towards the photo there, and replay makes them so.
    open_cuts: bool = True
    #: Whether a paste's overlap with an earlier one is measured on the earlier one's box in view: jobs whose
    #: ``job_key`` has no ``visible_overlap`` (made up to 7 December 2026) measured its whole box, and replay does so.
    visible_overlap: bool = True
    #: Whether, of two overlapping pastes, the share hidden is measured of the farther one (drawn behind): jobs whose
    #: ``job_key`` has no ``overlap_by_depth`` (made up to 7 December 2026) measured the earlier-planned one's box,
    #: whichever was in front, and replay does so.
    overlap_by_depth: bool = True
    #: Whether a Poisson paste imports its own gradients but not the jump at its silhouette, over a domain that may
    #: reach its crop's own edges: jobs whose ``job_key`` has no ``seamless_poisson`` (made up to 7 December 2026)
    #: took every gradient of the hard composite (the hard paste back) and kept the photo on the crop's edges, and
    #: replay does so.
    seamless_poisson: bool = True


@dataclass
class CompositeState:
    job: CompositeJob
    config: CompositeConfig
    class_map: ClassMap
    bank: Bank
    pools: dict
    by_relative: dict
    writer: BackgroundWriter = field(default_factory=BackgroundWriter)
    cutouts: OrderedDict = field(default_factory=OrderedDict)

    def cutout(self, entry: BankEntry) -> CutoutPixels:
        pixels = self.cutouts.pop(entry.id, None)
        if pixels is None:
            pixels = read_cutout(self.bank.root, entry)
        self.cutouts[entry.id] = pixels
        while len(self.cutouts) > CUTOUT_CACHE:
            self.cutouts.popitem(last=False)
        return pixels


def init_worker(job: CompositeJob) -> CompositeState:
    """Read the bank (its files were checked by the command) and index the backgrounds."""
    config = CompositeConfig.from_document(job.config_document, source="generate.json: job_key.config")
    bank = read_bank(job.bank_root)
    return CompositeState(job=job, config=config, class_map=ClassMap.from_document(job.class_map_document),
                          bank=bank, pools=eligible(bank.entries, config),
                          by_relative={(b.relative): (k, b) for k, b in enumerate(job.backgrounds.images)})


def work(state: CompositeState, item) -> list[dict]:
    """Make ``item`` (a :class:`PlannedComposite`) and start writing it; returns the results of composites whose
    files are now complete (``{"record", "seconds"}``; all of them for :data:`FLUSH`)."""
    if item == FLUSH:
        return state.writer.drain()
    return state.writer.submit(write_image, state, make_composite(state, item), WRITERS)


def _frame_box(box, region, scale, size) -> tuple[tuple[float, float, float, float], float,
                                                 tuple[float, float, float, float]]:
    """A photo box (x, y, w, h) in the written frame as (x0, y0, x1, y1) clipped to it, the share of the box the
    cut leaves, and the box in the frame's coordinates unclipped."""
    x0, y0 = (box.x - region[0]) * scale, (box.y - region[1]) * scale
    x1, y1 = x0 + box.w * scale, y0 + box.h * scale
    cx0, cy0, cx1, cy1 = max(0.0, x0), max(0.0, y0), min(float(size[0]), x1), min(float(size[1]), y1)
    full = (x1 - x0) * (y1 - y0)
    kept = max(0.0, cx1 - cx0) * max(0.0, cy1 - cy0)
    return (cx0, cy0, max(cx0, cx1), max(cy0, cy1)), (kept / full if full > 0 else 0.0), (x0, y0, x1, y1)


def covered_by_pastes(box: tuple[float, float, float, float], instance_ids: np.ndarray) -> float:
    """Share of the pixels whose centres lie in ``box`` (x0, y0, x1, y1) that show a pasted instance (0 for a box
    holding no pixel centre)."""
    c0, c1 = int(np.ceil(box[0] - 0.5)), int(np.ceil(box[2] - 0.5))
    r0, r1 = int(np.ceil(box[1] - 0.5)), int(np.ceil(box[3] - 0.5))
    window = instance_ids[max(0, r0):max(0, r1), max(0, c0):max(0, c1)]
    return float(np.count_nonzero(window)) / window.size if window.size else 0.0


def _background_entries(background: Background, labelled: bool, photo, config: CompositeConfig,
                        size) -> list[dict]:
    """The photo's boxes in the frame, before pasting: kept so far, or dropped as a crowd region (COCO's
    ``iscrowd``: no one object), unmapped, empty (no width or no height in the photo) or cropped."""
    out: list[dict] = []
    if not labelled:
        return out
    for box in background.boxes:
        ours = config.background_labels.our_class(box.label)
        frame, kept_share, unclipped = _frame_box(box, photo.region, photo.scale, size)
        reason = "crowd" if box.ignore else "unmapped" if ours is None else "empty" if min(box.w, box.h) <= 0 else (
            "cropped" if kept_share < config.background_labels.drop_cropped_share else None)
        out.append({"label": box.label, "class_name": ours, "frame": frame, "unclipped": unclipped,
                    "covered_share": None, "kept": reason is None, "reason": reason})
    return out


def composite_yolo_text(record: CompositeRecord, class_map: ClassMap, convention: str) -> str:
    """The YOLO label file of a composite's record: the boxes of ``convention`` (its visible pasted instances that
    are not ignore regions, then the photo's kept boxes), one ``index cx cy w h`` line each, ignored boxes
    (below the detector's least height) left out."""
    targets = targets_for(convention)
    boxes = image_boxes([i for i in record["instances"] if not i["ignore"]], targets) + background_boxes(record,
                                                                                                          targets)
    by_name = {c.name: c.id for c in class_map.classes}
    return yolo.box_lines([(by_name[b.label], b.x, b.y, b.w, b.h) for b in boxes if not b.ignore],
                          record["width"], record["height"], yolo.class_index(class_map))


def make_composite(state: CompositeState, planned: PlannedComposite) -> ImageBuffers:
    """Compose, annotate and check one planned composite (nothing is written here)."""
    job, config, class_map, bank = state.job, state.config, state.class_map, state.bank
    t0 = time.perf_counter()
    index, background = state.by_relative[planned.background]
    photo = read_photo(job.backgrounds.path(background), config.output)
    height, width = photo.pixels.shape[:2]
    rng = stream(config.seed, planned.seed, "composite", planned.background)
    camera_rng, paste_rng = rng.spawn(2)
    settings, sources = config.camera_for(planned.background)
    boxes = _background_entries(background, job.backgrounds.labelled, photo, config, (width, height))
    people = [b for b in boxes if b["kept"] or b["reason"] == "cropped"]
    if job.people_in_photo:     # the photo's edges in written rows: the cut for the output may crop a box
        top = -photo.region[1] * photo.scale
        placing = [(b["class_name"], b["unclipped"]) for b in people]
        rows: tuple[float, float] | None = (top, top + photo.header.height * photo.scale)
    else:                       # an earlier job's rule: person boxes whole in the frame
        placing, rows = [("person", b["frame"]) for b in people if b["class_name"] == "person"], None
    drawn = draw_camera(settings, sources, (width, height), photo.header.focal_35mm,
                        (photo.header.width, photo.header.height), photo.scale, camera_rng, placing, rows)
    placements = plan_pastes(drawn, state.pools, config,      # pastes keep off crowds as off the kept boxes
                             [b["frame"] for b in boxes if b["kept"] or b["reason"] == "crowd"], paste_rng,
                             job.visible_overlap, job.overlap_by_depth)
    entries = [bank.entry(p.entry_id) for p in placements]
    painted = compose(photo.pixels, [PasteInput(e, state.cutout(e), p) for e, p in zip(entries, placements)],
                      class_map, config.match, job.open_cuts, job.seamless_poisson)
    display, effects = painted.rgb, None
    if config.effects.enabled:
        effects = draw_effects(stream(config.seed, planned.seed, "effects", planned.background), config.effects)
        depth = (composite_depth(drawn.camera.ground_depth(), painted, [p.distance_m for p in placements])
                 if effects.defocus is not None else None)
        display = apply_effects(display, effects, depth)
    grey = photo.monochrome and job.grey_photos
    if grey:        # a grey photo's composite is grey: colour pastes would give themselves away
        display = to_monochrome(display)
    seconds = {"compose": time.perf_counter() - t0}

    t0 = time.perf_counter()
    class_ids, instance_ids = painted.class_ids, painted.instance_ids
    instances = annotate(class_ids, instance_ids, painted.instances, painted.amodal, painted.truncation)
    ignored = mark_ignored(instances, config.min_instance_px)
    for instance in instances:
        points = painted.keypoints.get(instance["id"])
        if points is not None:
            flags = keypoints.pasted_visibility(points, instance["id"], instance_ids)
            instance["keypoints"] = {"names": list(KEYPOINT_CLASSES[instance["class_name"]].names),
                                  "keypoints": keypoints.coco_keypoints(points[:, :2], flags),
                                  "num_keypoints": int((flags > 0).sum())}
    for box in boxes:
        if box["kept"]:
            box["covered_share"] = covered_by_pastes(box["frame"], instance_ids)
            if box["covered_share"] > config.background_labels.drop_covered_share:
                box["kept"], box["reason"] = False, "covered"
    panoptic_png, segments = panoptic(class_ids, instance_ids, painted.instances, class_map, ignored)
    measures = qa.measure(display, instances)
    verdict, reasons = qa.verdict(measures, config.qa)
    pastes = []
    for placement, entry, painted_paste in zip(placements, entries, painted.pastes):
        ax, ay = entry.anchor
        ground = [[placement.anchor_px[0] + placement.scale * (x - ax), placement.anchor_px[1] + placement.scale * (y - ay)]
                  for x, y in entry.ground_points]
        pastes.append({**placement.to_dict(), "cutout": {"bank": bank.id, "entry": entry.id}, "group": entry.group,
                       "aid": entry.aid, "exposure_gain": painted_paste["exposure_gain"],
                       "white_balance_gains": painted_paste["white_balance_gains"],
                       "instance_ids": painted_paste["instance_ids"], "ground_points": ground})
        for name in ("sharpness_sigma_px", "contrast_gain", "saturation_gain"):  # written where matching is on
            if name in painted_paste:
                pastes[-1][name] = painted_paste[name]
        del pastes[-1]["entry_id"]
        if not config.sharpen.on:  # written where sharpening is on (earlier datasets keep their records)
            del pastes[-1]["sharpen"]
    record = CompositeRecord(
        id=planned.id, name=planned.name, split=planned.split, width=width, height=height, seed=planned.seed,
        camera=drawn.to_dict(), files={},
        class_pixel_counts={class_map.by_id(int(c)).name: int(n)
                            for c, n in enumerate(np.bincount(class_ids.ravel(), minlength=256)) if n},
        instances=instances, panoptic_segments=segments,
        qa=QAResult(verdict=verdict, reasons=list(reasons), measures=measures),
        composite={"background": {"path": background.relative, "sha256": photo.sha256,
                                  "layout": job.backgrounds.layout, "labelled": job.backgrounds.labelled,
                                  "width": photo.header.width, "height": photo.header.height,
                                  "region": [float(v) for v in photo.region], "scale": float(photo.scale),
                                  **({"monochrome": True} if grey else {})},
                   "bank": {"id": bank.id, "format": BANK_FORMAT}, "pastes": pastes,
                   "background_boxes": [{"label": b["label"], "class_name": b["class_name"],
                                         "bbox": [round(b["frame"][0], 4), round(b["frame"][1], 4),
                                                  round(b["frame"][2] - b["frame"][0], 4),
                                                  round(b["frame"][3] - b["frame"][1], 4)],
                                         "covered_share": b["covered_share"], "kept": b["kept"],
                                         "reason": b["reason"]} for b in boxes],
                   "effects": None if effects is None else effects.to_dict()})
    cs = CityscapesName(job.city, index, planned.id)
    rejected = verdict == REJECTED
    files, arrays = label_files(planned.name, planned.split, cs, rejected, display, class_ids, instance_ids,
                                painted.instances, ignored, panoptic_png,
                                "" if rejected else composite_yolo_text(record, class_map, config.convention),
                                class_map)
    record["files"] = files
    seconds["annotate"] = time.perf_counter() - t0
    return ImageBuffers(record, arrays, rejected, seconds)
