"""The generation config: schema, rules, one-line errors, defaults, shipped configs."""

import json

import pytest

from conftest import REPO
from synthua_usd.core.errors import InputError, SchemaError
from synthua_usd.dataset.config import (
    CountQuota, GenerationConfig, Outputs, QAThresholds, RenderSettings, SplitRatios,
    schema_default,
)
from synthua_usd.model.render_config import RenderConfig, resolve_render
from synthua_usd.model.timecodes import parse_time_code_spec

BASE = {"name": "t", "images": 10}


def load(tmp_path, **changes):
    path = tmp_path / "gen.json"
    path.write_text(json.dumps({**BASE, **changes}))
    return GenerationConfig.load(path)


@pytest.mark.parametrize("name", ["demo.json", "district.json", "demo_random.json", "district_random.json",
                                  "settings_random.json", "district_sequences.json", "sim2real.json",
                                  "sim2real_street.json"])
def test_shipped_configs_load_and_round_trip(name):
    config = GenerationConfig.load(REPO / "configs" / name)
    assert GenerationConfig.from_document(config.to_document()) == config
    assert config.render.pixel_filter == "box"


def test_demo_config_is_small():
    config = GenerationConfig.load(REPO / "configs" / "demo.json")
    assert (config.render.width, config.render.height, config.render.spp) == (320, 240, 8)
    assert config.images <= 16
    district = GenerationConfig.load(REPO / "configs" / "district.json")
    assert (district.render.width, district.render.height) == (1280, 960)


def test_schema_documents_the_dataclass_defaults():
    """The dataclasses own the defaults; the schema's `default` annotations must say the same."""
    for prefix, instance in (("render", RenderSettings()), ("split", SplitRatios()), ("outputs", Outputs())):
        for key, value in vars(instance).items():
            if value is not None:
                assert schema_default(f"{prefix}.{key}") == value, (prefix, key)
    for key, value in vars(QAThresholds()).items():
        assert schema_default(f"qa.{key}") == (list(value) if isinstance(value, tuple) else value), key
    minimal = GenerationConfig.from_document(BASE)
    assert schema_default("amodal_groups") == list(minimal.amodal_groups)
    assert schema_default("seeds") == list(minimal.seeds)
    assert schema_default("sampling_seed") == minimal.sampling_seed


def test_minimal_document_takes_the_defaults():
    config = GenerationConfig.from_document(BASE)
    assert config.render == RenderSettings() and config.split == SplitRatios() and config.qa == QAThresholds()
    assert config.conditions == () and config.cameras == () and config.time_codes == () and config.seeds == (0,)
    render = resolve_render(stage={"width": 640, "height": 480}, config=config.render.render_values())
    assert (render.width, render.height, render.spp) == (640, 480, RenderConfig.spp)
    assert config.output_size(640, 480) == (640, 480)


@pytest.mark.parametrize("changes, message", [
    ({"images": 0}, "gen.json: images: 0 without a sequences block; expected at least 1 image, or sequences"),
    ({"colour": 1}, "gen.json: colour: not a key of the document; expected one of $schema, amodal_groups, cameras,"),
    ({"render": {"pixel_filter": "gaussian"}}, "gen.json: render.pixel_filter: 'box' was expected"),
    ({"cameras": ["World/Cam"]}, "gen.json: cameras[0]: "),
    ({"split": {"train": 0.5}}, "gen.json: split: train + val + test = 0.7; expected ratios summing to 1"),
    ({"conditions": ["fog"], "quotas": {"per_condition": {"fog": 11}}},
     "gen.json: quotas.per_condition: counts sum to 11; expected at most images = 10"),
    ({"conditions": ["fog"], "quotas": {"per_condition": {"rain": 2}}},
     "gen.json: quotas.per_condition: rain is not among conditions; expected keys among fog"),
    ({"quotas": {"per_condition": {"rain": 2}}},
     "gen.json: quotas.per_condition: counts per condition while conditions is empty"),
    ({"quotas": {"per_rig_type": {"drone": 2}}},
     "gen.json: quotas.per_rig_type: drone is not a rig type; expected keys among cctv, dashcam"),
    ({"render": {"width": 64, "height": 48}, "resample": {"width": 128, "height": 24}},
     "gen.json: resample.width: 128 > render.width 64; expected at most the render size"),
    ({"time_codes": "4:1"}, "gen.json: time_codes: '4:1'; expected comma-separated numbers"),
    ({"time_codes": "1:x"}, "gen.json: time_codes: '1:x'; expected comma-separated numbers"),
    ({"qa": {"reject": ["sharpness"]}}, "gen.json: qa.reject[0]: 'sharpness' is not one of"),
    ({"quotas": {"aid_users": {"min_share": 1.5, "min_pixels": 10}}},
     "gen.json: quotas.aid_users.min_share: 1.5 is greater than the maximum of 1"),
    ({"qa": {"blur_min": -1}}, "gen.json: qa.blur_min: -1 is less than the minimum of 0"),
    ({"resample": {"width": 0, "height": 2}}, "gen.json: resample.width: 0 is less than the minimum of 1"),
])
def test_bad_values_give_one_line_naming_file_and_field(tmp_path, changes, message):
    with pytest.raises(InputError) as caught:
        load(tmp_path, **changes)
    text = str(caught.value)
    assert text.startswith(f"{tmp_path}/{message}"), text
    assert "\n" not in text and "; expected" in text


def test_schema_violations_are_schema_errors_and_rules_are_input_errors(tmp_path):
    with pytest.raises(SchemaError):
        load(tmp_path, images="ten")
    with pytest.raises(InputError) as caught:
        load(tmp_path, split={"train": 0.5})
    assert not isinstance(caught.value, SchemaError)


def test_not_json_names_the_file(tmp_path):
    path = tmp_path / "gen.json"
    path.write_text("{name: 1}")
    with pytest.raises(InputError, match=r"gen.json: not valid JSON.*expected a generation config"):
        GenerationConfig.load(path)


def test_time_code_specs():
    assert parse_time_code_spec("1:48:8") == (1.0, 9.0, 17.0, 25.0, 33.0, 41.0)
    assert parse_time_code_spec("24, 1:3") == (24.0, 1.0, 2.0, 3.0)
    assert parse_time_code_spec("1:2:0.5,2") == (1.0, 1.5, 2.0)
    assert GenerationConfig.from_document({**BASE, "time_codes": [3, 1, 3]}).time_codes == (3.0, 1.0)
    for bad in ("", "1:2:0", "nan", "1:2:3:4", "2:1"):
        with pytest.raises(ValueError):
            parse_time_code_spec(bad)


def test_output_size_refuses_growing_beyond_the_stage_size():
    config = GenerationConfig.from_document({**BASE, "resample": {"width": 320, "height": 240}})
    assert config.output_size(640, 480) == (320, 240)
    with pytest.raises(InputError, match=r"^resample: 320x240; expected at most the render size 200x100"):
        config.output_size(200, 100)


def test_amodal_groups_against_a_class_map(class_map):
    config = GenerationConfig.from_document(BASE)
    groups = {c.group for c in class_map.classes}
    names = {c.name for c in class_map.classes}
    config.check_amodal_groups(groups, names)
    assert config.amodal_wanted("animal", "nature") and config.amodal_wanted("walker", "accessibility")
    assert not config.amodal_wanted("building", "building")
    bad = GenerationConfig.from_document({**BASE, "amodal_groups": ["persons"]})
    with pytest.raises(InputError, match="^amodal_groups: persons is not a class group or class"):
        bad.check_amodal_groups(groups, names)


def test_count_quota_targets():
    assert CountQuota(balanced=True).targets(["a", "b", "c"], 10) == {"a": 4, "b": 3, "c": 3}
    assert CountQuota(counts=(("a", 2),)).targets(["a", "b"], 10) == {"a": 2}


def test_qa_actions():
    qa = GenerationConfig.from_document({**BASE, "qa": {"reject": ["blur"]}}).qa
    assert qa.action("blur") == "rejected" and qa.action("shadows") == "flagged"
