"""The composite config: the schema documents the dataclasses' defaults, the shipped config is valid, and what a
schema cannot say is refused in one line."""

from __future__ import annotations

import json

import pytest

from conftest import REPO
from synthua_usd.core.errors import InputError
from synthua_usd.core.schemas import load_schema
from synthua_usd.dataset.composite_config import LATER_MATCH_FIELDS, LATER_MATCH_GROUPS, BackgroundLabels, \
    CameraSettings, CompositeConfig, MatchSettings, SharpenSettings


def _defaults(node, schema) -> dict:
    """Dotted path -> the default the schema documents, for every property that documents one."""
    out = {}
    for name, prop in (node.get("properties") or {}).items():
        target = prop
        if "$ref" in prop and prop["$ref"].startswith("#/$defs/"):
            target = schema["$defs"][prop["$ref"].split("/")[-1]]
        if "default" in prop:
            out[name] = prop["default"]
        for key, value in _defaults(target, schema).items():
            out[f"{name}.{key}"] = value
    return out


def test_the_schema_documents_the_dataclass_defaults():
    schema = load_schema("composite")
    written = CompositeConfig().to_document()
    documented = _defaults(schema, schema)
    documented["camera"] = schema["$defs"]["camera"]["default"]
    assert documented, "the schema documents defaults"
    for path, default in documented.items():
        if path == "shadow":
            continue
        if path == "sharpen":
            continue  # left out of the document while it holds its defaults, checked field by field below
        if path.startswith("sharpen."):
            field = getattr(SharpenSettings, path.split(".")[1])
            assert default == (list(field) if isinstance(field, tuple) else field), path
            continue
        if path.startswith("match.") and path.split(".")[1] in LATER_MATCH_FIELDS:
            field = getattr(MatchSettings, path.split(".")[1])
            assert default == (list(field) if isinstance(field, tuple) else field), path  # left out of the document
            continue
        value = written
        for part in path.split("."):
            value = value[part]
        if isinstance(default, dict) and not default:
            continue  # an empty object: its fields' own defaults are checked one by one
        assert value == default, path


def test_later_match_fields_are_written_only_where_set_so_earlier_job_keys_hold():
    assert not set(LATER_MATCH_FIELDS) & set(CompositeConfig().to_document()["match"])
    sharpness = {"sharpness_strength": 0.0, "sharpness_sigma_px": 3.0}
    tone = {"contrast_strength": 0.0, "contrast_gain": [0.67, 1.5], "saturation_strength": 0.0,
            "saturation_gain": [0.5, 1.5]}
    assert [set(group) for group in LATER_MATCH_GROUPS] == [set(sharpness), set(tone)]
    for part, group, other in (({"sharpness_strength": 0.5}, sharpness, tone),
                               ({"sharpness_sigma_px": 5.0}, sharpness, tone),
                               ({"saturation_strength": 1.0}, tone, sharpness),
                               ({"contrast_gain": [0.8, 1.2]}, tone, sharpness)):
        config = CompositeConfig.from_document({"match": part})
        document = config.to_document()
        assert {k: document["match"][k] for k in group} == {**group, **part}  # written together
        assert not set(other) & set(document["match"])                       # the other group still left out
        assert CompositeConfig.from_document(document) == config


def test_sharpening_is_written_only_where_set_so_earlier_job_keys_hold():
    assert "sharpen" not in CompositeConfig().to_document()
    config = CompositeConfig.from_document({"sharpen": {"share": 0.5}})
    assert config.to_document()["sharpen"] == {"share": 0.5, "amount": [2.0, 3.0], "sigma_px": [1.5, 2.5]}
    assert CompositeConfig.from_document(config.to_document()) == config


def test_people_heights_are_written_only_where_set_and_checked():
    camera = CompositeConfig().to_document()["camera"]
    assert "person_height_m" not in camera and "wheelchair_height_m" not in camera    # earlier job keys hold
    assert CameraSettings().people_heights() == {} and not CompositeConfig().sets_people_heights()
    config = CompositeConfig.from_document({"camera": {"person_height_m": 1.7},
                                            "folders": {"kids": {"person_height_m": 1.2, "wheelchair_height_m": 1.0}}})
    assert config.to_document()["camera"]["person_height_m"] == 1.7
    assert "wheelchair_height_m" not in config.to_document()["camera"]
    assert CompositeConfig.from_document(config.to_document()) == config
    settings, sources = config.camera_for("kids/a.jpg")
    assert settings.person_height_m == 1.2 and sources["person_height_m"] == "folder:kids"
    assert settings.people_heights() == {"person": 1.2, "manual_wheelchair": 1.0, "electric_wheelchair": 1.0}
    assert config.camera_for("b.jpg")[0].people_heights() == {"person": 1.7} and config.sets_people_heights()
    assert CompositeConfig.from_document({"folders": {"kids": {"wheelchair_height_m": 1.0}}}).sets_people_heights()
    assert CameraSettings(wheelchair_height_m=1.35, pitch_deg=-5.0).people_heights() == {}   # a known pitch wins
    seated = CompositeConfig.from_document({"camera": {"wheelchair_height_m": 1.35}})
    assert seated.to_document()["camera"]["wheelchair_height_m"] == 1.35
    assert CompositeConfig.from_document(seated.to_document()) == seated
    for name in ("person_height_m", "wheelchair_height_m"):
        with pytest.raises(InputError, match=rf"camera\.{name}: 3\.0; expected metres in \[0\.5, 2\.5\] or null"):
            CameraSettings(**{name: 3.0})


def test_other_classes_may_only_be_left_out():
    labels = CompositeConfig.from_document({"background_labels": {"classes": {"person": "person", "*": None}}})
    assert [labels.background_labels.our_class(n) for n in ("person", "dog")] == ["person", None]
    assert CompositeConfig().background_labels.our_class("dog") == "dog"          # not listed, no "*": its own name
    with pytest.raises(InputError, match=r"background_labels\.classes\.\*: 'person'; expected null"):
        BackgroundLabels(classes=(("*", "person"),))


def test_match_settings_made_in_code_are_checked():
    with pytest.raises(InputError, match=r"match\.sharpness_strength: nan; expected a share in \[0, 1\]"):
        MatchSettings(sharpness_strength=float("nan"))
    with pytest.raises(InputError, match=r"match\.sharpness_sigma_px: -1\.0; expected px in \[0, 50\]"):
        MatchSettings(sharpness_sigma_px=-1.0)
    with pytest.raises(InputError, match=r"match\.saturation_strength: 1\.5; expected a share in \[0, 1\]"):
        MatchSettings(saturation_strength=1.5)
    with pytest.raises(InputError, match=r"match\.contrast_strength: nan; expected a share in \[0, 1\]"):
        MatchSettings(contrast_strength=float("nan"))
    with pytest.raises(InputError, match=r"match\.contrast_gain: \[0\.05, 2\]; expected a range within \[0\.1, 10\]"):
        MatchSettings(contrast_gain=(0.05, 2.0))


def test_an_empty_document_is_the_defaults_and_a_document_round_trips():
    config = CompositeConfig.from_document({})
    assert config == CompositeConfig()
    assert CompositeConfig.from_document(config.to_document()) == config


def test_the_shipped_config_is_valid():
    config = CompositeConfig.load(REPO / "configs" / "composite.json")
    assert config.output == (640, 480) and config.convention == "wheelchair-sets"
    assert config.background_labels.our_class("wheelchair") == "manual_wheelchair"
    assert config.background_labels.our_class("person") == "person"
    assert config.camera.people_heights() == {"person": 1.7, "manual_wheelchair": 1.35, "electric_wheelchair": 1.35}


@pytest.mark.parametrize("document, message", [
    ({"bogus": 1}, r"x\.json: bogus: not a key of the document; expected one of \$schema, background_labels"),
    ({"match": {"sharpness_strength": 1.5}}, r"x\.json: match\.sharpness_strength: 1\.5"),
    ({"pastes": {"height_share": [0.9, 0.2]}}, r"x\.json: pastes\.height_share: \[0\.9, 0\.2\]; expected two finite "
                                               r"numbers with low <= high"),
    ({"split": {"train": 0.5, "val": 0.1, "test": 0.1}}, r"x\.json: split: train \+ val \+ test = 0\.7; expected"),
    ({"blend": {"hard": 0, "feather": 0, "blur": 0, "poisson": 0}}, r"x\.json: blend: weights"),
    ({"camera": {"height_m": [2, 1]}}, r"x\.json: camera\.height_m: \[2, 1\]"),
    ({"camera": {"person_height_m": 0.2}}, r"x\.json: camera\.person_height_m: 0\.2"),
    ({"camera": {"wheelchair_height_m": 2.6}}, r"x\.json: camera\.wheelchair_height_m: 2\.6"),
    ({"folders": {"a": {"height_m": -1}}}, r"x\.json: folders\.a\.height_m"),
    ({"output": {"width": 8, "height": 48}}, r"x\.json: output"),
    ({"sharpen": {"amount": [3, 1]}}, r"x\.json: sharpen\.amount: \[3, 1\]; expected two finite numbers"),
    ({"sharpen": {"sigma_px": [0.1, 1]}}, r"x\.json: sharpen\.sigma_px: \[0\.1, 1\]"),
])
def test_bad_documents_are_refused_naming_the_field(document, message):
    with pytest.raises(InputError, match=message):
        CompositeConfig.from_document(document, "x.json")


def test_folders_override_the_camera_by_the_longest_match():
    config = CompositeConfig.from_document({
        "camera": {"height_m": 1.5, "horizon_row_share": [0.3, 0.4]},
        "folders": {"cctv": {"height_m": 6.0, "horizon_row_share": 0.1}, "cctv/north/": {"height_m": 8.0}}})
    settings, sources = config.camera_for("cctv/north/frame1.jpg")
    assert settings.height_m == (8.0, 8.0) and settings.horizon_row_share == (0.1, 0.1)
    assert sources["height_m"] == "folder:cctv/north" and sources["horizon_row_share"] == "folder:cctv"
    settings, sources = config.camera_for("street/a.jpg")
    assert settings.height_m == (1.5, 1.5) and sources["height_m"] == "config"
    assert json.loads(json.dumps(config.to_document()))["folders"]["cctv/north"] == {"height_m": 8.0}
