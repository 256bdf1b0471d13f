"""An output that is one of the command's own inputs: every command that writes refuses it with one line naming the
output (``synthua_usd.core.input_guard``, one check for all), before it replaces anything; the inputs stay byte for
byte as they were."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from conftest import DATA, RANDOM_CONFIG, STAGES, TINY_CONFIG
from importers.hostile_corpus import CLASSMAP, GEOJSON

TINY = DATA / "valid" / "tiny_scene.usda"
MESSAGE = "none of the command's inputs"


def _street(folder: Path) -> Path:
    """The demo street's layers copied into ``folder``; its scenario."""
    folder.mkdir()
    for layer in STAGES.iterdir():
        if layer.is_file():
            shutil.copy(layer, folder / layer.name)
    return folder / "scenario.usda"


def _run(folder: Path) -> Path:
    """A run folder of `synthua train` (its weights a stand-in: the refusal comes before anything reads them)."""
    folder.mkdir()
    (folder / "weights.pt").write_bytes(b"weights")
    (folder / "train.json").write_text(json.dumps({"classes": ["person"], "budget": {"imgsz": 320}, "targets": None}))
    return folder


def test_randomise_into_its_own_scenario(refuse, workdir):
    """The issue's case: exit 0 and the scenario overwritten by the randomisation layer."""
    scenario = _street(workdir / "street")
    refuse("randomise", scenario, "--config", RANDOM_CONFIG, "--allow-external-assets", "--out", scenario,
           mentions=(str(scenario), "is the input SCENARIO itself", MESSAGE))


def test_randomise_into_its_scenario_by_another_name(refuse, workdir):
    scenario = _street(workdir / "street")
    os.link(scenario, workdir / "street" / "linked.usda")
    refuse("randomise", scenario, "--config", RANDOM_CONFIG, "--out", workdir / "street" / "linked.usda",
           mentions=("linked.usda", "SCENARIO", MESSAGE))


def test_render_over_its_class_map(refuse, workdir):
    """frame.json of the render is the class map it reads."""
    (workdir / "frame").mkdir()
    shutil.copy(CLASSMAP, workdir / "frame" / "frame.json")
    refuse("render", TINY, "--camera", "/World/Cam", "--width", "8", "--height", "6", "--spp", "1",
           "--class-map", workdir / "frame" / "frame.json", "--out", workdir / "frame",
           mentions=("frame.json", "--class-map", MESSAGE))


def test_cameras_author_report_over_its_class_map(refuse, workdir):
    """The report beside the layer (``rigs.report.json``) is the class map it reads."""
    shutil.copy(CLASSMAP, workdir / "rigs.report.json")
    scenario = _street(workdir / "street")
    refuse("cameras", "author", scenario, "--rig", "cctv:aim=aid_user", "--class-map", workdir / "rigs.report.json",
           "--out", workdir / "rigs.usda", mentions=("rigs.report.json", "--class-map", MESSAGE))


def test_cameras_author_over_a_layer_it_composes(refuse, workdir):
    scenario = _street(workdir / "street")
    refuse("cameras", "author", scenario, "--rig", "cctv:aim=aid_user", "--layer", workdir / "street" / "agents.usdc",
           "--out", workdir / "street" / "agents.usdc", mentions=("agents.usdc", "--layer", MESSAGE))


def test_twin_import_over_its_input(refuse, workdir):
    """The footprints file is named like the import's report, in the output folder."""
    shutil.copy(GEOJSON, workdir / "out" / "import_report.json")
    refuse("twin", "import", "footprints", workdir / "out" / "import_report.json", "--out", workdir / "out",
           mentions=("import_report.json", "INPUT", MESSAGE))


def test_eval_over_its_predictions(refuse, workdir):
    """COCO results kept as out/coco.json, the name of the report's COCOeval numbers: refused before reading."""
    (workdir / "eval").mkdir()
    (workdir / "eval" / "coco.json").write_text("[]")
    refuse("eval", "--gt", workdir / "dataset", "--pred", workdir / "eval" / "coco.json", "--out", workdir / "eval",
           mentions=("coco.json", "--pred", MESSAGE))


def test_train_over_the_run_it_starts_from(refuse, workdir):
    """Fine-tuning into the run folder it starts from would replace its weights: refused before training."""
    run = _run(workdir / "run")
    refuse("train", workdir / "photos", "--init", run, "--epochs", "1", "--out", run,
           mentions=("weights.pt", "--init", MESSAGE))


def test_evaluate_real_over_its_test_set(refuse, workdir):
    """A COCO test set kept as metrics.json in the report's folder: refused before the detector runs."""
    run = _run(workdir / "run")
    (workdir / "report").mkdir()
    (workdir / "report" / "metrics.json").write_text(json.dumps({"images": [], "annotations": [], "categories": []}))
    refuse("evaluate-real", run, workdir / "report" / "metrics.json", "--out", workdir / "report",
           mentions=("metrics.json", "TEST_SET", MESSAGE))


def test_generate_into_a_folder_holding_its_scenario(refuse, workdir):
    """A dataset folder is generate's own (its district scenes go to scenes/): a scenario kept there is refused."""
    (workdir / "dataset" / "scenes").mkdir(parents=True)
    scenario = _street(workdir / "dataset" / "scenes" / "street")
    refuse("generate", scenario, "--config", TINY_CONFIG, "--out", workdir / "dataset",
           mentions=("scenario.usda", "SCENARIO", "dataset"))


@pytest.mark.parametrize("where", ["twin", "render"])
def test_an_output_beside_its_input_is_still_fine(run_cli, tmp_path, where):
    """Only a file the command would replace is refused: a mesh in the folder its import goes to, a scenario in the
    folder its render goes to."""
    if where == "twin":
        shutil.copy(GEOJSON, tmp_path / "blocks.geojson")
        code, _, err = run_cli("twin", "import", "footprints", tmp_path / "blocks.geojson", "--out", tmp_path)
    else:
        shutil.copy(TINY, tmp_path / "tiny.usda")
        code, _, err = run_cli("render", tmp_path / "tiny.usda", "--camera", "/World/Cam", "--width", "8", "--height",
                               "6", "--spp", "1", "--out", tmp_path)
    assert code == 0, err
