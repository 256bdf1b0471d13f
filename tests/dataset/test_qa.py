"""QA measures on synthetic images (hand-computed values) and verdicts with their reasons."""

import numpy as np
import pytest

from synthua_usd.dataset.config import QAThresholds
from synthua_usd.dataset.qa import UNKNOWN_AID, aid_users, clipped_shares, laplacian_variance, measure, verdict


def checkerboard(h=24, w=32) -> np.ndarray:
    """1-pixel black/white checkerboard, (h, w, 3) uint8."""
    board = ((np.indices((h, w)).sum(axis=0) % 2) * 255).astype(np.uint8)
    return np.repeat(board[:, :, None], 3, axis=2)


def box_blur(rgb: np.ndarray) -> np.ndarray:
    """3 x 3 mean (interior), rounded to uint8."""
    f = rgb.astype(np.float64)
    h, w = f.shape[:2]
    out = sum(f[dy:h - 2 + dy, dx:w - 2 + dx] for dy in range(3) for dx in range(3)) / 9.0
    return np.rint(out).astype(np.uint8)


def test_laplacian_variance_of_a_checkerboard_and_its_blur():
    # Every interior pixel of the 1-px board has four opposite neighbours: Laplacian = +-4 x 255 = +-1020,
    # half each sign, so the variance is 1020^2.
    assert laplacian_variance(checkerboard()) == pytest.approx(1020.0 ** 2)
    # The 3 x 3 mean alternates round(5/9 x 255) = 142 and round(4/9 x 255) = 113: Laplacian +-4 x 29 = +-116.
    assert laplacian_variance(box_blur(checkerboard())) == pytest.approx(116.0 ** 2)
    assert laplacian_variance(np.full((8, 8, 3), 77, np.uint8)) == 0.0
    assert laplacian_variance(np.zeros((2, 9, 3), np.uint8)) == 0.0


def test_clipped_shares():
    assert clipped_shares(np.zeros((4, 5, 3), np.uint8)) == (1.0, 0.0)
    assert clipped_shares(np.full((4, 5, 3), 255, np.uint8)) == (0.0, 1.0)
    mixed = np.zeros((2, 2, 3), np.uint8)
    mixed[0, 0] = (255, 0, 0)      # saturated red: neither
    mixed[0, 1] = 255              # white
    mixed[1, 0] = (0, 0, 1)        # not quite black
    assert clipped_shares(mixed) == (0.25, 0.25)
    with pytest.raises(ValueError):
        clipped_shares(np.zeros((2, 2, 3), np.float32))


def inst(prim, cls, area, amodal=None, occlusion=None, uses=None):
    out = {"prim_path": prim, "class_name": cls, "area": area, "relations": {"uses": uses} if uses else {}}
    if amodal is not None:
        out["amodal_area"] = amodal
        out["occlusion"] = 1 - area / amodal
    if occlusion is not None:
        out["occlusion"] = occlusion
    return out


INSTANCES = [
    inst("/W/P1", "person", 30, amodal=50, uses="/W/D1"),
    inst("/W/D1", "walker", 10, amodal=30),
    inst("/W/P2", "person", 80, occlusion=0.3, uses="/W/D2"),   # device /W/D2 shows no pixel
    inst("/W/P3", "person", 500, amodal=500),                   # no device: not an aid user
    inst("/W/Car", "car", 900, amodal=1000),
]


def test_aid_users_pair_person_and_device():
    users = aid_users(INSTANCES)
    assert [(u.person_prim, u.aid_type, u.visible_pixels) for u in users] == [("/W/P1", "walker", 40),
                                                                              ("/W/P2", UNKNOWN_AID, 80)]
    assert users[0].occlusion == pytest.approx(1 - 40 / 80)   # pair: (30 + 10) / (50 + 30)
    assert users[1].occlusion == 0.3                          # the person's own, the device unseen


def test_measures_and_verdicts():
    black = np.zeros((6, 8, 3), np.uint8)
    m = measure(black, INSTANCES)
    assert m == {"blur_laplacian_var": 0.0, "shadows_clipped": 1.0, "highlights_clipped": 0.0, "aid_users": 2.0,
                 "aid_min_pixels": 40.0, "aid_max_occlusion": pytest.approx(0.5)}
    thresholds = QAThresholds(blur_min=50.0, shadows_clipped_max=0.5, highlights_clipped_max=0.25,
                              aid_min_pixels=100, aid_max_occlusion=0.4, reject=("shadows",))
    assert verdict(m, thresholds) == ("rejected", [
        "blur: laplacian variance 0.0 < 50", "shadows: 100.0 % of pixels at 0 > 50 %",
        "aid_size: smallest aid user 40 px < 100", "aid_occlusion: most occluded aid user 0.50 > 0.4"])
    flag_only = QAThresholds(blur_min=50.0, shadows_clipped_max=None, aid_min_pixels=None, aid_max_occlusion=None)
    assert verdict(m, flag_only) == ("flagged", ["blur: laplacian variance 0.0 < 50"])
    sharp = measure(checkerboard() // 2 + 60, [])   # 60 / 187: sharp, nothing clipped
    assert "aid_min_pixels" not in sharp and sharp["aid_users"] == 0.0
    assert verdict(sharp, thresholds) == ("accepted", [])
    white = measure(np.full((6, 8, 3), 255, np.uint8), [])
    assert verdict(white, QAThresholds(blur_min=None, reject=("highlights",))) == (
        "rejected", ["highlights: 100.0 % of pixels at 255 > 25 %"])
