"""Stage summaries (`synthua inspect`): what a stage holds, for people without usdview."""

from pathlib import Path

import pytest

from conftest import DATA, SCENARIO
from synthua_usd.usd.stage_io import open_stage
from synthua_usd.usd.summary import summarize


def test_inspect_lists_layers_classes_cameras_lights(run_cli):
    code, out, _ = run_cli("inspect", SCENARIO)
    assert code == 0
    for text in ("twin.usdc", "semantics.usda", "agents.usdc", "manual_wheelchair:1", "person:2", "window:16",
                 "/World/Cameras/CCTV  f=2.8 mm", "DistantLight", "DomeLight", "1..48 at 24 time codes/s"):
        assert text in out, text


def test_inspect_missing_stage_exit_2(run_cli, tmp_path):
    code, _, err = run_cli("inspect", tmp_path / "none.usda")
    assert code == 2 and err.strip().endswith("none.usda: file not found")


def test_summary_of_the_tiny_scene(class_map):
    summary = summarize(open_stage(DATA / "valid" / "tiny_scene.usda"), class_map)
    assert [Path(p).name for p in summary.layers] == ["tiny_scene.usda"]
    assert (summary.up_axis, summary.meters_per_unit, summary.time_range) == ("Z", 1.0, (1.0, 2.0))
    assert summary.classes == {"road": 1, "Pedestrian": 1} and summary.unlabelled_gprims == 0
    assert summary.gprim_count == 2 and summary.triangle_estimate == 2  # the Cube is not a Mesh: not counted
    (cam,) = summary.cameras
    assert cam["path"] == "/World/Cam"
    assert (cam["focal_length_mm"], cam["horizontal_aperture_mm"]) == pytest.approx((20.0, 36.0))  # float lens values
    assert summary.lights == [{"path": "/World/Sky", "type": "DomeLight", "intensity": 1.0}]
