"""Conditions as plain data: checked when made, the shipped seven, sun directions, fog extinction."""

import math

import numpy as np
import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.model.conditions import DEFAULT_CONDITION, KOSCHMIEDER, SHIPPED, Condition, display_order, shipped


def test_the_papers_five_then_sunset_and_snow_are_shipped():
    assert [c.name for c in SHIPPED] == ["clear_day", "day_fog", "day_rain_fog", "clear_night", "night_rain_fog",
                                         "sunset", "snow"]
    assert DEFAULT_CONDITION == "clear_day"
    night = shipped("clear_night")
    assert not night.sun_up and night.street_lights_on and night.vehicle_lamps_on
    rain = shipped("day_rain_fog")
    assert rain.rain_rate_mm_per_h > 0 and rain.ground_wetness == 1.0 and math.isfinite(rain.fog_visibility_m)
    assert shipped("snow").snow_cover == 1.0 and shipped("clear_day").fog_extinction_per_m == 0.0


def test_unknown_shipped_name_lists_the_known_ones():
    with pytest.raises(InputError, match="no shipped condition 'hail'; known: clear_day, day_fog"):
        shipped("hail")


def test_koschmieder_extinction():
    assert KOSCHMIEDER == pytest.approx(3.912, abs=5e-4)
    assert Condition("f", fog_visibility_m=200.0).fog_extinction_per_m == pytest.approx(3.912 / 200, rel=1e-3)


@pytest.mark.parametrize("elevation,azimuth,expected", [
    (90.0, 0.0, (0.0, 0.0, 1.0)), (0.0, 0.0, (0.0, 1.0, 0.0)), (0.0, 90.0, (1.0, 0.0, 0.0)),
    (30.0, 180.0, (0.0, -math.cos(math.radians(30)), 0.5)),
])
def test_sun_direction_from_elevation_and_azimuth(elevation, azimuth, expected):
    c = Condition("s", sun_elevation_deg=elevation, sun_azimuth_deg=azimuth)
    assert np.allclose(c.sun_direction("Z"), expected, atol=1e-12)
    x, y, z = expected
    assert np.allclose(c.sun_direction("Y"), (x, z, -y), atol=1e-12)


@pytest.mark.parametrize("kw,text", [
    (dict(name="has space"), "condition name should be letters, digits and underscores"),
    (dict(name="c", turbidity=0.5), "turbidity should be a number in [1, 10], but was 0.5"),
    (dict(name="c", snow_cover=2.0), "snow_cover should be a number in [0, 1], but was 2.0"),
    (dict(name="c", fog_visibility_m=0.0), "fog_visibility_m should be > 0 metres (inf for no fog), but was 0.0"),
    (dict(name="c", fog_visibility_m=float("nan")), "fog_visibility_m should be > 0 metres"),
    (dict(name="c", street_lights_on=1), "street_lights_on should be true or false, but was 1"),
    (dict(name="c", sun_elevation_deg=float("inf")), "sun_elevation_deg should be a number in [-90, 90]"),
])
def test_bad_conditions_are_refused_with_the_value(kw, text):
    with pytest.raises(InputError) as err:
        Condition(**kw)
    assert text in str(err.value)


def test_from_dict_refuses_unknown_keys_and_to_dict_round_trips():
    with pytest.raises(InputError, match=r"unknown keys \['fog'\]"):
        Condition.from_dict({"name": "x", "fog": 1})
    for c in SHIPPED:
        data = c.to_dict()
        if data["fog_visibility_m"] is None:  # JSON has no infinity
            data["fog_visibility_m"] = math.inf
        assert Condition.from_dict(data) == c


def test_display_order_puts_shipped_first():
    assert display_order(["zz", "snow", "clear_day", "aa"]) == ["clear_day", "snow", "aa", "zz"]
