"""``synthua generate`` with ``randomise.settings`` and ``randomise.distractors`` on (tests/data/configs/settings.json:
the demo street, three seeds: a street with a bus's ramp down, a shop, the street itself): each drawn setting is
written once into the dataset and listed in its manifest, every image is rendered in its seed's scenario with its
setting and distractors recorded, its labels are exact against an independent Embree ray cast, the dataset
verifies, replay is byte-identical, ``synthua randomise --record`` + ``synthua render`` give the image's bytes, and a
config that leaves the parts off keeps its document (and with it its job key and its bytes)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import DATA, RANDOM_CONFIG, SCENARIO, built_once, generate_dataset
from dataset_runs import records
from hostile import run_synthua
from reference_raycast import reference_labels
from synthua_usd.core.images import read_image
from synthua_usd.dataset.config import GenerationConfig
from synthua_usd.pipeline.scenes import SceneKey, scene_of
from synthua_usd.pipeline.verify import replay, verify
from synthua_usd.randomisation.settings import CAMERA_CLEARANCE_M

CONFIG = DATA / "configs" / "settings.json"


@pytest.fixture(scope="module")
def generated_settings(tmp_path_factory) -> Path:
    return built_once(tmp_path_factory, "settings", lambda out: generate_dataset(out, config=CONFIG))


def test_each_setting_is_written_once_and_every_image_records_its_scene(generated_settings):
    out = generated_settings
    assert verify(out).ok
    randomise = GenerationConfig.load(CONFIG).randomise
    keys = {seed: scene_of(randomise, seed) for seed in (0, 4, 5)}
    assert keys == {0: SceneKey("shop", 0), 4: SceneKey("vehicle_ramp", 0), 5: None}  # the scenes the seeds draw
    assert sorted(p.name for p in (out / "scenes").iterdir()) == ["shop_0", "vehicle_ramp_0"]
    listed = {f["path"] for f in json.loads((out / "manifest.json").read_text())["dataset_files"]}
    assert {"scenes/shop_0/twin.usdc", "scenes/vehicle_ramp_0/cameras.usda", "scenes/shop_0/scenario.usda"} <= listed
    for record in records(out):
        drawn = record["randomisation"]
        key = keys[record["seed"]]
        assert drawn["setting"] == (None if key is None else {"kind": key.kind, "variant": key.number,
                                                              "indoor": key.kind == "shop"})
        items = drawn["distractors"]["items"]
        assert items and all(item["label"] != "person" for item in items)
        mine = [i for i in record["instances"] if "/Distractors/" in i["prim_path"]]
        assert all(i["class_name"] not in ("person",) for i in mine)
        people = [i for i in record["instances"] if i["class_name"] == "person"]
        assert all("/World/Randomisation/Crowd/" in i["prim_path"] for i in people)
        if key is not None:  # in a setting, nobody placed free stands at the lens
            eye = np.array(drawn["view"]["camera"]["camera_to_world"])[:2, 3]
            for place in drawn["view"]["placements"]:
                if place["in_view"]:
                    assert np.hypot(*(np.array(place["position"][:2]) - eye)) >= CAMERA_CLEARANCE_M


def test_labels_in_the_settings_are_exact(generated_settings, class_map):
    """Each image's written class and instance maps against Embree's first hits in the image's scene, composed
    again from the dataset's own scenario of it with the recorded randomisation."""
    from synthua_usd.pipeline.randomiser import Randomiser
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    config = GenerationConfig.load(CONFIG)
    for record in records(generated_settings):
        key = scene_of(config.randomise, record["seed"])
        scenario = SCENARIO if key is None else generated_settings / key.folder / "scenario.usda"
        stage = open_stage(scenario, allow_external_assets=True)
        randomiser = Randomiser(stage, config.randomise, class_map, (record["width"], record["height"]))
        drawn = randomiser.apply(record["seed"], record["camera"]["prim_path"], record["time_code"],
                                 record["condition"]["name"], key)
        assert json.loads(json.dumps(drawn.to_dict())) == record["randomisation"]
        snapshot = StageReader(stage, class_map).snapshot(record["time_code"])
        camera = read_camera(stage, record["camera"]["prim_path"], record["time_code"])
        ref_class, ref_inst = reference_labels(snapshot, camera, record["width"], record["height"])
        files = record["files"]
        assert np.array_equal(read_image(generated_settings / files["class"])[0][..., 0], ref_class)
        assert np.array_equal(read_image(generated_settings / files["instance"])[0][..., 0], ref_inst)
        randomiser.close()


def test_replay_and_randomise_give_a_setting_images_bytes(generated_settings, tmp_path):
    record = next(r for r in records(generated_settings) if r["randomisation"]["setting"] is not None
                  and r["randomisation"]["setting"]["indoor"])
    result = replay(generated_settings, str(record["id"]))
    assert result.ok and result.identical, result
    done = run_synthua("randomise", SCENARIO, "--record", generated_settings / "records" / f"{record['name']}.json",
                       "--out", tmp_path / "layer.usda")
    assert done.code == 0, done.stderr
    args = done.stdout.split("render it with: ", 1)[1].split()[1:]
    assert args[1] == str(generated_settings / "scenes" / "shop_0" / "scenario.usda")
    args[args.index("--out") + 1] = str(tmp_path / "frame")
    rendered = run_synthua(*args)
    assert rendered.code == 0, rendered.stderr
    for ours, theirs in (("rgb.png", "rgb_png"), ("class.png", "class"), ("instance.png", "instance")):
        assert (tmp_path / "frame" / ours).read_bytes() == (generated_settings / record["files"][theirs]).read_bytes()


def test_the_parts_off_leave_a_configs_document_as_it_was():
    """A config that does not ask for settings or distractors (random.json), or asks for them off, keeps the
    document it had before they existed, so its generate.json, job key and files are those it had."""
    plain = GenerationConfig.load(RANDOM_CONFIG)
    document = json.loads(RANDOM_CONFIG.read_text())
    document["randomise"] |= {"settings": {"enabled": False}, "distractors": {"enabled": False}}
    off = GenerationConfig.from_document(document)
    assert off.to_document() == plain.to_document()
    assert {"settings", "distractors"}.isdisjoint(plain.to_document()["randomise"])
