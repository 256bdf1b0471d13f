"""Conditions round-trip through USD; a render's choice lives in the session layer only."""

import math

import pytest
from pxr import Usd

from conftest import DATA, DISTRICT, SCENARIO
from synthua_usd.composition.scenario import ENVIRONMENT_PATH, Environment, StageMetadata
from synthua_usd.core.errors import StageError
from synthua_usd.model.conditions import SHIPPED, Condition
from synthua_usd.usd.conditions import (attribute_name, condition_names, condition_selected, read_condition,
                                        selected_condition)
from synthua_usd.usd.scenario_layers import build_environment
from synthua_usd.usd.stage_io import open_stage

CUSTOM = Condition("dusk_drizzle", "made up", sun_elevation_deg=1.5, sun_azimuth_deg=271.25, turbidity=6.5,
                   fog_visibility_m=1234.5, fog_top_m=321.0, rain_rate_mm_per_h=0.7, ground_wetness=0.35,
                   snow_cover=0.0, street_lights_on=True, vehicle_lamps_on=False, lit_window_fraction=0.125,
                   night_sky_luminance_cd_m2=0.02)


@pytest.mark.parametrize("suffix", [".usda", ".usdc"])
def test_every_condition_round_trips_through_a_saved_layer(tmp_path, suffix):
    conditions = SHIPPED + (CUSTOM,)
    layer = build_environment(StageMetadata(), Environment(conditions, default="day_fog"))
    path = tmp_path / f"environment{suffix}"
    layer.GetRootLayer().Export(str(path))
    stage = Usd.Stage.Open(str(path))
    assert sorted(condition_names(stage)) == sorted(c.name for c in conditions)
    assert selected_condition(stage) == "day_fog" and read_condition(stage).name == "day_fog"
    for condition in conditions:
        assert read_condition(stage, condition.name) == condition
    assert math.isinf(read_condition(stage, "clear_day").fog_visibility_m)


def test_attributes_carry_their_units():
    assert attribute_name("fog_visibility_m") == "synthua:condition:fogVisibilityM"
    assert attribute_name("rain_rate_mm_per_h") == "synthua:condition:rainRateMmPerH"


def test_the_shipped_stages_offer_the_seven_conditions():
    for path in (SCENARIO, DISTRICT / "scenario.usda"):
        stage = open_stage(path)
        assert sorted(condition_names(stage)) == sorted(c.name for c in SHIPPED)
        assert read_condition(stage) == SHIPPED[0]


def test_choosing_a_condition_edits_only_the_session_layer():
    stage = open_stage(SCENARIO)
    before = {layer.identifier: layer.ExportToString() for layer in stage.GetLayerStack(includeSessionLayers=False)}
    with condition_selected(stage, "clear_night"):
        assert selected_condition(stage) == "clear_night"
        assert not read_condition(stage).sun_up
        # The UsdLux sun the viewers see is switched off by the variant as well.
        assert stage.GetPrimAtPath(f"{ENVIRONMENT_PATH}/Sun").GetAttribute("inputs:intensity").Get() == 0
    assert selected_condition(stage) == "clear_day"
    assert read_condition(stage, "snow").name == "snow" and selected_condition(stage) == "clear_day"
    after = {layer.identifier: layer.ExportToString() for layer in stage.GetLayerStack(includeSessionLayers=False)}
    assert after == before and not any(layer.dirty for layer in stage.GetLayerStack(includeSessionLayers=False))


def test_unknown_condition_names_the_known_ones():
    stage = open_stage(SCENARIO)
    with pytest.raises(StageError) as err:
        read_condition(stage, "hail")
    assert str(err.value) == (f"{stage.GetRootLayer().identifier}: no condition 'hail'; conditions in the stage: "
                              "clear_day, day_fog, day_rain_fog, clear_night, night_rain_fog, sunset, snow")


def test_a_stage_without_conditions_reads_none_and_refuses_a_name():
    stage = open_stage(DATA / "valid" / "tiny_scene.usda")
    assert read_condition(stage) is None and condition_names(stage) == []
    with pytest.raises(StageError, match="offers no conditions"):
        read_condition(stage, "clear_day")


def test_an_out_of_range_attribute_is_a_stage_error_naming_it():
    stage = build_environment(StageMetadata(), Environment())
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        stage.GetPrimAtPath(ENVIRONMENT_PATH).GetAttribute(attribute_name("snow_cover")).Set(3.0)
    with pytest.raises(StageError, match="variant 'clear_day': condition clear_day: snow_cover should be a number in"):
        read_condition(stage)
