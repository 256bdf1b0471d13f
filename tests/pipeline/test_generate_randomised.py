"""``synthua generate`` with scene randomisation on (tests/data/configs/random.json, the demo street): every
image's choices recorded, images of one camera and time code but other seeds are other scenes (class maps,
looks and RGB differ beyond noise), replay, resumption after kill -9 and `synthua randomise` + `synthua render
--layer` give the dataset's bytes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import DATA, RANDOM_CONFIG, SCENARIO, generate_dataset
from hostile import assert_refused, run_synthua
from synthua_usd.core.images import read_image
from synthua_usd.pipeline.verify import verify
from dataset_runs import kill_when, records, tree_bytes

def _files(dataset: Path, record: dict) -> dict[str, Path]:
    return {k: dataset / v["path"] for k, v in record["checksums"].items()}


def test_records_name_every_choice(generated_random):
    assert verify(generated_random).ok
    job = json.loads((generated_random / "generate.json").read_text())
    assert job["job_key"]["config"]["randomise"]["seed"] == 11
    for record in records(generated_random):
        drawn = record["randomisation"]
        assert drawn["seed"] == 11 and drawn["scene_seed"] == record["seed"]
        cast = drawn["scene"]["cast"]
        assert cast and len(drawn["view"]["placements"]) == len(cast)
        assert {"profile", "body", "skin", "upper", "lower", "shoes", "device"} <= set(cast[0])
        assert drawn["scene"]["recolours"] and drawn["view"]["camera"]["focal_length_mm"] > 0
        light = drawn["light"]
        assert light["sun_elevation_deg"] == pytest.approx(record["condition"]["sun_elevation_deg"])
        assert record["exposure"].get("compensation_ev", 0.0) == pytest.approx(light["exposure_ev"])
        assert record["camera"]["focal_length_mm"] == pytest.approx(drawn["view"]["camera"]["focal_length_mm"],
                                                                    rel=1e-6)
        people = [i for i in record["instances"] if i["class_name"] == "person"]
        assert people and all("/World/Randomisation/Crowd/" in i["prim_path"] for i in people)


def test_other_seeds_at_one_camera_and_time_code_are_other_scenes(generated_random):
    """Two images of one camera and time code with other seeds: their class maps disagree on many pixels
    (people moved, the camera too), their casts look different, and their RGB differs far beyond what another
    sampler seed alone changes (measured on one image re-rendered with the other's sampler seed)."""
    recs = records(generated_random)
    pairs = [(a, b) for a in recs for b in recs if a["id"] < b["id"] and a["camera"]["prim_path"] ==
             b["camera"]["prim_path"] and a["time_code"] == b["time_code"] and a["seed"] != b["seed"]]
    assert pairs
    a, b = min(pairs, key=lambda p: p[0]["condition"]["name"] != p[1]["condition"]["name"])  # one condition if any
    fa, fb = _files(generated_random, a), _files(generated_random, b)
    disagree = np.mean(read_image(fa["class"])[0] != read_image(fb["class"])[0])
    assert disagree > 0.02, disagree
    looks = lambda r: {(m["body"], tuple(m["upper"])) for m in r["randomisation"]["scene"]["cast"]}  # noqa: E731
    assert looks(a) != looks(b)
    rgb_a = read_image(fa["rgb_png"])[0].astype(float)
    rgb_b = read_image(fb["rgb_png"])[0].astype(float)
    scenes = np.abs(rgb_a - rgb_b).mean()
    noise = _noise_of_another_sampler_seed(generated_random, a, b["seed"])
    assert scenes > 3 * noise, (scenes, noise)


def _noise_of_another_sampler_seed(dataset: Path, record: dict, seed: int) -> float:
    """Mean |difference| of ``record``'s RGB and the same image rendered with sampler seed ``seed``."""
    import shutil
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        result = run_synthua("randomise", SCENARIO, "--record", dataset / "records" / f"{record['name']}.json",
                             "--out", tmp / "layer.usda")
        assert result.code == 0, result.stderr
        args = result.stdout.split("render it with: ", 1)[1].split()[1:]
        args[args.index("--seed") + 1] = str(seed)
        args[args.index("--out") + 1] = str(tmp / "frame")
        rendered = run_synthua(*args)
        assert rendered.code == 0, rendered.stderr
        other = read_image(tmp / "frame" / "rgb.png")[0].astype(float)
        shutil.rmtree(tmp / "frame")
    return float(np.abs(other - read_image(_files(dataset, record)["rgb_png"])[0].astype(float)).mean())


def test_randomise_and_render_reproduce_the_images_bytes(generated_random, tmp_path):
    """`synthua randomise --record` writes the image's three layers and the look images its people wear beside them
    (the layers read nothing outside their folder) and prints the render command; that command writes the
    dataset's RGB, class and instance files byte for byte."""
    record = records(generated_random)[-1]
    result = run_synthua("randomise", SCENARIO, "--record", generated_random / "records" / f"{record['name']}.json",
                         "--out", tmp_path / "r" / "layer.usda")
    assert result.code == 0, result.stderr
    assert sorted(p.name for p in (tmp_path / "r").iterdir()) == ["layer.looks", "layer.prototypes.usdc",
                                                                  "layer.scene.usda", "layer.usda"]
    assert {p.name for p in (tmp_path / "r" / "layer.looks").iterdir()} >= {"face.png"}
    args = result.stdout.split("render it with: ", 1)[1].split()[1:]
    args[args.index("--out") + 1] = str(tmp_path / "frame")
    rendered = run_synthua(*args)
    assert rendered.code == 0, rendered.stderr
    files = _files(generated_random, record)
    for ours, theirs in (("rgb.png", "rgb_png"), ("class.png", "class"), ("instance.png", "instance")):
        assert (tmp_path / "frame" / ours).read_bytes() == files[theirs].read_bytes(), ours


def test_replay_of_randomised_images_is_byte_identical(generated_random, run_cli):
    for image in ("1", "6"):
        code, out, err = run_cli("replay", generated_random, image)
        assert code == 0 and "byte-identical" in out, out + err


def test_resume_after_kill_gives_the_same_randomised_dataset(generated_random, tmp_path):
    out = tmp_path / "killed"
    killed = kill_when(out, lambda o: len(list((o / "records").glob("*.json"))) >= 2 if (o / "records").exists()
                       else False, config=RANDOM_CONFIG)
    assert killed or (out / "manifest.json").exists()
    generate_dataset(out, config=RANDOM_CONFIG)
    assert tree_bytes(out) == tree_bytes(generated_random)


def test_randomise_refuses_what_it_cannot_draw(tmp_path):
    plain = DATA / "configs" / "tiny.json"
    assert_refused(run_synthua("randomise", SCENARIO, "--config", plain, "--out", tmp_path / "l.usda"),
                   "tiny.json", "no randomise block")
    assert_refused(run_synthua("randomise", SCENARIO, "--config", RANDOM_CONFIG, "--camera", "/World/Nope",
                               "--out", tmp_path / "l.usda"), "no camera at '/World/Nope'")
    assert_refused(run_synthua("randomise", SCENARIO, "--config", RANDOM_CONFIG, "--out", tmp_path / "l.txt"),
                   "l.txt", "USD layer name")
    assert_refused(run_synthua("randomise", SCENARIO, "--out", tmp_path / "l.usda"), "--config nor --record")
    assert_refused(run_synthua("randomise", SCENARIO, "--config", RANDOM_CONFIG, "--time-code", "nan",
                               "--out", tmp_path / "l.usda"), "--time-code")
    assert not list(tmp_path.iterdir())
