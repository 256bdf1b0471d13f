"""The ``settings`` part of the randomise block (issue 40: backgrounds beyond the one district): off by default and
then left out of the config's document (job keys as before), a setting drawn per seed from a stream of its own that
moves no district draw, every kind drawn, the same seed the same setting, and impossible values refused in one line
naming the field."""

from __future__ import annotations

from collections import Counter

import pytest

from synthua_usd.core.errors import InputError, SchemaError
from synthua_usd.dataset.config import GenerationConfig
from synthua_usd.pipeline.scenes import SceneKey, scene_of
from synthua_usd.pipeline.districts import district_of
from synthua_usd.randomisation.config import RandomisationConfig
from synthua_usd.randomisation.settings import SETTING_KINDS


def test_off_by_default_and_absent_from_the_document():
    config = RandomisationConfig()
    assert not config.settings.enabled and not config.distractors.enabled
    document = config.to_document()
    assert "settings" not in document and "distractors" not in document
    assert all(scene_of(config, seed) is None for seed in range(50))
    on = RandomisationConfig.from_document({"settings": {"enabled": True, "variants": 3}})
    assert RandomisationConfig.from_document(on.to_document()) == on and on.to_document()["settings"]["variants"] == 3


def test_settings_are_drawn_per_seed_from_a_stream_of_their_own():
    districts = RandomisationConfig.from_document({"district": {"enabled": True, "seeds": [0, 5]}})
    both = RandomisationConfig.from_document({"district": {"enabled": True, "seeds": [0, 5]},
                                              "settings": {"enabled": True, "district_share": 0.3, "variants": 4}})
    keys = [scene_of(both, seed) for seed in range(400)]
    assert keys == [scene_of(both, seed) for seed in range(400)]  # the same seed, the same scenario
    in_district = [s for s, k in enumerate(keys) if k is None or k.kind == "district"]
    # a seed that stays in the district is in the district it draws without settings: no district draw moved
    assert all(keys[s] == SceneKey("district", district_of(districts, s)) for s in in_district)
    assert 0.2 < len(in_district) / len(keys) < 0.4
    kinds = Counter(k.kind for k in keys if k.kind != "district")
    assert set(kinds) == set(SETTING_KINDS) and min(kinds.values()) > 20
    assert {k.number for k in keys if k.kind != "district"} == {0, 1, 2, 3}
    narrowed = RandomisationConfig.from_document({"settings": {"enabled": True, "kinds": ["park"], "district_share": 0}})
    assert {scene_of(narrowed, s) for s in range(30)} <= {SceneKey("park", v) for v in range(8)}
    assert SceneKey("park", 3).folder == "scenes/park_3" and SceneKey("district", 2).name == "district_2"


@pytest.mark.parametrize("block, mentions", [
    ({"settings": {"enabled": True}, "crowd": {"enabled": False}}, "randomise.settings: enabled while"),
    ({"settings": {"variants": 0}}, "randomise.settings.variants: 0"),
    ({"settings": {"district_share": 1.5}}, "randomise.settings.district_share"),
])
def test_impossible_settings_are_refused_in_one_line(block, mentions):
    with pytest.raises((InputError, SchemaError)) as err:
        GenerationConfig.from_document({"name": "x", "images": 2, "randomise": block}, source="gen.json")
    message = str(err.value)
    assert mentions in message and "\n" not in message


def test_unknown_kinds_are_refused():
    with pytest.raises(SchemaError):
        GenerationConfig.from_document({"name": "x", "images": 2, "randomise": {"settings": {"kinds": ["moon"]}}})
    with pytest.raises(InputError, match="settings.kinds: moon; expected one or more distinct of corridor"):
        RandomisationConfig.from_document({"settings": {"kinds": ["moon"]}})
