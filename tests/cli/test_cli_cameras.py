"""`synthua cameras`: a small run end to end, exit status 1 for rejected cameras, and bad input refused in
one line with exit status 2 (unknown rig types, heights out of range, a scenario without roads for a
dashcam, distortion without an inverse, ...), leaving earlier outputs as they were."""

import json

import pytest

from conftest import DATA, SCENARIO
from hostile import assert_refused, run_synthua, tree_state

TINY = DATA / "valid" / "tiny_scene.usda"
NO_ROADS = DATA / "invalid" / "no_roads.usda"


def test_types_and_help_teach_the_rigs(run_cli):
    code, out, _ = run_cli("cameras", "types")
    assert code == 0
    for name in ("cctv", "dashcam", "uav_nadir", "uav_oblique", "pedestrian_eye", "wheelchair_eye"):
        assert name in out
    code, out, _ = run_cli("cameras", "author", "--help")
    assert code == 0 and "--min-target-px" in out and "Examples:" in out and "ride=auto" in out


def test_author_writes_the_layer_and_the_report(run_cli, tmp_path):
    out = tmp_path / "cams.usda"
    code, stdout, _ = run_cli("cameras", "author", SCENARIO, "--rig", "uav_nadir:height_m=30,aim=crossing",
                              "--rig", "dashcam", "--out", out, "--width", "64", "--height", "48", "--time-code", "1,48")
    assert code == 0, stdout
    report = json.loads((tmp_path / "cams.report.json").read_text())
    assert [c["name"] for c in report["cameras"]] == ["UAVNadir_Crossing_1", "Dashcam_1"]
    assert "UAVNadir_Crossing_1" in stdout and "written (on road)" in stdout
    assert f"wrote {out} (2 cameras) and {tmp_path / 'cams.report.json'}" in stdout


def test_cameras_that_miss_the_minimum_exit_1_and_stay_out_of_the_layer(run_cli, tmp_path):
    out = tmp_path / "cams.usda"
    code, stdout, err = run_cli("cameras", "author", SCENARIO, "--rig", "cctv", "--out", out, "--width", "64",
                                "--height", "48", "--time-code", "24", "--min-target-px", "5000")
    assert code == 1 and "rejected" in stdout and "fewer than 5000 visible pixels" in err
    assert "def Camera" not in out.read_text()


@pytest.mark.parametrize("args, mentions", [
    (["--rig", "tripod"], ["rig type 'tripod' is unknown", "expected one of cctv, dashcam"]),
    (["--rig", "cctv:height_m=9"], ["height_m = 9.0", "expected 3-8 m"]),
    (["--rig", "uav_nadir:height_m=10"], ["height_m = 10.0", "expected 20-120 m"]),
    (["--rig", "wheelchair_eye:height_m=1.6"], ["height_m = 1.6", "expected 1.05-1.35 m"]),
    (["--rig", "cctv:k1=-0.9"], ["rig 1 (cctv)", "has no inverse"]),
    (["--rig", "cctv:aim=/World/Nothing"], ["aim = /World/Nothing", "no agent or labelled prim"]),
    (["--rig", "wheelchair_eye:ride=/World/Agents/Agent_0000"], ["is a pedestrian", "seated (wheelchair) agent"]),
    (["--rig", "cctv", "--time-code", "99"], ["time code 99 is outside the stage's time range"]),
])
def test_bad_rigs_are_refused_in_one_line(run_cli, tmp_path, args, mentions):
    code, out, err = run_cli("cameras", "author", SCENARIO, "--out", tmp_path / "c.usda", "--width", "64",
                             "--height", "48", *args)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("synthua: error: "), err
    for text in mentions:
        assert text in lines[0]
    assert not (tmp_path / "c.usda").exists() and not (tmp_path / "c.report.json").exists()


@pytest.mark.parametrize("stage, rig, mentions", [
    (NO_ROADS, "dashcam", ["no_roads.usda: has no road surfaces", "expected a twin with roads"]),
    (TINY, "cctv", ["the scenario has no agents with mobility aids to aim at"]),
    (TINY, "wheelchair_eye:ride=auto,aim=none", ["no wheelchair users to ride with"]),
])
def test_scenarios_that_lack_what_a_rig_needs_are_refused(run_cli, tmp_path, stage, rig, mentions):
    code, _, err = run_cli("cameras", "author", stage, "--rig", rig, "--out", tmp_path / "c.usda",
                           "--width", "64", "--height", "48")
    assert code == 2 and len(err.strip().splitlines()) == 1
    for text in mentions:
        assert text in err


def test_refusals_from_a_real_process_leave_earlier_outputs_alone(tmp_path):
    """As the hostile suite runs commands: a subprocess, no traceback, one line, the folder untouched."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "cams.usda").write_text("#usda 1.0\n")
    before = tree_state(tmp_path)
    for stage, rig, mention in ((NO_ROADS, "dashcam", "has no road surfaces"),
                                (SCENARIO, "dashcam:height_m=3", "height_m = 3.0"),
                                (SCENARIO, "cctv:k1=-0.9", "has no inverse")):
        result = run_synthua("cameras", "author", stage, "--rig", rig, "--out", out / "cams.usda")
        assert_refused(result, mention)
        assert tree_state(tmp_path) == before
    result = run_synthua("cameras", "author", SCENARIO, "--rig", "cctv", "--out", out / "cams.txt")
    assert_refused(result, "cams.txt", "needs a USD file name")
