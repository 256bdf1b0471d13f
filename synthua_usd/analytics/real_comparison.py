"""``synthua stats DATASET --compare REAL``: where a generated dataset differs from a real detection set, measure by
measure, before anything is trained on it.

The two sides:

* **ours**: the dataset's images (QA-rejected left out) and the boxes a detector trains on
  (:mod:`~synthua_usd.analytics.detection_targets`), drawn by a named box convention (default ``wheelchair-sets``:
  a wheelchair's box covers its seated user, who has no person box, as real wheelchair sets box them); boxes lower
  than ``min_height_px`` (default 8 px) are left out, as training leaves them out.
* **real**: a detection set read by :mod:`~synthua_usd.analytics.detection_sources` (an Ultralytics YOLO folder:
  every split unless one is asked for; a COCO instances file; or another generated dataset, through the same
  convention); boxes marked ``iscrowd`` left out.

Each of our classes counts as the real class the mapping gives it (:mod:`~synthua_usd.analytics.class_mapping`:
``--map REAL=OURS[,OURS...]``; without it the same names, and ``wheelchair`` = both wheelchair classes); classes
either side the mapping leaves out are not compared. Measures, per class and over all mapped classes (``all``):

* ``box_height_share``: a box's height / its image's height, per box;
* ``aspect_ratio``: a box's width / height, per box (boxes of zero width or height left out);
* ``boxes_per_image``: boxes in an image, per image, images without any counted as 0;

and per image, for ``all`` only: ``rms_contrast`` and ``edge_density`` of the RGB as stored
(:mod:`~synthua_usd.analytics.image_contrast`, which defines them; ours as ``synthua stats`` measures them, the real
photos by :func:`~synthua_usd.analytics.image_contrast.photo_measures`).

Per measure and class: each side's count, mean, median, 10th and 90th percentile
(:func:`~synthua_usd.analytics.image_contrast.spread`), and the two-sample Kolmogorov–Smirnov statistic
D = sup |F_ours(x) − F_real(x)| (the largest gap between the two empirical distribution functions: 0 for the same
distribution, 1 for samples that do not overlap) with its two-sided p-value, both by ``scipy.stats.ks_2samp``
(exact for small samples, asymptotic for large). With thousands of boxes even a small D has a tiny p-value: D says
how far apart the distributions are, p only whether the gap could be chance.
"""

from __future__ import annotations

import logging
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from synthua_usd.analytics.class_mapping import build_mapping
from synthua_usd.analytics.dataset_index import DatasetIndex
from synthua_usd.analytics.detection_sets import DetectionSet
from synthua_usd.analytics.detection_sources import detect_format, read_detection_set
from synthua_usd.analytics.detection_targets import read_generated, targets_for
from synthua_usd.analytics.image_contrast import SPREAD, photo_measures, spread
from synthua_usd.model.detection_limits import DEFAULT_MIN_HEIGHT_PX
from synthua_usd.model.photo_sets import ALL_SPLITS

log = logging.getLogger(__name__)

#: The measures, in the order they are reported.
MEASURES = ("box_height_share", "aspect_ratio", "boxes_per_image", "rms_contrast", "edge_density")
#: Measures of each image rather than of each box; reported over all classes only.
IMAGE_MEASURES = ("rms_contrast", "edge_density")
#: The row over every mapped class.
ALL = "all"
#: The box convention our boxes are drawn by unless another is asked for: the real wheelchair sets'.
DEFAULT_COMPARE_CONVENTION = "wheelchair-sets"


@dataclass(frozen=True)
class MeasureComparison:
    """One measure of one class (``class_name``, a real class, or :data:`ALL`): each side's :func:`spread` and the
    Kolmogorov–Smirnov statistic and p-value (None when a side has no value)."""

    measure: str
    class_name: str
    ours: dict
    real: dict
    ks_statistic: float | None
    ks_p_value: float | None

    def row(self) -> dict:
        """A flat row (``real_comparison.csv``)."""
        return ({"measure": self.measure, "class": self.class_name}
                | {f"ours_{k}": self.ours[k] for k in ("count",) + SPREAD}
                | {f"real_{k}": self.real[k] for k in ("count",) + SPREAD}
                | {"ks_statistic": self.ks_statistic, "ks_p_value": self.ks_p_value})


@dataclass(frozen=True)
class RealComparison:
    """The comparison of a dataset with a real set: ``rows`` in :data:`MEASURES` order (``all`` first, then the
    classes); ``about`` what was compared (sources, mapping, convention, counts); ``samples`` (measure, class) ->
    (ours, real) values, for the figures."""

    rows: tuple[MeasureComparison, ...]
    about: dict
    samples: dict = field(repr=False, default_factory=dict)

    def document(self) -> dict:
        """``statistics.json``'s ``real_comparison``."""
        return self.about | {"measures": [r.row() for r in self.rows]}

    def largest(self, count: int = 3) -> list[MeasureComparison]:
        """The rows whose distributions differ most (largest KS statistic first)."""
        known = [r for r in self.rows if r.ks_statistic is not None]
        return sorted(known, key=lambda r: -r.ks_statistic)[:count]


def ks(ours, real) -> tuple[float | None, float | None]:
    """(D, p) of ``scipy.stats.ks_2samp(ours, real)``, two-sided; (None, None) when either is empty."""
    from scipy.stats import ks_2samp

    if len(ours) == 0 or len(real) == 0:
        return None, None
    result = ks_2samp(np.asarray(ours, np.float64), np.asarray(real, np.float64))
    return float(result.statistic), float(result.pvalue)


def box_samples(dataset: DetectionSet, label_of: dict[str, str], classes: tuple[str, ...]) -> dict:
    """(measure, class) -> values of the box measures of ``dataset``: a box labelled ``l`` counts as class
    ``label_of[l]`` (boxes of other labels, and ignored ones, left out); ``classes`` the compared classes."""
    out: dict[tuple[str, str], list[float]] = defaultdict(list)
    for image in dataset.images:
        per_class = dict.fromkeys(classes, 0)
        for box in image.boxes:
            name = label_of.get(box.label)
            if name is None or box.ignore:
                continue
            per_class[name] += 1
            for key in (name, ALL):
                out["box_height_share", key].append(box.h / image.height)
                if box.w > 0 and box.h > 0:
                    out["aspect_ratio", key].append(box.w / box.h)
        for name, count in per_class.items():
            out["boxes_per_image", name].append(float(count))
        out["boxes_per_image", ALL].append(float(sum(per_class.values())))
    return out


def read_real(path: str | Path, split: str | None = None, convention: str = DEFAULT_COMPARE_CONVENTION,
              fmt: str = "auto") -> DetectionSet:
    """The real set at ``path``: a YOLO set's ``split`` (None: every split), a generated dataset's (None: every
    split) with boxes by ``convention``, a COCO file whole."""
    fmt = detect_format(Path(path)) if fmt == "auto" else fmt
    if fmt == "yolo" and split is None:
        split = ALL_SPLITS
    return read_detection_set(path, fmt, split, targets=targets_for(convention))


def compare(index: DatasetIndex, contrast: list[dict], real: DetectionSet, maps: tuple[str, ...] = (),
            convention: str = DEFAULT_COMPARE_CONVENTION,
            min_height_px: float = DEFAULT_MIN_HEIGHT_PX) -> RealComparison:
    """The comparison of the dataset of ``index`` (``contrast``: its images' measures as
    :func:`synthua_usd.analytics.statistics.compute` gives them, by name) with ``real``; ``maps`` the ``--map``
    options; ``convention`` the box convention of our boxes, lower than ``min_height_px`` left out."""
    things = [c.name for c in index.class_map.classes if c.isthing]
    mapping = build_mapping(maps, real.names, things, test_side="the real set", model_side="the dataset's class map")
    ours_classes = tuple(m for m in things if m in mapping.test_class_of())
    targets = targets_for(convention, ours_classes, min_height_px=min_height_px)
    ours = read_generated(index.root, None, targets)
    classes = mapping.test_classes
    samples_ours = box_samples(ours, mapping.test_class_of(), classes)
    samples_real = box_samples(real, {c: c for c in classes}, classes)
    by_name = {r["name"]: r for r in contrast}
    kept = [by_name[Path(im.path).stem] for im in ours.images if Path(im.path).stem in by_name]
    log.info("measuring the contrast and edges of %d real photos", len(real.images))
    real_contrast = [photo_measures(im.path) for im in real.images]
    for measure in IMAGE_MEASURES:
        samples_ours[measure, ALL] = [r[measure] for r in kept]
        samples_real[measure, ALL] = [r[measure] for r in real_contrast]
    rows, samples = [], {}
    for measure in MEASURES:
        for name in (ALL,) + (() if measure in IMAGE_MEASURES else classes):
            a, b = samples_ours.get((measure, name), []), samples_real.get((measure, name), [])
            rows.append(MeasureComparison(measure, name, spread(a), spread(b), *ks(a, b)))
            samples[measure, name] = (np.asarray(a, np.float64), np.asarray(b, np.float64))
    ignored = sum(b.ignore for im in ours.images for b in im.boxes)
    about = {
        "real": {"source": real.source, "layout": real.layout, "split": real.split, "images": len(real.images),
                 "boxes": {c: len(samples_real.get(("box_height_share", c), [])) for c in classes},
                 "classes_not_compared": [n for n in real.names if n not in classes]},
        "ours": {"images": len(ours.images),
                 "boxes": {c: len(samples_ours.get(("box_height_share", c), [])) for c in classes},
                 "ignored_boxes_left_out": int(ignored), "min_height_px": targets.min_height_px},
        "mapping": mapping.document(), "mapping_options": mapping.text(), "convention": convention,
        "targets": targets.document(),
    }
    return RealComparison(tuple(rows), about, samples)
