"""The ``randomise`` block of a generation config: defaults held to the schema's documentation, round trips,
and one-line refusals of impossible ranges."""

from __future__ import annotations

import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.core.schemas import load_schema
from synthua_usd.dataset.config import GenerationConfig
from synthua_usd.randomisation.config import RandomisationConfig


def test_defaults_are_the_schemas():
    """Every default the schema documents is the dataclass's."""
    schema = load_schema("generate")["$defs"]["randomise"]["properties"]
    config = RandomisationConfig()
    assert schema["seed"]["default"] == config.seed
    for part, spec in schema.items():
        if part == "seed":
            continue
        values = getattr(config, part)
        for key, field in spec["properties"].items():
            value = getattr(values, key)
            assert list(value) == field["default"] if isinstance(value, tuple) else value == field["default"], \
                (part, key)


def test_round_trip_and_off_by_default():
    doc = {"name": "x", "images": 2, "randomise": {"seed": 3, "crowd": {"aids": ["walker"], "aid_share": [0.5, 0.5]},
                                                    "light": {"enabled": False}}}
    config = GenerationConfig.from_document(doc)
    assert config.randomise.crowd.aids == ("walker",) and not config.randomise.light.enabled
    assert GenerationConfig.from_document(config.to_document()) == config
    plain = GenerationConfig.from_document({"name": "x", "images": 2})
    assert plain.randomise is None and "randomise" not in plain.to_document()
    assert config.randomise.enabled_parts == ("crowd", "devices", "hair", "looks", "materials", "camera")


@pytest.mark.parametrize("block, mentions", [
    ({"crowd": {"density_per_m2": [0.05, 0.01]}}, "randomise.crowd.density_per_m2: [0.05, 0.01]"),
    ({"crowd": {"density_per_m2": [0.1, 0.5]}}, "expected a range within [0, 0.3]"),
    ({"crowd": {"density_per_m2": [0.0, 0.1]}}, "low end > 0"),
    ({"crowd": {"aid_users_in_view": [1.5, 2]}}, "two whole numbers"),
    ({"light": {"exposure_ev": [-9, 0]}}, "randomise.light.exposure_ev"),
    ({"light": {"latitude_deg": 80}}, "latitude"),
    ({"district": {"enabled": True}, "crowd": {"enabled": False}}, "randomise.district: enabled while"),
    ({"camera": {"focal_length_factor": [2, 1]}}, "randomise.camera.focal_length_factor"),
    ({"looks": {"long_legs": 1.5}}, "randomise.looks.long_legs"),
    ({"looks": {"palette": "neon"}}, "randomise.looks.palette"),
])
def test_impossible_ranges_are_refused(block, mentions):
    with pytest.raises(InputError) as err:
        GenerationConfig.from_document({"name": "x", "images": 2, "randomise": block}, source="gen.json")
    message = str(err.value)
    assert mentions in message and message.startswith("gen.json") and "\n" not in message


def test_unknown_keys_and_values_are_refused_by_the_schema():
    from synthua_usd.core.errors import SchemaError

    for block in ({"crowd": {"speed": 1}}, {"crowd": {"aids": ["skateboard"]}}, {"materials": {"classes": ["sky"]}},
                  {"what": {}}):
        with pytest.raises(SchemaError):
            GenerationConfig.from_document({"name": "x", "images": 2, "randomise": block})
