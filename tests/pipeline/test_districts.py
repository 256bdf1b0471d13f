"""Randomised scenes over several district seeds: each district is written into the dataset once as a
self-contained scenario (the same twin bytes as `synthua create district --seed`), and a dataset whose seeds
draw two districts renders each image in its own, verifies and replays byte for byte."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from conftest import DISTRICT, generate_dataset
from synthua_usd.core.errors import InputError
from synthua_usd.pipeline.districts import check_district_scenario, district_of, write_district_scene
from synthua_usd.pipeline.verify import verify
from synthua_usd.randomisation.config import DistrictRandomisation, RandomisationConfig
from synthua_usd.usd.stage_io import open_stage


def test_a_district_is_written_as_a_self_contained_scenario(class_map, tmp_path):
    scene = write_district_scene(DISTRICT / "scenario.usda", 5, tmp_path / "d5", class_map)
    folder = scene.parent
    assert sorted(p.name for p in folder.iterdir() if p.is_file()) == [
        "cameras.usda", "environment.usda", "render.usda", "rigs.usda", "scenario.usda", "semantics.usda", "twin.usdc"]
    for name in ("cameras.usda", "environment.usda", "render.usda", "rigs.usda"):
        assert (folder / name).read_bytes() == (DISTRICT / name).read_bytes()
    stage = open_stage(scene)  # composes inside its own folder
    twin = stage.GetRootLayer().subLayerPaths
    assert "./agents.usdc" not in twin
    from pxr import Sdf

    assert Sdf.Layer.FindOrOpen(str(folder / "twin.usdc")).customLayerData["synthua:source"].endswith("(seed 5)")
    again = write_district_scene(DISTRICT / "scenario.usda", 5, tmp_path / "again", class_map)
    for path in sorted(folder.rglob("*")):
        if path.is_file():
            assert path.read_bytes() == (again.parent / path.relative_to(folder)).read_bytes(), path.name


def test_only_demo_districts_take_district_seeds(tmp_path):
    from conftest import SCENARIO

    with pytest.raises(InputError, match="synthua create district"):
        check_district_scenario(SCENARIO)  # the demo street's twin is no district


@pytest.mark.slow
def test_a_dataset_over_two_districts(tmp_path):
    config = RandomisationConfig(district=DistrictRandomisation(enabled=True, seeds=(0, 5)))
    seeds = [s for s in range(40) if district_of(config, s) == 0][:1] + [s for s in range(40)
                                                                         if district_of(config, s) == 5][:1]
    doc = {"name": "districts", "images": 2, "render": {"width": 64, "height": 48, "spp": 2, "max_depth": 3,
                                                        "denoise": False},
           "cameras": ["/World/Cameras/CCTV_Largo"], "time_codes": [24], "conditions": ["clear_day"], "seeds": seeds,
           "split": {"train": 1.0, "val": 0.0, "test": 0.0},
           "randomise": {"district": {"enabled": True, "seeds": [0, 5]}}, "workers": 1}
    path = tmp_path / "gen.json"
    path.write_text(json.dumps(doc))
    out = tmp_path / "ds"
    generate_dataset(out, config=path, scenario=DISTRICT / "scenario.usda")
    assert verify(out).ok
    recs = [json.loads(p.read_text()) for p in sorted((out / "records").glob("*.json"))]
    assert sorted(r["randomisation"]["district_seed"] for r in recs) == [0, 5]
    assert sorted(p.name for p in (out / "scenes").iterdir()) == ["district_0", "district_5"]
    manifest = json.loads((out / "manifest.json").read_text())
    listed = {f["path"] for f in manifest["dataset_files"]}
    assert "scenes/district_5/twin.usdc" in listed
    from synthua_usd.pipeline.verify import replay

    # replay of the image in the district the generator made (district 0's takes the same path: about 20 s more)
    record = next(r for r in recs if r["randomisation"]["district_seed"] == 5)
    result = replay(out, str(record["id"]))
    assert result.ok and result.identical, result
    # synthua randomise of a district image writes its layers over that district's copy in the dataset (that
    # rendering such layers gives the image's bytes: test_generate_randomised, on the street)
    from synthua_usd.pipeline.randomiser import RandomiseRequest, randomise_image

    result = randomise_image(RandomiseRequest(scenario=DISTRICT / "scenario.usda", out=tmp_path / "r" / "layer.usda",
                                              record_path=out / "records" / f"{record['name']}.json"))
    scenario = Path(result.render_args[2])
    assert scenario == out / "scenes" / "district_5" / "scenario.usda"
    assert result.render_args[result.render_args.index("--layer") + 1] == str(tmp_path / "r" / "layer.usda")
    # the districts differ: their twins' houses are other widths and colours
    assert (out / "scenes/district_0/twin.usdc").read_bytes() != (out / "scenes/district_5/twin.usdc").read_bytes()
    shutil.rmtree(out)
