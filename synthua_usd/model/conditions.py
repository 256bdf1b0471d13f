"""Weather and light conditions as plain data: the one module that defines what a condition is and which
conditions synthua ships.

A :class:`Condition` holds physical parameters only; :mod:`synthua_usd.usd.conditions` authors them as a
``condition`` variant set on the environment prim and reads the composed values back, and the Mitsuba
backend (:mod:`synthua_usd.backends.mitsuba.weather_scene`, :mod:`synthua_usd.backends.weather`) turns them
into emitters, surfaces, fog and rain. Nothing here knows USD or a renderer.

Frames: world Z up (Y-up stages are handled by :meth:`Condition.sun_direction`); azimuth is measured
clockwise from north (+Y on Z-up stages) towards east (+X); elevation above the horizon.
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from synthua_usd.core.errors import InputError

#: Koschmieder's constant: meteorological visibility is where a black object's contrast against the
#: horizon falls to 2 %, so the extinction coefficient is β = −ln(0.02) / V = 3.912 / V.
KOSCHMIEDER = -math.log(0.02)
#: Classes whose upward-facing faces get wet in rain (paved ground; roofs and grass are left dry-looking).
WET_GROUND_CLASSES = ("road", "street_road", "sidewalk", "curb_ramp", "crosswalk", "cover")
#: Classes that never carry snow: people and the aids they use move and shed it.
SNOW_FREE_CLASSES = ("person", "manual_wheelchair", "electric_wheelchair", "walker", "crutch", "smart_cane",
                     "wooden_cane", "orthopedic_cane", "tripod_cane")
#: Upward-facing: the face normal within this angle of the up axis.
WET_MAX_SLOPE_DEG = 30.0
#: Snow lies fully on faces up to the first slope and not at all beyond the second (linear in between).
SNOW_SLOPE_DEG = (30.0, 60.0)

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class Condition:
    """One weather and light condition.

    Attributes
    ----------
    name : str
        Identifier, also the USD variant name (letters, digits, underscores).
    description : str
        One line for people.
    sun_elevation_deg : float
        Sun above the horizon, degrees (−90..90). At or below 0 the sun and the daylight sky are off and
        the sky is a uniform dome of ``night_sky_luminance_cd_m2``.
    sun_azimuth_deg : float
        Clockwise from north towards east, degrees (0..360).
    turbidity : float
        Linke-type sky turbidity of the Hosek–Wilkie sky model, 1..10 (2 very clear, 3 clear, 6+ hazy).
    fog_visibility_m : float
        Meteorological visibility in metres; ``inf`` is no fog. Extinction β = 3.912 / V.
    fog_top_m : float
        Thickness of the fog (or rain-cloud) layer above the ground, metres: the sun's beam crosses it.
    rain_rate_mm_per_h : float
        Rain rate, mm/h (0 none, 2.5 light/moderate, 7.6+ heavy); sets the drop density of rain streaks.
    ground_wetness : float
        0 dry .. 1 soaked, on upward-facing faces of :data:`WET_GROUND_CLASSES`.
    snow_cover : float
        0 none .. 1 full, on upward-facing faces of every surface.
    street_lights_on, vehicle_lamps_on : bool
        Luminaires (class ``luminaire``) and vehicle head and tail lamps emit light.
    lit_window_fraction : float
        Share of windows lit from inside, 0..1 (which ones is fixed per window, see :mod:`synthua_usd.model.lamps`).
    night_sky_luminance_cd_m2 : float
        Luminance of the uniform night sky (skyglow), cd/m²; used only when the sun is down.
    """

    name: str
    description: str = ""
    sun_elevation_deg: float = 64.6
    sun_azimuth_deg: float = 0.0
    turbidity: float = 3.0
    fog_visibility_m: float = math.inf
    fog_top_m: float = 0.0
    rain_rate_mm_per_h: float = 0.0
    ground_wetness: float = 0.0
    snow_cover: float = 0.0
    street_lights_on: bool = False
    vehicle_lamps_on: bool = False
    lit_window_fraction: float = 0.0
    night_sky_luminance_cd_m2: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not _NAME.match(self.name):
            raise InputError(f"condition name should be letters, digits and underscores, but was {self.name!r}")
        ranges = {"sun_elevation_deg": (-90.0, 90.0), "sun_azimuth_deg": (0.0, 360.0), "turbidity": (1.0, 10.0),
                  "fog_top_m": (0.0, 20_000.0), "rain_rate_mm_per_h": (0.0, 500.0), "ground_wetness": (0.0, 1.0),
                  "snow_cover": (0.0, 1.0), "lit_window_fraction": (0.0, 1.0),
                  "night_sky_luminance_cd_m2": (0.0, 10.0)}
        for key, (lo, hi) in ranges.items():
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not lo <= value <= hi:
                raise InputError(f"condition {self.name}: {key} should be a number in [{lo:g}, {hi:g}], "
                                 f"but was {value!r}")
        v = self.fog_visibility_m
        if isinstance(v, bool) or not isinstance(v, (int, float)) or math.isnan(v) or v <= 0:
            raise InputError(f"condition {self.name}: fog_visibility_m should be > 0 metres (inf for no fog), "
                             f"but was {v!r}")
        for key in ("street_lights_on", "vehicle_lamps_on"):
            if not isinstance(getattr(self, key), bool):
                raise InputError(f"condition {self.name}: {key} should be true or false, "
                                 f"but was {getattr(self, key)!r}")

    @classmethod
    def from_dict(cls, data: dict) -> "Condition":
        known = [f.name for f in fields(cls)]
        unknown = sorted(set(data) - set(known))
        if unknown:
            raise InputError(f"condition: unknown keys {unknown}; known keys: {known}")
        return cls(**data)

    def to_dict(self) -> dict:
        """Plain values for JSON (``fog_visibility_m`` inf becomes null, since JSON has no infinity)."""
        out = asdict(self)
        if math.isinf(out["fog_visibility_m"]):
            out["fog_visibility_m"] = None
        return out

    @property
    def sun_up(self) -> bool:
        return self.sun_elevation_deg > 0.0

    @property
    def fog_extinction_per_m(self) -> float:
        """β = 3.912 / visibility, 1/m (0 without fog)."""
        return 0.0 if math.isinf(self.fog_visibility_m) else KOSCHMIEDER / self.fog_visibility_m

    def sun_direction(self, up_axis: str = "Z") -> np.ndarray:
        """(3,) float64 unit world vector from the scene towards the sun. Z up: x east, y north; Y up:
        x east, z south (right-handed)."""
        el, az = math.radians(self.sun_elevation_deg), math.radians(self.sun_azimuth_deg)
        east, north, up = math.cos(el) * math.sin(az), math.cos(el) * math.cos(az), math.sin(el)
        if up_axis == "Y":
            return np.array([east, up, -north])
        return np.array([east, north, up])


# --- the shipped conditions ------------------------------------------------------------------------------
# Sun angles are those of the demo district's place, Curitiba (latitude φ = −25.43°), with +Y north:
# noon elevation 90° − |φ − δ| (declination δ = 0 at the equinox: 64.6°; δ = +23.44° at the June solstice,
# Curitiba's winter: 41.1°), azimuth 0° (the noon sun is to the north south of the tropic); sunset
# azimuth 360° − arccos(sin δ / cos φ) = 296.1° at the June solstice (sunrise would be at 63.9°).
# Night skies: 0.01 cd/m² is a bright suburban sky (≈ 17.6 mag/arcsec²); overcast city skies reflect
# street light back and are brighter (0.03).

NOON_ELEVATION_DEG = 64.6

SHIPPED: tuple[Condition, ...] = (
    Condition("clear_day", "clear sky, equinox noon", sun_elevation_deg=NOON_ELEVATION_DEG, turbidity=3.0),
    Condition("day_fog", "radiation fog, 150 m visibility, 100 m deep, at noon",
              sun_elevation_deg=NOON_ELEVATION_DEG, turbidity=3.0, fog_visibility_m=150.0, fog_top_m=100.0,
              vehicle_lamps_on=True),
    Condition("day_rain_fog", "heavy rain (8 mm/h) under 800 m of rain cloud, 500 m visibility, wet ground",
              sun_elevation_deg=NOON_ELEVATION_DEG, turbidity=3.0, fog_visibility_m=500.0, fog_top_m=800.0,
              rain_rate_mm_per_h=8.0, ground_wetness=1.0, vehicle_lamps_on=True),
    Condition("clear_night", "clear night lit by street lights, vehicle lamps and 40 % of windows",
              sun_elevation_deg=-30.0, turbidity=3.0, street_lights_on=True, vehicle_lamps_on=True,
              lit_window_fraction=0.4, night_sky_luminance_cd_m2=0.01),
    Condition("night_rain_fog", "rain (5 mm/h) at night, 300 m visibility, wet ground, street lights on",
              sun_elevation_deg=-30.0, turbidity=3.0, fog_visibility_m=300.0, fog_top_m=800.0,
              rain_rate_mm_per_h=5.0, ground_wetness=1.0, street_lights_on=True, vehicle_lamps_on=True,
              lit_window_fraction=0.4, night_sky_luminance_cd_m2=0.03),
    Condition("sunset", "sun 3 degrees above the west-north-west horizon (June solstice sunset)",
              sun_elevation_deg=3.0, sun_azimuth_deg=296.1, turbidity=4.0),
    Condition("snow", "fresh snow on every upward-facing surface, clear winter noon",
              sun_elevation_deg=41.1, turbidity=2.5, snow_cover=1.0),
)
DEFAULT_CONDITION = "clear_day"


def shipped(name: str) -> Condition:
    """The shipped condition ``name``; an :class:`InputError` lists the known ones."""
    for condition in SHIPPED:
        if condition.name == name:
            return condition
    raise InputError(f"no shipped condition '{name}'; known: {', '.join(c.name for c in SHIPPED)}")


def display_order(names) -> list[str]:
    """``names`` with the shipped conditions first, in their order (the paper's five, then sunset and
    snow), then any others sorted: the order of listings and contact sheets."""
    rank = {c.name: k for k, c in enumerate(SHIPPED)}
    return sorted(names, key=lambda n: (rank.get(n, len(rank)), n))


def indoors(condition: Condition) -> Condition:
    """``condition`` as it is inside a closed room (the procedural indoor settings, :mod:`synthua_usd.demo.settings`),
    under the same name: no outdoor weather (fog, rain, wet ground, snow), no window lit from inside (a window seen
    from the room shows what is beyond it, not a lamp), and no sky: the room's doors are shut and its windows glazed
    (opaque panes), so neither the sun nor the sky lights anything inside, and they are put out (the sun below the
    horizon, a black night sky) so that a renderer spends its light samples on the room's own lights, which are on
    under every condition (:mod:`synthua_usd.model.lamps`, role ``ceiling``). Measured before they were put out:
    with the sun up, a renderer sampling the sun and sky by their outdoor illuminance left 78 % of a room's pixels
    black at 4 spp."""
    return replace(condition, description=f"{condition.description} (indoors: lit by the room's lights; no sky, fog, "
                                          f"rain, wet ground or snow)",
                   sun_elevation_deg=-90.0, night_sky_luminance_cd_m2=0.0, fog_visibility_m=math.inf, fog_top_m=0.0,
                   rain_rate_mm_per_h=0.0, ground_wetness=0.0, snow_cover=0.0, lit_window_fraction=0.0)
