"""The sim-to-real experiment as data: its arms, budgets in image-steps, nested subsets of the real photos, the runs
they make, the spread of their scores over seeds, and each arm against (b) (:func:`compare`: the difference of the
means and Welch's interval of it) (``tools/sim2real.py`` runs it; docs/statistics.md).

Arms (each trained once per seed, each from the same initial weights):

=====  ====================================================================================================
``a``  synthetic only: a generated dataset's train split
``b``  real only: the real training photos (or a nested subset of them)
``c``  synthetic, then real: (a)'s run of the same seed fine-tuned on (b)'s photos with (b)'s budget
``d``  real + another labelled set (composites of aid users into those photos, say) mixed in one training
=====  ====================================================================================================

A budget is a number of **image-steps** (epochs × training images), the same for every arm, because minutes
drift 15–25 % between runs on a shared machine while image-steps do not. Each arm's epochs are the budget over
its training set's size, rounded to the nearest whole number (halves up), at least 1; :class:`EpochBudget` says
when that rounding changes the steps. Ultralytics turns mosaic augmentation off for the last ``close_mosaic``
epochs, an epoch count: 10 of 150 epochs of 50 photos, but 10 of the 17 epochs of a 450-image mixed set (six tenths of
its steps); every arm closes it for the same share of its epochs (:attr:`EpochBudget.close_mosaic`, by default
:data:`CLOSE_MOSAIC_SHARE`, Ultralytics' 10 epochs of the 150 a 7,500-image-step budget gives 50 photos). The real
photos are drawn once, in a seeded order, and a subset of n photos
is the first n of that order, so the subsets are nested (25 ⊂ 50 ⊂ 100 ...) and the same for every arm and seed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from synthua_usd.analytics.detection_metrics import FP_KINDS
from synthua_usd.core.errors import InputError, echo

ARMS = {"a": "synthetic only", "b": "real only", "c": "synthetic, then real", "d": "real + mixed set"}
#: Arms trained on the real photos (at every real size).
REAL_ARMS = ("b", "c", "d")
#: ``--real-sizes``' word for every real training photo.
ALL = "all"
#: The fewest seeds whose spread a comparison may quote.
MIN_SEEDS = 3
#: Share of an arm's epochs trained without mosaic augmentation at the end (``--close-mosaic-share``).
CLOSE_MOSAIC_SHARE = 1 / 15


@dataclass(frozen=True)
class EpochBudget:
    """``budget_images`` image-steps over ``images`` training images: ``epochs`` (the quotient rounded to the nearest
    whole number, halves up, at least 1), the last ``close_mosaic`` of them without mosaic augmentation."""

    budget_images: int
    images: int
    epochs: int
    close_mosaic: int = 0

    @property
    def image_steps(self) -> int:
        """What is trained: epochs × images."""
        return self.epochs * self.images

    @property
    def exact(self) -> bool:
        return self.image_steps == self.budget_images

    def note(self) -> str | None:
        """How rounding changed the steps (None when it did not)."""
        if self.exact:
            return None
        change = 100.0 * (self.image_steps - self.budget_images) / self.budget_images
        return (f"{self.budget_images:,} image-steps / {self.images:,} images = {self.budget_images / self.images:.2f} "
                f"epochs, trained as {self.epochs}: {self.image_steps:,} image-steps ({change:+.1f} %)")


def _half_up(x: float) -> int:
    return math.floor(x + 0.5)


def epochs_for(budget_images: int, images: int, close_mosaic_share: float = CLOSE_MOSAIC_SHARE) -> EpochBudget:
    """The whole epochs of ``budget_images`` image-steps over ``images`` training images, ``close_mosaic_share`` of
    them (rounded, halves up) the last without mosaic augmentation."""
    if budget_images < 1 or images < 1:
        raise InputError(f"--budget-images: {budget_images} over {images} images; expected at least 1 of each")
    if not 0.0 <= close_mosaic_share <= 1.0:
        raise InputError(f"--close-mosaic-share: {close_mosaic_share:g}; expected a share in [0, 1]")
    epochs = max(1, _half_up(budget_images / images))
    return EpochBudget(budget_images, images, epochs, _half_up(epochs * close_mosaic_share))


def _items(text: str, option: str) -> list[str]:
    items = [t.strip() for t in str(text).split(",") if t.strip()]
    if not items:
        raise InputError(f"{option}: {echo(text)!r}; expected a comma-separated list")
    if len(set(items)) != len(items):
        raise InputError(f"{option}: {echo(text)}; expected each value once")
    return items


def parse_arms(text: str) -> tuple[str, ...]:
    """``a,b,c,d`` (any of them) -> the arms in that order."""
    arms = _items(text, "--arms")
    unknown = [a for a in arms if a not in ARMS]
    if unknown:
        raise InputError(f"--arms: {echo(', '.join(unknown))}; expected some of "
                         + ", ".join(f"{k} ({v})" for k, v in ARMS.items()))
    return tuple(a for a in ARMS if a in arms)


def parse_seeds(text: str) -> tuple[int, ...]:
    """``0,1,2`` -> (0, 1, 2): seeds are whole numbers in [0, 2^31)."""
    seeds = []
    for item in _items(text, "--seeds"):
        if not item.isdigit() or int(item) >= 2**31:
            raise InputError(f"--seeds: {echo(item)!r}; expected whole numbers from 0 to 2147483647, e.g. 0,1,2")
        seeds.append(int(item))
    return tuple(seeds)


def parse_sizes(text: str, available: int) -> tuple[int, ...]:
    """``25,50,all`` over ``available`` real training photos -> the sizes, ascending (``all`` = ``available``)."""
    sizes = []
    for item in _items(text, "--real-sizes"):
        if item == ALL:
            sizes.append(available)
        elif item.isdigit() and 1 <= int(item) <= available:
            sizes.append(int(item))
        else:
            raise InputError(f"--real-sizes: {echo(item)!r}; expected numbers of real training photos from 1 to "
                             f"{available} (the training set's), or {ALL}")
    return tuple(sorted(set(sizes)))


def draw_order(names: Sequence[str], seed: int) -> tuple[str, ...]:
    """``names`` (sorted first, so the order does not depend on how they were listed) in the order of a
    ``numpy.random.default_rng(seed)`` permutation."""
    ordered = sorted(names)
    if len(set(ordered)) != len(ordered):
        raise InputError("real training photos: a photo is listed twice; expected each photo once")
    return tuple(ordered[k] for k in np.random.default_rng(seed).permutation(len(ordered)))


def nested_subsets(names: Sequence[str], sizes: Sequence[int], seed: int) -> dict[int, tuple[str, ...]]:
    """Subsets of ``names``, one per size: the first n of :func:`draw_order`, so every subset holds the smaller ones."""
    order = draw_order(names, seed)
    return {n: order[:n] for n in sizes}


@dataclass(frozen=True)
class PlannedRun:
    """One training: ``arm``, the real photos it sees (``real_images``; None for (a)), ``seed``, its ``budget``, and
    the number of images of another set mixed in (``mixed_images``, arm d)."""

    arm: str
    real_images: int | None
    seed: int
    budget: EpochBudget
    mixed_images: int = 0

    @property
    def name(self) -> str:
        """Its folder name: ``a_synthetic_s0``, ``b_n0050_s0``, ..."""
        return f"a_synthetic_s{self.seed}" if self.arm == "a" else f"{self.arm}_n{self.real_images:04d}_s{self.seed}"

    @property
    def pretraining(self) -> str | None:
        """The run (c) starts from: (a)'s of the same seed."""
        return f"a_synthetic_s{self.seed}" if self.arm == "c" else None


def plan_runs(arms: Sequence[str], sizes: Sequence[int], seeds: Sequence[int], budget_images: int,
              synthetic_budget_images: int, synthetic_images: int | None = None,
              mixed_images: dict[int, int] | None = None,
              close_mosaic_share: float = CLOSE_MOSAIC_SHARE) -> list[PlannedRun]:
    """Every run of the experiment, seed by seed (so that an interrupted experiment has whole seeds): (a) first
    when (a) or (c) is asked (c starts from it), then (b), (c), (d) at each real size, smallest first.
    ``mixed_images``: images of the mixed set at each size (arm d); every run without mosaic for the last
    ``close_mosaic_share`` of its epochs."""
    runs = []
    for seed in seeds:
        if "a" in arms or "c" in arms:
            runs.append(PlannedRun("a", None, seed, epochs_for(synthetic_budget_images, synthetic_images,
                                                                  close_mosaic_share)))
        for n in sizes:
            for arm in (a for a in REAL_ARMS if a in arms):
                mixed = (mixed_images or {}).get(n, 0) if arm == "d" else 0
                runs.append(PlannedRun(arm, n, seed, epochs_for(budget_images, n + mixed, close_mosaic_share),
                                        mixed))
    return runs


def spread(values: Sequence[float | None]) -> dict:
    """Mean, min, max and sample standard deviation (n − 1; None under 2 values) of the values that are not None
    (an AP is None where the test set has no box of its class); ``n`` counts them."""
    x = np.asarray([v for v in values if v is not None], dtype=float)
    if x.size == 0:
        return {"n": 0, "mean": None, "min": None, "max": None, "std": None}
    return {"n": int(x.size), "mean": float(x.mean()), "min": float(x.min()), "max": float(x.max()),
            "std": float(x.std(ddof=1)) if x.size > 1 else None}


#: The counts at the detection confidence a score row holds beside its APs: true and false positives, false
#: negatives, and the false positives by what they land on.
COUNTS = ("tp", "fp", "fn") + tuple(f"fp_{kind}" for kind in FP_KINDS)


def summarise(scores: Sequence[dict], measures: Sequence[str] = ("AP50", "AP50_95") + COUNTS) -> list[dict]:
    """Rows of ``scores`` (one per run, test set and class: ``test``, ``arm``, ``real_images``, ``seed``, ``class``
    and the measures) grouped over seeds: per (test, arm, real_images, class) the seeds and each measure's
    :func:`spread` (of the rows that hold it), in the order the groups first appear."""
    groups: dict[tuple, list[dict]] = {}
    for row in scores:
        groups.setdefault((row["test"], row["arm"], row["real_images"], row["class"]), []).append(row)
    return [{"test": test, "arm": arm, "real_images": n, "class": name, "seeds": [r["seed"] for r in rows]}
            | {m: spread([r.get(m) for r in rows]) for m in measures}
            for (test, arm, n, name), rows in groups.items()]


#: Confidence of :func:`compare`'s interval of a difference of means.
CONFIDENCE = 0.95


def compare(scores: Sequence[dict], baseline: str = "b", measure: str = "AP50",
            confidence: float = CONFIDENCE) -> list[dict]:
    """Every other arm against ``baseline`` at the same test set, real size and class, in ``measure``: the
    difference of the means over seeds, the differences seed by seed (the seeds both arms have), the ranges, and
    Welch's interval of the difference at ``confidence`` (unequal variances, Welch-Satterthwaite degrees of freedom;
    None under 2 seeds on either side). ``beyond`` says whether the whole interval lies above zero: a difference
    the seeds' spread does not explain (``df`` None where neither arm varies: the interval is the difference)."""
    from scipy.stats import t as student_t

    groups: dict[tuple, dict[str, dict[int, float]]] = {}
    for row in scores:
        if row[measure] is not None:
            key = (row["test"], row["real_images"], row["class"])
            groups.setdefault(key, {}).setdefault(row["arm"], {})[row["seed"]] = float(row[measure])
    out = []
    for (test, n, name), arms in groups.items():
        base = arms.get(baseline)
        if not base:
            continue
        for arm, values in arms.items():
            if arm == baseline:
                continue
            x, y = spread(list(values.values())), spread(list(base.values()))
            common = sorted(set(values) & set(base))
            row = {"test": test, "real_images": n, "class": name, "arm": arm, "baseline": baseline,
                   "measure": measure, "seeds": sorted(values), "baseline_seeds": sorted(base),
                   "difference": x["mean"] - y["mean"],
                   "common_seeds": common, "per_seed": [values[s] - base[s] for s in common],
                   "ranges_overlap": max(x["min"], y["min"]) <= min(x["max"], y["max"]),
                   "confidence": confidence, "df": None, "low": None, "high": None, "beyond": None}
            if x["n"] > 1 and y["n"] > 1:
                vx, vy = x["std"] ** 2 / x["n"], y["std"] ** 2 / y["n"]
                se = math.sqrt(vx + vy)
                df, half = None, 0.0                              # no spread at all: the interval is the point
                if se > 0:
                    df = (vx + vy) ** 2 / (vx ** 2 / (x["n"] - 1) + vy ** 2 / (y["n"] - 1))
                    half = float(student_t.ppf((1 + confidence) / 2, df)) * se
                row |= {"df": df, "low": row["difference"] - half, "high": row["difference"] + half,
                        "beyond": row["difference"] - half > 0}
            out.append(row)
    return out
