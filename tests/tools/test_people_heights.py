"""tools/people_heights.py: people on foot and seated wheelchair users of known heights, projected by a level pinhole
camera into YOLO photos, give back the seated height and horizons that agree; bad input is one line."""

import numpy as np
import pytest
from PIL import Image

from conftest import load_tool

W, H, F, CAMERA_M, HORIZON = 200, 160, 150.0, 1.4, 60.0


def _rows(height_m: float, distance_m: float) -> tuple[float, float]:
    """Top and bottom rows of someone ``height_m`` tall standing ``distance_m`` in front of the level camera."""
    return HORIZON - F * (height_m - CAMERA_M) / distance_m, HORIZON + F * CAMERA_M / distance_m


@pytest.fixture(scope="module")
def tool():
    return load_tool("people_heights.py", "people_heights")


def _photos(root, seated_m: float):
    (root / "images" / "train").mkdir(parents=True)
    (root / "labels" / "train").mkdir(parents=True)
    scenes = {"a": [(0, 1.7, 4.0), (1, seated_m, 5.0)], "b": [(0, 1.7, 6.0), (0, 1.7, 3.0), (1, seated_m, 3.5)],
              "c": [(1, seated_m, 4.0)],                                   # no person: left out
              "d": [(0, 1.7, 1.2), (1, seated_m, 4.0)]}                    # the person's feet below the photo
    for stem, people in scenes.items():
        Image.fromarray(np.zeros((H, W, 3), np.uint8)).save(root / "images" / "train" / f"{stem}.png")
        lines = []
        for k, (label, height_m, distance) in enumerate(people):
            top, bottom = (min(max(row, 0.0), H) for row in _rows(height_m, distance))    # the photo cuts it
            lines.append(f"{label} {(20 + 40 * k) / W} {(top + bottom) / 2 / H} {20 / W} {(bottom - top) / H}")
        (root / "labels" / "train" / f"{stem}.txt").write_text("\n".join(lines) + "\n")
    (root / "data.yaml").write_text(f"path: {root}\ntrain: images/train\nnames:\n  0: person\n  1: wheelchair\n")
    return root


def test_the_seated_height_and_the_horizons_come_back(tool, tmp_path, capsys):
    photos = _photos(tmp_path / "set", 1.3)
    assert tool.main([str(photos), "--camera-height", str(CAMERA_M), "--wheelchair-height", "1.3"]) == 0
    said = capsys.readouterr().out
    assert "2 photos hold both whole; their 2 wheelchair boxes are 1.300 m tall (quartiles 1.300 and 1.300)" in said
    assert "lies +0.0 % of the photo's height" in said
    photos_n, heights, gaps = tool.measure(photos, "all", "person", "wheelchair", 1.7, 1.35, CAMERA_M)
    # a wheelchair height stated too large puts the seated users' horizon above the people's, by p H (1/1.3 - 1/1.35)
    top, bottom = _rows(1.3, 5.0)
    assert photos_n == 2 and heights == pytest.approx([1.3, 1.3])
    assert gaps[0] == pytest.approx((bottom - top) * CAMERA_M * (1 / 1.3 - 1 / 1.35) / H)


def test_bad_input_is_one_line(tool, tmp_path, capsys):
    photos = _photos(tmp_path / "set", 1.3)
    assert tool.main([str(photos), "--wheelchair", "chair"]) == 2
    assert capsys.readouterr().err.strip() == (f"synthua: error: {photos}: no class 'chair'; expected one of person, "
                                               f"wheelchair")
    assert tool.main([str(photos), "--camera-height", "0"]) == 2
    assert "--camera-height: 0.0; expected metres in [0.1, 100]" in capsys.readouterr().err
