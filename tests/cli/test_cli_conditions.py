"""`synthua render --condition`, `synthua inspect` and `synthua contact-sheet` on tiny images."""

import json

import numpy as np
import pytest

from conftest import SCENARIO
from synthua_usd.backends.contact_sheet import GAP_PX, HEADER_PX, SIDE_PX, TITLE_PX
from synthua_usd.core.images import linear_to_display, read_image
from synthua_usd.core.schemas import validate_document

TINY = ("--width", "32", "--height", "24", "--spp", "2")


@pytest.fixture(scope="module")
def two_conditions(lamps_scenario, tmp_path_factory):
    from synthua_usd.cli.main import main

    out = {}
    for name in ("clear_day", "clear_night"):
        out[name] = tmp_path_factory.mktemp(name)
        assert main(["render", str(lamps_scenario), "--camera", "/World/Cam", *TINY, "--condition", name,
                     "--out", str(out[name])]) == 0
    return out


def test_frame_json_records_the_condition_and_the_exposure(two_conditions):
    for name, folder in two_conditions.items():
        doc = json.loads((folder / "frame.json").read_text())
        validate_document(doc, "frame", "frame.json")
        assert doc["condition"]["name"] == name
        assert doc["exposure"]["scale"] > 0 and "log-average" in doc["exposure"]["rule"]
        rgb, _ = read_image(folder / "rgb.exr")
        png, _ = read_image(folder / "rgb.png")
        assert np.array_equal(png, linear_to_display(rgb * np.float32(doc["exposure"]["scale"])))
    day, night = (json.loads((f / "frame.json").read_text()) for f in two_conditions.values())
    assert day["exposure"]["ev100"] > night["exposure"]["ev100"] + 8
    assert day["condition"]["fog_visibility_m"] is None  # no fog; JSON has no infinity


def test_labels_do_not_depend_on_the_condition(two_conditions):
    day, night = two_conditions.values()
    for name in ("class.png", "instance.png", "depth.exr"):
        assert np.array_equal(read_image(day / name)[0], read_image(night / name)[0])


def test_unknown_condition_is_one_line_listing_the_known_ones(run_cli, tmp_path):
    code, out, err = run_cli("render", SCENARIO, *TINY, "--condition", "hail", "--out", tmp_path / "o")
    assert code == 2 and out == ""
    assert err == (f"synthua: error: {SCENARIO}: no condition 'hail'; conditions in the stage: clear_day, day_fog, "
                   "day_rain_fog, clear_night, night_rain_fog, sunset, snow\n")
    assert not (tmp_path / "o").exists()


def test_inspect_lists_the_conditions(run_cli):
    code, out, _ = run_cli("inspect", SCENARIO)
    assert code == 0
    assert "conditions clear_day*  day_fog  day_rain_fog  clear_night  night_rain_fog  sunset  snow" in out


def test_contact_sheet_is_a_labelled_grid(run_cli, lamps_scenario, tmp_path):
    out = tmp_path / "sheet.png"
    code, text, _ = run_cli("contact-sheet", lamps_scenario, "--time-code", "1", "--width", "32", "--height", "24",
                            "--spp", "1", "--condition", "clear_day", "--condition", "clear_night", "--out", out)
    assert code == 0 and "1 cameras x 2 conditions (clear_day, clear_night)" in text
    sheet, spec = read_image(out)
    assert sheet.shape == (TITLE_PX + HEADER_PX + 24 + 2 * GAP_PX, SIDE_PX + 2 * (2 * 32 + 3 * GAP_PX), 3)
    assert sheet.dtype == np.uint8 and spec.get_string_attribute("oiio:ColorSpace") == "srgb_rec709_scene"
    assert sheet[:TITLE_PX].max() > 200  # the title is drawn


@pytest.mark.parametrize("args,message", [
    (("--condition", "hail"), "no condition 'hail'; conditions in the stage: clear_day"),
    (("--camera", "/World/Nope"), "no camera at '/World/Nope'"),
    (("--time-code", "99"), "time code 99 is outside the stage's time range [1, 2]"),
])
def test_contact_sheet_refuses_bad_input_in_one_line(run_cli, lamps_scenario, tmp_path, args, message):
    code, _, err = run_cli("contact-sheet", lamps_scenario, *args, "--out", tmp_path / "s.png")
    assert code == 2 and message in err and err.count("\n") == 1
    assert not (tmp_path / "s.png").exists()


def test_contact_sheet_wants_a_png(run_cli, lamps_scenario, tmp_path):
    code, _, err = run_cli("contact-sheet", lamps_scenario, "--out", tmp_path / "s.jpg")
    assert code == 2 and "the contact sheet is a PNG" in err
