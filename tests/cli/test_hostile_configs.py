"""Hostile generation configs and randomise options: a misspelt key of the ``randomise`` or ``sequences`` block named
with the key it most likely meant (not "is not valid under any of the given schemas"), values that would silently
make nothing (aid users "in view" at no height, a tracking sequence of one frame), and ``randomise --record`` with
options the record fixes. Each is one line, exit 2, nothing written."""

from __future__ import annotations

import pytest

from conftest import RANDOM_CONFIG, SCENARIO
from importers.hostile_corpus import doc, write

SEQUENCES = {"cameras": ["/World/Cameras/CCTV"], "seeds": [0], "duration_s": 1.0, "fps": 6}


def _config(workdir, name: str, **changes):
    """The randomised test config with ``changes`` merged into its top level (a value None deletes the key)."""
    document = doc(RANDOM_CONFIG)
    for key, value in changes.items():
        if value is None:
            document.pop(key, None)
        else:
            document[key] = value
    return write(workdir / name, document)


@pytest.mark.parametrize("block, field, nearest", [
    ({"seed": 11, "crowd": {"densty_per_m2": [0.01, 0.02]}}, "randomise.crowd.densty_per_m2", "density_per_m2"),
    ({"seed": 11, "crowds": {}}, "randomise.crowds", "crowd"),
    ({"seed": 11, "light": {"exposure": [0, 1]}}, "randomise.light.exposure", "exposure_ev"),
])
def test_a_misspelt_randomise_key_names_the_nearest(refuse, workdir, block, field, nearest):
    config = _config(workdir, "typo.json", randomise=block)
    message = refuse("randomise", SCENARIO, "--config", config, "--out", workdir / "r" / "layer.usda",
                     mentions=("typo.json", field, f"expected {nearest}, the nearest valid key"))
    assert "any of the given schemas" not in message


@pytest.mark.parametrize("key, nearest", [("duraton_s", "duration_s"), ("fsp", "fps"), ("camera", "cameras")])
def test_a_misspelt_sequences_key_names_the_nearest(refuse, workdir, key, nearest):
    block = dict(SEQUENCES)
    block[key] = block.pop(nearest, 1)
    config = _config(workdir, "typo.json", sequences=block, randomise=None)
    message = refuse("generate", SCENARIO, "--config", config, "--out", workdir / "dataset",
                     mentions=("typo.json", f"sequences.{key}", f"expected {nearest}, the nearest valid key"))
    assert "any of the given schemas" not in message


@pytest.mark.parametrize("duration_s, fps", [(0.001, 1), (0.1, 10), (1.4, 1)])
def test_a_sequence_of_fewer_than_two_frames_is_refused(refuse, workdir, duration_s, fps):
    """0.001 s at 1 fps rendered one frame without a word."""
    config = _config(workdir, "short.json", sequences={**SEQUENCES, "duration_s": duration_s, "fps": fps},
                     randomise=None)
    refuse("generate", SCENARIO, "--config", config, "--out", workdir / "dataset",
           mentions=("short.json", "sequences.duration_s", "at least 2 frames"))


@pytest.mark.parametrize("share", [[0, 0], [0, 0.5], [0.001, 0.002]])
def test_aid_users_in_view_at_no_height_are_refused(refuse, workdir, share):
    """view_height_share [0, 0] put the aid users out of view, silently."""
    document = doc(RANDOM_CONFIG)
    document["randomise"]["crowd"]["view_height_share"] = share
    config = write(workdir / "flat.json", document)
    refuse("randomise", SCENARIO, "--config", config, "--out", workdir / "r" / "layer.usda",
           mentions=("flat.json", "randomise.crowd.view_height_share", "at least 0.005"))


@pytest.mark.parametrize("option, value", [("--seed", "7"), ("--seed", "0"), ("--camera", "/World/Cameras/CCTV"),
                                           ("--time-code", "3"), ("--condition", "clear_night"),
                                           ("--config", str(RANDOM_CONFIG))])
def test_randomise_refuses_an_option_the_record_fixes(refuse, workdir, generated_random, option, value):
    """--record with --seed 7 wrote the record's image and ignored the seed."""
    record = sorted((generated_random / "records").glob("*.json"))[0]
    refuse("randomise", SCENARIO, "--record", record, option, value, "--out", workdir / "r" / "layer.usda",
           mentions=(option, "--record", "one or the other"))


@pytest.mark.parametrize("block, mentions", [
    ({"settings": {"enabled": True, "variants": 0}}, ("randomise.settings.variants", "0")),
    ({"settings": {"enabled": True, "kinds": ["moon"]}}, ("randomise.settings.kinds", "moon")),
    ({"settings": {"enabled": True}, "crowd": {"enabled": False}}, ("randomise.settings: enabled while",)),
    ({"distractors": {"enabled": True, "on_surfaces": [0.5, 2]}}, ("randomise.distractors.on_surfaces",
                                                                   "two whole numbers")),
    ({"distractors": {"enabled": True, "objects": ["piano"]}}, ("randomise.distractors.objects", "piano")),
    ({"distractors": {"enabled": True, "primitive_size_m": [0.5, 0.1]}}, ("randomise.distractors.primitive_size_m",)),
])
def test_impossible_settings_and_distractors_are_refused(refuse, workdir, block, mentions):
    """Each a line naming the file and the field, exit 2, before anything is planned or written."""
    document = doc(RANDOM_CONFIG)
    document["randomise"] |= block
    config = write(workdir / "parts.json", document)
    refuse("generate", SCENARIO, "--config", config, "--out", workdir / "dataset", mentions=("parts.json", *mentions))
