"""The paper's dataset statistics (SYNTHUA-DT, Section 3) computed from a :class:`DatasetIndex`.

What is counted, once for every statistic:

* Classes are those of the dataset's class map except ``unlabelled`` (id 0, void): N = 36 for the bundled map.
  Balance measures (entropy, Gini, coverage) run over all N classes, absent ones as zeros, so a class the
  dataset lacks counts as imbalance.
* An *object* (for instance counts, shares, imbalance ratios, areas and instances per image) is a panoptic
  segment: each instance of a thing class, and for a stuff class (road, sidewalk, grass, ...) its region in
  one image, as COCO panoptic counts them.
* Pixel shares are of labelled pixels (``unlabelled`` left out); the unlabelled share is given apart.
* Shannon entropy is in bits, normalised by log2 N.
* Mobility-aid classes are the device classes of :data:`synthua_usd.assets.devices.DEVICES` in the class map;
  an *aid user* is a visible person whose ``uses`` relation names a device
  (:func:`synthua_usd.dataset.qa.aid_users`).
* ``diversity``: how different the images' scenes are (:mod:`synthua_usd.analytics.diversity`; the one figure
  that reads label maps, the class-map disagreement of images sharing camera and time code).
* ``image_contrast``: RMS contrast and edge density of each image's RGB, their mean, median, p10 and p90 over the
  dataset and over each split (:mod:`synthua_usd.analytics.image_contrast`, which defines them; the one figure
  that reads every RGB, each once).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np

from synthua_usd.analytics import measures as m
from synthua_usd.analytics.dataset_index import DatasetIndex
from synthua_usd.analytics.diversity import diversity
from synthua_usd.analytics.image_contrast import image_measures, summarise
from synthua_usd.assets.devices import DEVICES
from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.model.taxonomy import SemanticClass

#: Occlusion buckets of aid users (the same edges as coverage.json's).
OCCLUSION_EDGES = (0.0, 0.25, 0.5, 0.75, 1.0)
#: Visible-pixel buckets of aid users (person + device); the last is open-ended in practice.
SIZE_EDGES = (0, 50, 100, 250, 500, 1000, 2500, 5000, 10000, 50000, 10**9)
#: Coverage asked of the "classes covering the area" figure.
COVERAGE = 0.8


@dataclass(frozen=True)
class ClassRow:
    """One class's row of ``class_statistics.csv`` (areas in pixels)."""

    id: int
    name: str
    display_name: str
    group: str
    isthing: bool
    instances: int
    instance_share: float
    imbalance_ratio: float | None
    area: m.AreaSummary
    pixels: int
    pixel_share: float
    images: int

    def csv_row(self) -> dict:
        a = self.area
        return {"id": self.id, "name": self.name, "display_name": self.display_name, "group": self.group,
                "isthing": self.isthing, "instances": self.instances, "instance_share": self.instance_share,
                "imbalance_ratio": self.imbalance_ratio, "area_mean_px": a.mean, "area_median_px": a.median,
                "area_std_px": a.std, "area_max_px": a.max, "area_iqr_px": a.iqr, "pixels": self.pixels,
                "pixel_share": self.pixel_share, "images": self.images}


@dataclass(frozen=True)
class DatasetStatistics:
    """Everything ``synthua stats`` reports; :meth:`document` is ``statistics.json``."""

    classes: tuple[ClassRow, ...]
    areas: dict[str, list[int]]            # class name -> object areas (box plots)
    instances_per_image: list[int]         # by image id
    cooccurrence: np.ndarray               # (N, N) int64 images showing both classes
    summary: dict                          # dataset-level figures (see module docstring)
    image_contrast: list[dict]             # by image id: id, name, split, rms_contrast, edge_density

    def document(self) -> dict:
        return {"summary": self.summary, "classes": [c.csv_row() for c in self.classes],
                "instances_per_image": self.instances_per_image, "image_contrast_per_image": self.image_contrast,
                "cooccurrence": {"classes": [c.name for c in self.classes], "images": self.cooccurrence.tolist()}}


def mobility_aid_classes(classes) -> list[SemanticClass]:
    """The device classes (wheelchairs, walker, crutch, canes) among ``classes``, in class-map order."""
    return [c for c in classes if c.name in DEVICES]


def _histogram(values, edges) -> dict:
    counts, edges = np.histogram(np.asarray(values, np.float64), bins=np.asarray(edges, np.float64))
    return {"edges": [float(e) for e in edges], "counts": [int(c) for c in counts]}


def _count_edges(top: int, bins: int = 30) -> np.ndarray:
    """Histogram edges for counts 0..top: one bin per integer (edges at k - 0.5) up to ``bins`` integers, else
    ``bins`` equal bins over [0, top + 1]."""
    if top + 1 <= bins:
        return np.arange(top + 2) - 0.5
    return np.linspace(0, top + 1, bins + 1)


def _distribution(values) -> dict:
    v = np.asarray(values, np.float64)
    if v.size == 0:
        return {"count": 0, "mean": None, "median": None, "max": None}
    return {"count": int(v.size), "mean": float(v.mean()), "median": float(np.median(v)), "max": float(v.max())}


def compute(index: DatasetIndex) -> DatasetStatistics:
    """The statistics of the images of ``index`` (QA-rejected images are not in it); a dataset without images
    raises :class:`InputError`."""
    if not index.images:
        raise InputError(f"{shown(index.root)}: no images ({index.rejected} rejected by QA, left out); expected a "
                         f"dataset with at least one image to describe")
    classes = [c for c in index.class_map.classes if c.id != 0]
    position = {c.id: k for k, c in enumerate(classes)}
    images = index.images
    n_img = len(images)

    areas: dict[str, list[int]] = {c.name: [] for c in classes}
    per_image = []
    for img in images:
        kept = [(cid, area) for cid, area in img.segments if cid in position]
        per_image.append(len(kept))
        for cid, area in kept:
            areas[classes[position[cid]].name].append(area)
    counts = np.array([len(areas[c.name]) for c in classes], np.int64)
    pixels = np.array([sum(img.class_pixels.get(c.name, 0) for img in images) for c in classes], np.int64)
    presence = np.array([[img.class_pixels.get(c.name, 0) > 0 for c in classes] for img in images], bool
                        ).reshape(n_img, len(classes))
    image_counts = presence.sum(axis=0)
    ratios = m.imbalance_ratios(counts)
    instance_shares, pixel_shares = m.shares(counts), m.shares(pixels)
    rows = tuple(ClassRow(c.id, c.name, c.display_name, c.group, c.isthing, int(counts[k]), float(instance_shares[k]),
                          ratios[k], m.AreaSummary.of(areas[c.name]), int(pixels[k]), float(pixel_shares[k]),
                          int(image_counts[k]))
                 for k, c in enumerate(classes))

    total_pixels = sum(img.width * img.height for img in images)
    unlabelled = sum(img.class_pixels.get("unlabelled", 0) for img in images)
    aids = mobility_aid_classes(classes)
    aid_pixels = {c.name: int(pixels[position[c.id]]) for c in aids}
    aid_total = sum(aid_pixels.values())
    users = [u for img in images for u in img.aid_users]
    with_user = sum(1 for img in images if img.aid_users)
    with_aid_class = sum(1 for img in images if any(img.class_pixels.get(c.name, 0) > 0 for c in aids))
    occlusions = [u.occlusion for u in users if u.occlusion is not None]
    sizes = [u.visible_pixels for u in users]
    ipi = np.asarray(per_image, np.int64)
    top = int(ipi.max()) if ipi.size else 0

    summary = {
        "images": n_img, "rejected_images_left_out": index.rejected,
        "classes": len(classes), "objects": int(counts.sum()),
        "pixels": int(total_pixels), "labelled_pixels": int(pixels.sum()),
        "unlabelled_share": (unlabelled / total_pixels) if total_pixels else 0.0,
        "shannon_entropy_bits": m.shannon_entropy_bits(pixels),
        "normalised_entropy": m.normalised_entropy(pixels),
        "gini_pixel_area": m.gini(pixels),
        "coverage": COVERAGE, "classes_for_coverage": m.classes_for_coverage(pixels, COVERAGE),
        "coverage_curve": [float(v) for v in m.coverage_curve(pixels)],
        "instances_per_image": _distribution(ipi) | {
            "histogram": _histogram(ipi, _count_edges(top)),
            "density_buckets": m.density_buckets(ipi)},
        "images_per_split": dict(sorted(Counter(i.split for i in images).items())),
        "images_per_condition": dict(sorted(Counter(i.condition for i in images).items())),
        "images_per_rig_type": dict(sorted(Counter(i.rig_type for i in images).items())),
        "images_with_aid_user": with_user,
        "share_images_with_aid_user": with_user / n_img if n_img else 0.0,
        "images_with_aid_class": with_aid_class,
        "share_images_with_aid_class": with_aid_class / n_img if n_img else 0.0,
        "aid_area": {name: {"pixels": px, "share": px / aid_total if aid_total else 0.0}
                     for name, px in aid_pixels.items()},
        "aid_users": {
            "count": len(users),
            "per_aid_type": dict(sorted(Counter(u.aid_type for u in users).items())),
            "occlusion": _distribution(occlusions) | {"histogram": _histogram(occlusions, OCCLUSION_EDGES)},
            "visible_pixels": _distribution(sizes) | {
                "histogram": _histogram(sizes, SIZE_EDGES)}},
    }
    summary["diversity"] = diversity(index)
    contrast = [{"id": img.id, "name": img.name, "split": img.split} | image_measures(index, img) for img in images]
    summary["image_contrast"] = summarise(contrast)
    return DatasetStatistics(classes=rows, areas=areas, instances_per_image=[int(v) for v in ipi],
                             cooccurrence=m.cooccurrence(presence), summary=summary, image_contrast=contrast)
