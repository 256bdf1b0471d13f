"""``synthua agents populate``: a populated agents layer from a stage, deterministic per seed, refusing what
cannot be."""

import json
import re

import pytest

from conftest import DATA, MOBILITY_AIDS, SCENARIO, STAGES
from synthua_usd.agents.crowd import CrowdParams
from synthua_usd.composition.scenario import LAYER_FILE
from synthua_usd.core.errors import InputError
from synthua_usd.pipeline.populate import PopulateRequest, populate


def test_populate_is_deterministic_per_seed(run_cli, tmp_path):
    args = ("agents", "populate", SCENARIO, "--density", "0.05", "--time-codes", "12")
    assert run_cli(*args, "--seed", "4", "--out", tmp_path / "a.usda")[0] == 0
    assert run_cli(*args, "--seed", "4", "--out", tmp_path / "b.usda")[0] == 0
    assert run_cli(*args, "--seed", "5", "--out", tmp_path / "c.usda")[0] == 0
    a, b, c = ((tmp_path / n).read_bytes() for n in ("a.usda", "b.usda", "c.usda"))
    assert a == b and a != c


def test_populate_refuses_impossible_density_and_writes_nothing(run_cli, tmp_path):
    code, _, err = run_cli("agents", "populate", SCENARIO, "--density", "15", "--out", tmp_path / "a.usda")
    assert code == 2 and "physically impossible" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "a.usda").exists()


@pytest.mark.slow
def test_populated_layer_composes_renders_and_exports_person_device_pairs(run_cli, tmp_path):
    code, out, _ = run_cli("agents", "populate", SCENARIO, "--density", "0.2", "--aid-share", "1.0", "--time-codes", "24",
                           "--seed", "1", "--out", tmp_path / "crowd.usda")
    assert code == 0 and "with mobility aids" in out
    layers = [tmp_path / "crowd.usda"] + [STAGES / LAYER_FILE[role] for role in ("render", "environment", "cameras",
                                                                                "semantics", "twin")]
    assert run_cli("compose", tmp_path / "scene.usda", *layers, "--allow-external-assets")[0] == 0
    # The scenario lives in tmp_path and composes the repository's layers: external by design here.
    assert run_cli("validate", "stage", tmp_path / "scene.usda", "--allow-external-assets")[0] == 0
    code, _, err = run_cli("render", tmp_path / "scene.usda", "--allow-external-assets", "--camera",
                           "/World/Cameras/CCTV", "--time-code", "12",
                           "--width", "160", "--height", "120", "--spp", "1", "--out", tmp_path / "frame")
    assert code == 0, err
    doc = json.loads((tmp_path / "frame" / "frame.json").read_text())
    by_path = {i["prim_path"]: i for i in doc["instances"]}
    pairs = [(i, by_path[i["relations"]["uses"]]) for i in doc["instances"]
             if i["prim_path"].startswith("/World/Agents/Agent_") and "relations" in i]
    assert pairs
    for person, device in pairs:
        assert person["class_name"] == "person" and device["class_name"] in MOBILITY_AIDS
        assert person["id"] != device["id"]
    assert any(p["pixel_count"] and d["pixel_count"] for p, d in pairs)


def test_walk_on_roads_for_twins_without_sidewalks(run_cli, tmp_path):
    assert run_cli("twin", "import", "cityjson", DATA / "valid" / "lod2_house.city.json", "--out", tmp_path)[0] == 0
    code, _, err = run_cli("agents", "populate", tmp_path / "scenario.usda", "--out", tmp_path / "a.usda")
    assert code == 2 and "add --walk-on road" in err and not (tmp_path / "a.usda").exists()
    code, out, err = run_cli("agents", "populate", tmp_path / "scenario.usda", "--walk-on", "sidewalk,road",
                             "--density", "0.05", "--frames", "6", "--out", tmp_path / "a.usda")
    assert code == 0, err
    assert "walkable area 134 m²" in out  # 20 x 7 m road less its 2 x 3 m hole
    code, _, err = run_cli("agents", "populate", tmp_path / "scenario.usda", "--walk-on", "lava",
                           "--out", tmp_path / "b.usda")
    assert code == 2 and "walkable classes ['lava'] are not classes" in err



def test_populate_returns_the_crowd_and_writes_a_binary_layer(tmp_path):
    params = CrowdParams(density_per_m2=0.05, time_codes=6, seed=2)
    crowd, path, seconds = populate(PopulateRequest(SCENARIO, tmp_path / "agents.usdc", params))
    assert path == tmp_path / "agents.usdc" and path.read_bytes().startswith(b"PXR-USDC") and seconds > 0
    assert crowd.report["placed"] == len(crowd.trajectories) > 0
    assert crowd.report["min_separation_m"] >= 0.1 - 1e-9
    assert crowd.params.time_codes_per_second == 24.0  # taken from the stage


@pytest.mark.parametrize("out,text", [
    ("agents.txt", "the agents layer needs a USD file name (.usda text, .usdc binary or .usd)"),
    (SCENARIO, "is the input TWIN_OR_SCENARIO itself"),
])
def test_populate_refuses_bad_output_paths(tmp_path, out, text):
    before = SCENARIO.read_bytes()
    with pytest.raises(InputError, match=re.escape(text)):
        populate(PopulateRequest(SCENARIO, tmp_path / out))
    assert list(tmp_path.iterdir()) == [] and SCENARIO.read_bytes() == before


def test_a_twin_opened_without_its_semantics_is_said_to_be_unlabelled(run_cli, tmp_path):
    """The demo's twin.usdc alone: every gprim is class 0. The message names that cause and the scenario beside
    it, not --walk-on."""
    code, _, err = run_cli("agents", "populate", STAGES / "twin.usdc", "--out", tmp_path / "a.usdc")
    assert code == 2 and err.count("synthua: error:") == 1, err
    line = err.strip().splitlines()[-1]
    assert "none of its gprims has a 'synthua' label" in line and str(STAGES / "scenario.usda") in line and "--walk-on" not in line
    assert not (tmp_path / "a.usdc").exists()


def test_a_stage_without_the_walkable_classes_lists_the_classes_it_has(run_cli, tmp_path):
    code, _, err = run_cli("agents", "populate", SCENARIO, "--walk-on", "tent", "--out", tmp_path / "a.usdc")
    line = err.strip().splitlines()[-1]
    assert code == 2 and "none of the walkable classes (tent)" in line and "sidewalk" in line and "--walk-on" in line
