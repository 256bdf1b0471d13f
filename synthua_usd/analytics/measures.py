"""The paper's statistics as plain formulas over NumPy arrays (Section 3 of SYNTHUA-DT): balance of a
distribution (Shannon entropy, normalised entropy, Gini coefficient, classes needed for a coverage),
summaries of object areas, imbalance ratios, scene-density buckets and co-occurrence.

Every function takes plain numbers and returns plain numbers; what is counted is decided by the caller
(:mod:`synthua_usd.analytics.statistics`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Scene-density buckets of instances per image, as the paper reports them: <= 100, 101-500, > 500.
DENSITY_BUCKETS = (("<=100", 0, 100), ("101-500", 101, 500), (">500", 501, None))


def shares(values) -> np.ndarray:
    """(n,) non-negative amounts -> (n,) float64 shares summing to 1 (all zeros when the total is 0)."""
    x = np.asarray(values, np.float64)
    total = x.sum()
    return x / total if total > 0 else np.zeros_like(x)


def shannon_entropy_bits(values) -> float:
    """H = -sum p_i log2 p_i over the shares p of ``values`` (zero shares add nothing), in bits."""
    p = shares(values)
    p = p[p > 0]
    return float(-(p * np.log2(p)).sum()) if p.size else 0.0


def normalised_entropy(values) -> float:
    """H / log2(n) for n = len(values) categories (zeros included): 1 for a uniform distribution, 0 when one
    category holds everything; 0 for fewer than two categories."""
    n = len(values)
    return shannon_entropy_bits(values) / float(np.log2(n)) if n >= 2 else 0.0


def gini(values) -> float:
    """Gini coefficient G = sum_i sum_j |x_i - x_j| / (2 n^2 mean) of ``values`` (zeros included), computed
    from the ascending sort as G = 2 sum_i i x_(i) / (n sum x) - (n + 1) / n with i = 1..n.
    0 for equal amounts, (n - 1) / n when one of n holds everything; 0 for an empty or all-zero input."""
    x = np.sort(np.asarray(values, np.float64))
    n = x.size
    total = x.sum()
    if n == 0 or total <= 0:
        return 0.0
    i = np.arange(1, n + 1)
    return float(2.0 * (i * x).sum() / (n * total) - (n + 1.0) / n)


def classes_for_coverage(values, coverage: float = 0.8) -> int:
    """The fewest categories whose amounts, largest first, reach ``coverage`` of the total (0 for an all-zero
    input). A tiny tolerance keeps exact reaches (0.8 of the total) from failing on rounding."""
    p = np.sort(shares(values))[::-1]
    if p.sum() == 0:
        return 0
    cumulative = np.cumsum(p)
    return int(np.searchsorted(cumulative, coverage - 1e-12) + 1)


def coverage_curve(values) -> np.ndarray:
    """(n,) cumulative shares of ``values`` sorted largest first (the coverage CDF)."""
    return np.cumsum(np.sort(shares(values))[::-1])


@dataclass(frozen=True)
class AreaSummary:
    """Object areas of one class in pixels: count, mean, median, population standard deviation (ddof 0),
    maximum and interquartile range Q3 - Q1 (quartiles by linear interpolation, NumPy's default)."""

    count: int
    mean: float | None
    median: float | None
    std: float | None
    max: float | None
    iqr: float | None

    @classmethod
    def of(cls, areas) -> "AreaSummary":
        a = np.asarray(areas, np.float64)
        if a.size == 0:
            return cls(0, None, None, None, None, None)
        q1, q3 = np.percentile(a, [25, 75])
        return cls(int(a.size), float(a.mean()), float(np.median(a)), float(a.std()), float(a.max()),
                   float(q3 - q1))


def imbalance_ratios(counts) -> list[float | None]:
    """IR_c = max(counts) / count_c per class; None for a class with count 0 (no ratio exists)."""
    c = np.asarray(counts, np.float64)
    top = c.max() if c.size else 0.0
    return [float(top / v) if v > 0 else None for v in c]


def density_buckets(instances_per_image) -> dict[str, int]:
    """Images per scene-density bucket (:data:`DENSITY_BUCKETS`)."""
    n = np.asarray(instances_per_image, np.int64)
    return {name: int(np.count_nonzero((n >= lo) & ((n <= hi) if hi is not None else True)))
            for name, lo, hi in DENSITY_BUCKETS}


def cooccurrence(presence: np.ndarray) -> np.ndarray:
    """(images, classes) bool presence -> (classes, classes) int64 counts of images in which both classes
    appear; the diagonal is the number of images showing the class."""
    p = np.asarray(presence, np.int64)
    return p.T @ p
