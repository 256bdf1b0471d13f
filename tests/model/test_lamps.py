"""Lamps as plain data: roles, photometry, which windows are lit."""

import math

import pytest

from synthua_usd.model.conditions import shipped
from synthua_usd.model.lamps import KINDS, ROLE_BY_CLASS, is_on, lamp_role, window_is_lit


def test_role_is_authored_else_by_class():
    assert lamp_role("headlamp", "car") == "headlamp"
    assert lamp_role("", "luminaire") == "street" and lamp_role("", "window") == "window"
    assert lamp_role("", "building") == ""
    assert set(ROLE_BY_CLASS.values()) <= set(KINDS)


def test_flux_is_spread_over_the_instance_area():
    street = KINDS["street"]
    assert street.luminance(2.0) == pytest.approx(street.flux_lm / (math.pi * 2.0))
    assert KINDS["window"].luminance(123.0) == KINDS["window"].luminance_cd_m2


def test_lit_windows_are_fixed_per_path_and_grow_with_the_fraction():
    paths = [f"/World/Twin/House{k}/Window{j}" for k in range(20) for j in range(10)]
    lit = {f: {p for p in paths if window_is_lit(p, f)} for f in (0.0, 0.2, 0.4, 1.0)}
    assert not lit[0.0] and lit[1.0] == set(paths)
    assert lit[0.2] <= lit[0.4]
    assert 0.3 < len(lit[0.4]) / len(paths) < 0.5


def test_conditions_switch_lamps():
    day, night = shipped("clear_day"), shipped("clear_night")
    assert not is_on(KINDS["street"], day, "/a") and is_on(KINDS["street"], night, "/a")
    assert is_on(KINDS["headlamp"], shipped("day_rain_fog"), "/car")
