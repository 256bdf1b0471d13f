"""`synthua train` and `synthua evaluate-real` refuse bad option values with one line naming the option, before
anything is read or written (no detector needed)."""

from __future__ import annotations

import pytest

from synthua_usd.model import detection_limits as L

BAD = ["nan", "inf", "-inf", "-1", "1e308", "abc"]


@pytest.mark.parametrize("option", ["--minutes", "--imgsz", "--batch", "--epochs", "--min-height-px"])
@pytest.mark.parametrize("value", BAD)
def test_train_options_out_of_range(refuse, option, value):
    refuse("train", "out", option, value, "--out", "run", mentions=(option,))


@pytest.mark.parametrize("option", ["--confidence", "--imgsz"])
@pytest.mark.parametrize("value", BAD + ["0"])
def test_evaluate_real_options_out_of_range(refuse, option, value):
    refuse("evaluate-real", "out", "out", option, value, "--out", "eval", mentions=(option,))


def test_confidence_of_one_and_imgsz_off_the_stride_are_refused(refuse):
    refuse("evaluate-real", "run", "out", "--confidence", "1", "--out", "eval", mentions=("--confidence", "(0, 1)"))
    refuse("train", "out", "--imgsz", "100", "--out", "run", mentions=("--imgsz", "multiple of 32"))


def test_bad_map_is_one_line(refuse):
    refuse("evaluate-real", "run", "out", "--map", "wheelchair", "--out", "eval", mentions=("--map", "wheelchair"))


def test_limits_hold_their_defaults():
    assert L.MINUTES.contains(L.DEFAULT_MINUTES) and L.IMGSZ.contains(L.DEFAULT_IMGSZ)
    assert L.DEFAULT_IMGSZ % 32 == 0 and L.BATCH.contains(L.DEFAULT_BATCH)
    assert L.MIN_HEIGHT_PX.contains(L.DEFAULT_MIN_HEIGHT_PX) and L.CONFIDENCE.contains(L.DEFAULT_CONFIDENCE)


def test_a_convention_and_a_contradicting_option_are_refused(refuse):
    refuse("train", "out", "--convention", "wheelchair-sets", "--aid-users-as-person", "--out", "run",
           mentions=("--aid-users-as-person on", "--convention wheelchair-sets sets it off"))
    refuse("train", "out", "--convention", "coco", "--out", "run", mentions=("--convention",))
    refuse("evaluate-real", "run", "out", "--convention", "coco", "--out", "eval", mentions=("--convention",))
