"""The balance and summary formulas on small inputs computed by hand (values in the comments)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from synthua_usd.analytics import measures as m


def pairwise_gini(values) -> float:
    """The definition: sum over ordered pairs |x_i - x_j| / (2 n^2 mean)."""
    x = list(values)
    n, mean = len(x), sum(x) / len(x)
    return sum(abs(a - b) for a, b in itertools.product(x, x)) / (2 * n * n * mean)


def test_gini_by_hand():
    # |1-2|+|1-3|+|1-4|+|2-3|+|2-4|+|3-4| = 10, twice over ordered pairs = 20; 20 / (2 * 16 * 2.5) = 0.25
    assert m.gini([1, 2, 3, 4]) == pytest.approx(0.25)
    assert m.gini([4, 1, 3, 2]) == pytest.approx(0.25)          # order does not matter
    assert m.gini([0, 0, 0, 5]) == pytest.approx(0.75)          # one of n holds all: (n - 1) / n
    assert m.gini([2, 2, 2]) == 0.0
    assert m.gini([]) == 0.0 and m.gini([0, 0]) == 0.0
    rng = np.random.default_rng(0)
    for _ in range(5):
        x = rng.integers(0, 50, size=7)
        if x.sum():
            assert m.gini(x) == pytest.approx(pairwise_gini(x))


def test_entropy_by_hand():
    # shares 1/4, 1/4, 1/2: H = 1/4*2 + 1/4*2 + 1/2*1 = 1.5 bits; normalised by log2 3
    assert m.shannon_entropy_bits([1, 1, 2]) == pytest.approx(1.5)
    assert m.normalised_entropy([1, 1, 2]) == pytest.approx(1.5 / math.log2(3))
    # zeros count as categories in the normalisation: 1 bit over log2 4 = 2 bits
    assert m.shannon_entropy_bits([1, 0, 0, 1]) == pytest.approx(1.0)
    assert m.normalised_entropy([1, 0, 0, 1]) == pytest.approx(0.5)
    assert m.normalised_entropy([5, 5, 5, 5]) == pytest.approx(1.0)
    assert m.shannon_entropy_bits([7, 0]) == 0.0
    assert m.shannon_entropy_bits([0, 0]) == 0.0 and m.normalised_entropy([3]) == 0.0


def test_paper_figures_are_bits_over_35_classes():
    """The paper's H = 3.5615 and H_norm = 0.6943 agree with bits normalised by log2 35 (not by ln)."""
    assert 3.5615 / math.log2(35) == pytest.approx(0.6943, abs=2e-4)


def test_coverage_by_hand():
    assert m.classes_for_coverage([50, 30, 15, 5], 0.8) == 2        # 50 + 30 is exactly 80 %
    assert m.classes_for_coverage([29, 50, 21], 0.8) == 3           # 50 + 29 = 79 % is short
    assert m.classes_for_coverage([1, 0, 0], 0.8) == 1
    assert m.classes_for_coverage([0, 0], 0.8) == 0
    np.testing.assert_allclose(m.coverage_curve([1, 3, 0, 4]), [0.5, 0.875, 1.0, 1.0])


def test_area_summary_by_hand():
    a = m.AreaSummary.of([1, 2, 3, 4, 100])
    # mean 22, median 3; deviations -21 -20 -19 -18 78, squares sum 7610, /5 = 1522; quartiles 2 and 4
    assert (a.count, a.mean, a.median, a.max) == (5, 22.0, 3.0, 100.0)
    assert a.std == pytest.approx(math.sqrt(1522))
    assert a.iqr == pytest.approx(2.0)
    b = m.AreaSummary.of([8, 16])          # linear quartiles 10 and 14
    assert (b.mean, b.median, b.std, b.iqr) == (12.0, 12.0, 4.0, 4.0)
    assert m.AreaSummary.of([]) == m.AreaSummary(0, None, None, None, None, None)


def test_imbalance_and_density_and_cooccurrence_by_hand():
    assert m.imbalance_ratios([10, 5, 0, 1]) == [1.0, 2.0, None, 10.0]
    assert m.density_buckets([100, 101, 500, 501, 0]) == {"<=100": 2, "101-500": 2, ">500": 1}
    presence = np.array([[1, 1, 0], [1, 0, 1], [1, 1, 1]], bool)
    np.testing.assert_array_equal(m.cooccurrence(presence), [[3, 2, 2], [2, 2, 1], [2, 1, 2]])
