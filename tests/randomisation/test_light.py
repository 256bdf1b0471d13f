"""The light of a randomised image: the sun's path, the condition's elevation band, the night kept dark."""

from __future__ import annotations

import math

import numpy as np
import pytest

from synthua_usd.model.conditions import shipped
from synthua_usd.randomisation.config import LightRandomisation
from synthua_usd.randomisation.light import LOW_SUN_BAND_DEG, draw_light, elevation_band, solar_position


def test_solar_position_against_known_suns():
    """Equinox (δ = 0 on day 80/81): the sun culminates at 90° − |φ| in the north for southern latitudes
    (Curitiba: 64.57°) and at the zenith on the equator; it rises in the east (azimuth 90°) at 6 h solar time;
    at the June solstice Curitiba's noon sun stands at 90° − 25.43° − 23.44° = 41.1° (the shipped snow sun)."""
    delta = math.radians(23.44) * math.sin(2 * math.pi * (284 + 81) / 365)
    assert abs(math.degrees(delta)) < 0.5
    el, az = solar_position(-25.43, 81, 12.0)
    assert el == pytest.approx(64.57 - math.degrees(delta), abs=0.01) and az == pytest.approx(0.0, abs=1e-6)
    el, az = solar_position(0.0, 81, 6.0)
    assert el == pytest.approx(0.0, abs=0.5) and az == pytest.approx(90.0, abs=0.5)
    el, _ = solar_position(-25.43, 172, 12.0)  # June solstice
    assert el == pytest.approx(41.1, abs=0.1)
    _, afternoon = solar_position(-25.43, 81, 15.0)
    assert 180.0 < afternoon < 360.0  # west of north in the afternoon


@pytest.mark.parametrize("name", ["clear_day", "sunset", "snow", "day_fog"])
def test_drawn_suns_stay_in_their_conditions_band(name):
    base = shipped(name)
    config = LightRandomisation()
    band = elevation_band(base, config.sun_band_deg)
    rng = np.random.default_rng(4)
    draws = [draw_light(rng, base, config) for _ in range(200)]
    elevations = np.array([d.sun_elevation_deg for d in draws])
    assert np.all((elevations >= band[0]) & (elevations <= band[1]))
    assert elevations.std() > 1.0 and len({round(d.sun_azimuth_deg) for d in draws}) > 30  # it does vary
    for d in draws:  # each sun is the one its date and hour put there
        assert (d.sun_elevation_deg, d.sun_azimuth_deg) == pytest.approx(
            solar_position(config.latitude_deg, d.day_of_year, d.solar_hour))
        assert -0.5 <= d.exposure_ev <= 0.5 and 1.5 <= d.turbidity <= 10
        condition = d.condition(base)
        assert condition.fog_visibility_m == base.fog_visibility_m and condition.snow_cover == base.snow_cover
    if name == "sunset":
        assert band == LOW_SUN_BAND_DEG


def test_night_keeps_the_sun_down_and_varies_the_sky():
    base = shipped("clear_night")
    draws = [draw_light(np.random.default_rng(k), base, LightRandomisation()) for k in range(50)]
    assert all(d.sun_elevation_deg == base.sun_elevation_deg and d.day_of_year is None for d in draws)
    skies = [d.night_sky_luminance_cd_m2 for d in draws]
    assert min(skies) >= 0.5 * base.night_sky_luminance_cd_m2 and max(skies) <= 2.0 * base.night_sky_luminance_cd_m2
    assert np.std(skies) > 0


def test_light_off_is_the_condition_as_it_is():
    base = shipped("clear_day")
    draw = draw_light(np.random.default_rng(0), base, LightRandomisation(enabled=False))
    assert draw.condition(base) == base and draw.exposure_ev == 0.0
