"""``synthua generate`` with camera effects on (tests/data/configs/random_effects.json: random.json with every effect
applied to every image): the scene draws, the labels and the plan are random.json's (the effects draw from a stream
of their own), each image's RGB is its random.json twin with the recorded effects applied to it (with that twin's
depth), and replay gives the dataset's bytes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import DATA, built_once, generate_dataset
from dataset_runs import records
from synthua_usd.backends.camera_effects import apply_effects
from synthua_usd.core.images import read_image
from synthua_usd.pipeline.verify import verify
from synthua_usd.randomisation.config import EFFECTS
from synthua_usd.randomisation.effects import EffectsDraw

EFFECTS_CONFIG = DATA / "configs" / "random_effects.json"


@pytest.fixture(scope="module")
def generated_effects(tmp_path_factory) -> Path:
    return built_once(tmp_path_factory, "random_effects", lambda out: generate_dataset(out, config=EFFECTS_CONFIG))


def _files(dataset: Path, record: dict) -> dict[str, Path]:
    return {key: dataset / rel for key, rel in record["files"].items()}


def test_effects_are_recorded_and_applied_to_the_rendered_image_only(generated_effects, generated_random):
    assert verify(generated_effects).ok
    ours = {r["name"]: r for r in records(generated_effects)}
    plain = {r["name"]: r for r in records(generated_random)}
    assert sorted(ours) == sorted(plain)
    for name, record in ours.items():
        drawn = dict(record["randomisation"])
        effects = EffectsDraw.from_dict(drawn.pop("effects"))
        assert effects.applied == EFFECTS                       # every probability is 1 in the config
        twin = plain[name]
        assert drawn == twin["randomisation"], name               # no scene, view or light draw moved
        a, b = _files(generated_effects, record), _files(generated_random, twin)
        for key in ("class", "instance", "panoptic", "depth", "yolo_label"):
            assert a[key].read_bytes() == b[key].read_bytes(), (name, key)
        assert record["instances"] == twin["instances"]
        rendered = read_image(b["rgb_png"])[0]
        depth = read_image(b["depth"])[0][..., 0]
        expected = apply_effects(rendered, effects, depth)
        assert (read_image(a["rgb_png"])[0] == expected).all(), name
        assert not (expected == rendered).all()


def test_replay_with_effects_is_byte_identical(generated_effects, run_cli):
    for image in ("1", "4"):
        code, out, err = run_cli("replay", generated_effects, image)
        assert code == 0 and "byte-identical" in out, out + err


def test_a_record_with_effects_passes_its_schema_and_names_the_draw(generated_effects):
    from synthua_usd.dataset.record import IMAGE, record_problem

    record = json.loads(next((generated_effects / "records").glob("*.json")).read_text())
    assert record_problem(record, IMAGE) is None
    assert set(record["randomisation"]["effects"]) == set(EFFECTS)
    record["randomisation"]["effects"]["bloom"] = None
    assert record_problem(record, IMAGE) is not None
