"""Per-class metrics and their means on a confusion matrix small enough to check by hand."""

from __future__ import annotations

import numpy as np
import pytest

from synthua_usd.analytics import segmentation_metrics as sm


def test_confusion_matrix_ignores_void_ground_truth():
    gt = np.array([[0, 1, 1], [2, 2, 0]])
    pred = np.array([[2, 1, 2], [2, 1, 1]])
    # evaluated pixels (gt != 0): (1,1) (1,2) (2,2) (2,1)
    np.testing.assert_array_equal(sm.confusion_matrix(gt, pred, 3), [[0, 0, 0], [0, 1, 1], [0, 1, 1]])
    assert sm.confusion_matrix(gt, pred, 3, ignore=None).sum() == 6


def test_metrics_by_hand():
    # rows gt, columns prediction; classes 0 (void, never in gt here), 1, 2, 3
    cm = np.array([[0, 0, 0, 0],
                   [0, 6, 2, 0],      # class 1: 8 gt pixels, 6 right, 2 taken for class 2
                   [0, 1, 3, 0],      # class 2: 4 gt pixels, 3 right, 1 taken for class 1
                   [0, 0, 0, 0]])     # class 3: no gt, no prediction
    per = sm.class_metrics(cm)
    c1, c2, c3 = per[1], per[2], per[3]
    assert (c1.tp, c1.fp, c1.fn, c1.tn) == (6, 1, 2, 3)
    assert c1.iou == pytest.approx(6 / 9) and c1.precision == pytest.approx(6 / 7)
    assert c1.recall == pytest.approx(6 / 8) and c1.f1 == pytest.approx(12 / 15)
    assert c1.accuracy == pytest.approx(9 / 12)
    assert (c2.tp, c2.fp, c2.fn, c2.tn) == (3, 2, 1, 6)
    assert c2.iou == pytest.approx(3 / 6) and c2.precision == pytest.approx(3 / 5) and c2.recall == 0.75
    assert c2.f1 == pytest.approx(2 * 0.6 * 0.75 / (0.6 + 0.75))
    assert c3.iou is None and c3.precision is None and c3.recall is None and c3.f1 is None
    assert c3.accuracy == 1.0
    s = sm.summary(cm, per)
    assert s["pixels"] == 12 and s["pixel_accuracy"] == pytest.approx(9 / 12)
    assert s["mean_iou"] == pytest.approx((6 / 9 + 3 / 6) / 2) and s["mean_iou_classes"] == 2
    assert s["frequency_weighted_iou"] == pytest.approx(8 / 12 * 6 / 9 + 4 / 12 * 3 / 6)


def test_a_class_only_predicted_counts_in_the_mean_with_iou_zero():
    cm = np.array([[0, 0, 0], [0, 2, 2], [0, 0, 0]])      # class 2 predicted, never true
    per = sm.class_metrics(cm)
    assert per[2].iou == 0.0 and per[2].precision == 0.0 and per[2].recall is None and per[2].f1 == 0.0
    assert sm.summary(cm, per)["mean_iou"] == pytest.approx((0.5 + 0.0) / 2)
