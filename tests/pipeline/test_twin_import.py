"""Imported twins render through the existing path, with labels."""

import numpy as np
import pytest

from conftest import third_party
from reference_raycast import reference_labels
from synthua_usd.composition.scenario import LAYER_FILE, ROOT_FILE
from synthua_usd.pipeline.frame import FrameRequest, run_frames
from synthua_usd.pipeline.twin_import import REPORT_FILE


def import_and_render(run_cli, tmp_path, kind, source, camera="/World/Cameras/Overview", size=(96, 64)):
    out = tmp_path / "twin"
    code, stdout, err = run_cli("twin", "import", kind, source, "--out", out)
    assert code == 0, err
    run = run_frames(FrameRequest(stage_path=out / "scenario.usda", out_dir=tmp_path / "frame", camera_paths=(camera,),
                                  width=size[0], height=size[1], spp=2))
    return stdout, run.frames[0]


@pytest.mark.slow
def test_delft_import_renders_with_labels(run_cli, tmp_path):
    stdout, result = import_and_render(run_cli, tmp_path, "cityjson", third_party("cityjson", "delft.json"))
    assert "570 objects" in stdout
    counts = result.document["class_pixel_counts"]
    assert counts.get("building", 0) > 0 and counts.get("road", 0) > 0
    ref_class, _ = reference_labels(result.snapshot, result.camera, 96, 64)
    assert np.mean(ref_class == result.rendered.class_ids) >= 0.999


@pytest.mark.slow
def test_pointcloud_import_renders_with_labels(run_cli, tmp_path):
    stdout, result = import_and_render(run_cli, tmp_path, "pointcloud", third_party("las", "plane.laz"))
    assert "simplification deviation" in stdout
    counts = result.document["class_pixel_counts"]
    assert counts.get("road", 0) > 0.2 * 96 * 64


def test_import_report_is_written(run_cli, tmp_path):
    import json

    from conftest import DATA

    code, _, _ = run_cli("twin", "import", "cityjson", DATA / "valid" / "lod2_house.city.json", "--out", tmp_path)
    assert code == 0
    layers = [LAYER_FILE[role] for role in ("render", "environment", "cameras", "semantics", "twin")]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(layers + [ROOT_FILE, REPORT_FILE])
    report = json.loads((tmp_path / REPORT_FILE).read_text())
    assert report["classes"] == {"building": 1, "door": 1, "road": 1, "unlabelled": 1}
    assert report["origin_offset_m"] == pytest.approx([676010.0, 7185999.0, 900.0])
    from pxr import Sdf

    layer = Sdf.Layer.FindOrOpen(str(tmp_path / "twin.usdc"))
    assert layer.customLayerData["synthua:crs"].endswith("EPSG/0/31982")
    assert list(layer.customLayerData["synthua:origin_offset_m"]) == pytest.approx([676010.0, 7185999.0, 900.0])


def test_import_bad_input_exit_2_nothing_written(run_cli, tmp_path):
    from conftest import DATA

    code, _, err = run_cli("twin", "import", "cityjson", DATA / "invalid" / "cityjson_no_crs.city.json", "--out",
                           tmp_path / "o")
    assert code == 2 and "metadata.referenceSystem is missing" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_cli_crs_serves_a_cityjson_without_one_and_unknown_units_are_refused(run_cli, tmp_path):
    import json

    from conftest import DATA

    doc = json.loads((DATA / "invalid" / "cityjson_no_crs.city.json").read_text())
    src = tmp_path / "nocrs.city.json"
    src.write_text(json.dumps(doc))
    code, _, err = run_cli("twin", "import", "cityjson", src, "--out", tmp_path / "a", "--crs", "EPSG:31982")
    assert code == 0, err
    report = json.loads((tmp_path / "a" / REPORT_FILE).read_text())
    assert report["crs"] == "EPSG:31982" and report["units"]["source"] == "--crs"
    code, _, err = run_cli("twin", "import", "cityjson", src, "--out", tmp_path / "b")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "cannot be determined (metadata.referenceSystem is missing); expected a CRS in the file, or --crs" in err
    code, _, err = run_cli("twin", "import", "footprints", src, "--out", tmp_path / "c", "--units", "m")
    assert code == 2 and "--units: given for a footprints import" in err


def test_cli_strict_exits_1_on_a_residual_finding(run_cli, tmp_path):
    from las_files import write_las

    rng = np.random.default_rng(9)
    g = np.column_stack([rng.uniform(0, 30, 3000), rng.uniform(0, 30, 3000), rng.normal(0, 0.2, 3000)]) + 500
    src = write_las(tmp_path / "rough.las", g)
    args = ("twin", "import", "pointcloud", src, "--plane-threshold-m", "1", "--max-residual-m", "0.1")
    code, stdout, err = run_cli(*args, "--out", tmp_path / "a")
    assert code == 0 and "warning: " in err and "(residual-bound)" in err and "p95" in stdout
    code, _, err = run_cli(*args, "--out", tmp_path / "b", "--strict")
    assert code == 1 and (tmp_path / "b" / REPORT_FILE).exists()


def test_import_and_populate_in_one_go(run_cli, tmp_path):
    import json

    from conftest import DATA
    from synthua_usd.usd.stage_io import open_stage

    src = DATA / "valid" / "lod2_house.city.json"
    code, _, err = run_cli("twin", "import", "cityjson", src, "--out", tmp_path / "a", "--density", "0.1")
    assert code == 2 and "--density: given without --populate" in err
    code, stdout, err = run_cli("twin", "import", "cityjson", src, "--out", tmp_path / "b", "--populate",
                                "--density", "0.05", "--aid-share", "1", "--frames", "6")
    assert code in (0, 1), err
    report = json.loads((tmp_path / "b" / REPORT_FILE).read_text())
    people = report["population"]
    assert people["placed"] >= 1 and people["aid_users"] == people["placed"]
    assert people["walkable_area_m2"] == pytest.approx(134, abs=2)  # the 20 x 7 m road less its 2 x 3 m hole
    stage = open_stage(tmp_path / "b" / "scenario.usda")
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (1, 6)
    agents = [p for p in stage.Traverse() if str(p.GetPath()).startswith("/World/Agents/Agent_")
              and p.GetParent().GetPath().pathString == "/World/Agents"]
    assert len(agents) == people["placed"]
