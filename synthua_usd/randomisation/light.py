"""The light of one randomised image: its condition with the sun placed by a date and a solar time, the sky's
turbidity and the night sky's luminance varied, and an exposure compensation.

The sun follows the date and the time of day at the config's latitude (the demo district's Curitiba by
default), so elevation and azimuth vary together as they do outdoors; a draw is kept only when the sun lies
in its condition's elevation band (:func:`elevation_band`), so a noon condition stays a day and a sunset a low
sun. Solar position: Cooper's declination δ = 23.44° sin(2π (284 + N) / 365) and the hour angle of local solar
time (no equation of time: about ±4° of azimuth, well inside the spread drawn). Conditions with the sun down
keep it down; their skyglow is scaled. Plain data: a :class:`LightDraw` and the :class:`Condition` it makes.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

from synthua_usd.model.conditions import Condition
from synthua_usd.randomisation.config import LightRandomisation

#: Conditions whose sun stands lower than this are low-sun conditions (sunset, sunrise): band LOW_SUN_BAND_DEG.
LOW_SUN_DEG = 10.0
LOW_SUN_BAND_DEG = (0.5, 10.0)
#: Solar hours a day draw spans (the sun is up within them at every latitude the config accepts).
HOURS = (4.0, 20.0)
#: Turbidity range of the Hosek-Wilkie sky model Mitsuba's sunsky implements.
TURBIDITY_RANGE = (1.5, 10.0)
#: Draws of (date, hour) before the condition's own sun is kept (a band the latitude cannot reach).
MAX_TRIES = 4000


def solar_position(latitude_deg: float, day_of_year: float, solar_hour: float) -> tuple[float, float]:
    """(elevation, azimuth) of the sun in degrees at ``latitude_deg`` on day ``day_of_year`` (1..365) at local
    solar time ``solar_hour`` (12 = solar noon); azimuth clockwise from north (0..360)."""
    phi = math.radians(latitude_deg)
    delta = math.radians(23.44) * math.sin(2 * math.pi * (284 + day_of_year) / 365)
    omega = math.radians(15.0 * (solar_hour - 12.0))
    sin_el = math.sin(phi) * math.sin(delta) + math.cos(phi) * math.cos(delta) * math.cos(omega)
    elevation = math.degrees(math.asin(max(-1.0, min(1.0, sin_el))))
    azimuth = math.degrees(math.atan2(-math.sin(omega), math.tan(delta) * math.cos(phi) - math.sin(phi) * math.cos(omega)))
    return elevation, azimuth % 360.0


def elevation_band(condition: Condition, band_deg: float) -> tuple[float, float] | None:
    """Sun elevations (degrees) a randomised ``condition`` may take: within ``band_deg`` of its own for a day
    condition (at least 5° up), :data:`LOW_SUN_BAND_DEG` for a low sun, None when its sun is down."""
    el = condition.sun_elevation_deg
    if el <= 0:
        return None
    if el < LOW_SUN_DEG:
        return LOW_SUN_BAND_DEG
    return max(5.0, el - band_deg), min(90.0, el + band_deg)


@dataclass(frozen=True)
class LightDraw:
    """What one image's light drew: the date (day of year) and solar hour of its sun (None with the sun down),
    the sun's elevation and azimuth, turbidity, night sky luminance and the exposure compensation (EV)."""

    day_of_year: float | None
    solar_hour: float | None
    sun_elevation_deg: float
    sun_azimuth_deg: float
    turbidity: float
    night_sky_luminance_cd_m2: float
    exposure_ev: float

    def condition(self, base: Condition) -> Condition:
        """``base`` with this draw's sun, turbidity and night sky."""
        return replace(base, sun_elevation_deg=self.sun_elevation_deg, sun_azimuth_deg=self.sun_azimuth_deg,
                       turbidity=self.turbidity, night_sky_luminance_cd_m2=self.night_sky_luminance_cd_m2)

    def to_dict(self) -> dict:
        return asdict(self)


def draw_light(rng: np.random.Generator, base: Condition, config: LightRandomisation) -> LightDraw:
    """The light of one image under ``base``; with ``config.enabled`` False, ``base`` as it is (no EV)."""
    if not config.enabled:
        return LightDraw(None, None, base.sun_elevation_deg, base.sun_azimuth_deg, base.turbidity,
                         base.night_sky_luminance_cd_m2, 0.0)
    day = hour = None
    elevation, azimuth = base.sun_elevation_deg, base.sun_azimuth_deg
    band = elevation_band(base, config.sun_band_deg)
    if band is not None:
        for _ in range(MAX_TRIES):
            d, h = float(rng.uniform(1.0, 365.0)), float(rng.uniform(*HOURS))
            el, az = solar_position(config.latitude_deg, d, h)
            if band[0] <= el <= band[1]:
                day, hour, elevation, azimuth = d, h, el, az
                break
    turbidity = float(np.clip(base.turbidity + rng.uniform(*config.turbidity_offset), *TURBIDITY_RANGE))
    night = base.night_sky_luminance_cd_m2
    if not base.sun_up:
        night = float(min(10.0, night * rng.uniform(*config.night_sky_factor)))
    ev = float(rng.uniform(*config.exposure_ev))
    return LightDraw(day, hour, float(elevation), float(azimuth), turbidity, night, ev)
