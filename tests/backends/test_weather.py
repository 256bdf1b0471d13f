"""Fog and rain in image space: Koschmieder fog, the fog layer's light, rain streaks."""

import dataclasses
import math

import numpy as np
import pytest

from synthua_usd.backends.weather import (apply_fog, drop_density_per_m3, fog_lighting, rain_streaks,
                                          terminal_speed_mps)
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.conditions import shipped

RNG = np.random.default_rng(7)
RGB = RNG.random((48, 64, 3)).astype(np.float32)
DISTANCE = RNG.uniform(1.0, 400.0, (48, 64))
HIT = RNG.random((48, 64)) > 0.2
AIRLIGHT = np.array([0.3, 0.32, 0.35])
E_SUN, E_SKY = np.array([1.36, 1.14, 0.89]), np.array([0.16, 0.25, 0.44])


def test_fog_at_infinite_visibility_equals_no_fog():
    clear = shipped("clear_day")
    assert math.isinf(clear.fog_visibility_m) and clear.fog_extinction_per_m == 0.0
    assert apply_fog(RGB, DISTANCE, HIT, clear.fog_extinction_per_m, AIRLIGHT) is RGB
    sun, sky, airlight = fog_lighting(clear, E_SUN, E_SKY)
    assert (sun, sky) == (1.0, 1.0) and np.allclose(airlight, (E_SUN + E_SKY) / math.pi)
    # ... and fog thins continuously towards it: at 10^9 m visibility nothing visible changes.
    thin = dataclasses.replace(shipped("day_fog"), fog_visibility_m=1e9)
    assert np.abs(apply_fog(RGB, DISTANCE, HIT, thin.fog_extinction_per_m, AIRLIGHT) - RGB)[HIT].max() < 1e-5


def test_koschmieder_contrast_is_two_percent_at_the_visibility():
    beta = shipped("day_fog").fog_extinction_per_m
    black = np.zeros((1, 1, 3), np.float32)
    seen = apply_fog(black, np.array([[shipped("day_fog").fog_visibility_m]]), np.array([[True]]), beta, AIRLIGHT)
    assert np.allclose(1.0 - seen[0, 0] / AIRLIGHT, 0.02, atol=1e-4)
    sky = apply_fog(RGB, DISTANCE, HIT, beta, AIRLIGHT)
    assert np.allclose(sky[~HIT], AIRLIGHT)  # rays that escape see only fog


def test_fog_dims_the_sun_and_brightens_the_sky():
    sun, sky, _ = fog_lighting(shipped("day_fog"), E_SUN, E_SKY)
    assert sun < 0.1 and sky > 1.0
    # A non-absorbing layer sends part of the light back up: less reaches the ground than without fog.
    assert np.mean(sun * E_SUN + sky * E_SKY) < np.mean(E_SUN + E_SKY)


def test_marshall_palmer_and_atlas_fall_speed():
    density, lam = drop_density_per_m3(5.0, min_diameter_mm=0.0)
    assert lam == pytest.approx(4.1 * 5.0 ** -0.21) and density == pytest.approx(8000 / lam)
    assert terminal_speed_mps(np.array([2.0]))[0] == pytest.approx(9.65 - 10.3 * math.exp(-1.2))


def _camera():
    # Looking along +Y from 1.6 m: USD convention, the camera looks down its local -Z.
    m = np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 1.6], [0, 0, 0, 1]], float)
    return PinholeCamera("/Cam", 24.0, 36.0, 24.0, 0.1, 1000.0, m)


def test_rain_streaks_are_seeded_and_hidden_behind_surfaces():
    image = np.full((48, 64, 3), 0.1, np.float32)
    far = np.zeros((48, 64), np.float32)  # nothing hit: drops at every depth show
    a = rain_streaks(image, far, _camera(), 10.0, np.ones(3), np.random.default_rng(1))
    b = rain_streaks(image, far, _camera(), 10.0, np.ones(3), np.random.default_rng(1))
    assert np.array_equal(a, b) and (a > image).any()
    wall = np.full((48, 64), 0.5, np.float32)  # a surface 0.5 m away hides every drop (they start at 1 m)
    assert np.array_equal(rain_streaks(image, wall, _camera(), 10.0, np.ones(3), np.random.default_rng(1)), image)
    assert rain_streaks(image, far, _camera(), 0.0, np.ones(3), np.random.default_rng(1)) is image
    heavier = rain_streaks(image, far, _camera(), 40.0, np.ones(3), np.random.default_rng(1))
    assert (heavier - image).sum() > (a - image).sum()
