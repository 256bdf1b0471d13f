"""Parametric low-poly people: height, build, skin and clothing vary; a walking pose whose legs and arms
swing about hip and shoulder pivots, and a seated pose for wheelchair users. The person faces +X with
the feet at z = 0 (standing) or sits on a seat 0.5 m high.

Skin tones span the Fitzpatrick range; proportions follow the usual eight-heads figure.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd import geometry as geo
from synthua_usd.materials import SHIRTS, SKINS, TROUSERS

#: Random looks come in steps of these, so that agents of one size share geometry (USD prototypes).
HEIGHT_STEP_M = 0.05
BUILD_STEP = 0.05


def _quantise(value: float, step: float) -> float:
    """``value`` rounded to a multiple of ``step``, as the float nearest that decimal (1.7, not 1.7000000000000002)."""
    return round(round(value / step) * step, 6)


@dataclass(frozen=True)
class PersonLook:
    """``height_m`` standing height; ``build`` width factor (1 = average)."""

    height_m: float
    build: float
    skin: str
    shirt: str
    trousers: str

    @classmethod
    def random(cls, rng: np.random.Generator) -> "PersonLook":
        """Height N(1.70, 0.09) m clipped to 1.45-1.98 m, build U(0.85, 1.25), both then rounded to
        :data:`HEIGHT_STEP_M` and :data:`BUILD_STEP` (rounding draws nothing: the rng stream is unchanged)."""
        height = float(np.clip(rng.normal(1.70, 0.09), 1.45, 1.98))
        build = float(rng.uniform(0.85, 1.25))
        return cls(height_m=_quantise(height, HEIGHT_STEP_M), build=_quantise(build, BUILD_STEP),
                   skin=SKINS[int(rng.integers(len(SKINS)))].key, shirt=SHIRTS[int(rng.integers(len(SHIRTS)))].key,
                   trousers=TROUSERS[int(rng.integers(len(TROUSERS)))].key)


@dataclass(frozen=True, eq=False)
class Limb:
    """A mesh in the limb's own frame (pivot at the origin, hanging down -Z) and where the pivot sits."""

    pivot: tuple[float, float, float]
    mesh: geo.Mesh
    material: str


@dataclass(frozen=True, eq=False)
class PersonGeometry:
    body: dict[str, tuple[geo.Mesh, str]]   # rigid parts: name -> (mesh, material)
    limbs: dict[str, Limb]                  # swinging parts (walking pose only)


def person(look: PersonLook, seated: bool = False) -> PersonGeometry:
    s = look.height_m / 1.75
    w = look.build
    leg_len, hip_z = 0.86 * s, 0.9 * s
    torso = (0.13 * s, 0.19 * s * w)  # half depth, half width
    head_r = 0.11 * s
    if seated:
        hip_z = 0.52
        shoulder_z = hip_z + 0.58 * s
        body = {
            "Torso": (geo.box((-torso[0] - 0.05, -torso[1], hip_z), (torso[0] - 0.05, torso[1], shoulder_z)), look.shirt),
            "Head": (geo.sphere((-0.03, 0.0, shoulder_z + 0.05 + head_r), head_r, 2), look.skin),
            "Legs": (geo.merge(geo.box((0.0, -0.17 * w, hip_z - 0.07), (0.45 * s, -0.02, hip_z + 0.08)),
                               geo.box((0.0, 0.02, hip_z - 0.07), (0.45 * s, 0.17 * w, hip_z + 0.08)),
                               geo.box((0.36 * s, -0.16 * w, 0.08), (0.47 * s, -0.04, hip_z - 0.07)),
                               geo.box((0.36 * s, 0.04, 0.08), (0.47 * s, 0.16 * w, hip_z - 0.07))), look.trousers),
            "Arms": (geo.merge(geo.box((-0.05, -torso[1] - 0.08, shoulder_z - 0.32 * s), (0.25, -torso[1], shoulder_z - 0.22 * s)),
                               geo.box((-0.05, torso[1], shoulder_z - 0.32 * s), (0.25, torso[1] + 0.08, shoulder_z - 0.22 * s))),
                     look.shirt),
        }
        return PersonGeometry(body, {})
    shoulder_z = hip_z + 0.55 * s
    body = {
        "Torso": (geo.box((-torso[0], -torso[1], hip_z - 0.05), (torso[0], torso[1], shoulder_z)), look.shirt),
        "Head": (geo.sphere((0.0, 0.0, shoulder_z + 0.04 + head_r), head_r, 2), look.skin),
    }
    leg = geo.box((-0.07 * s, -0.075 * w, -leg_len), (0.07 * s, 0.075 * w, 0.0))
    arm = geo.box((-0.045, -0.04 * w, -0.62 * s), (0.045, 0.04 * w, 0.0))
    hand = geo.sphere((0.0, 0.0, -0.66 * s), 0.045, 1)
    limbs = {
        "LegL": Limb((0.0, 0.09 * w, hip_z), leg, look.trousers),
        "LegR": Limb((0.0, -0.09 * w, hip_z), leg, look.trousers),
        "ArmL": Limb((0.0, torso[1] + 0.045 * w, shoulder_z - 0.03), geo.merge(arm, hand), look.shirt),
        "ArmR": Limb((0.0, -torso[1] - 0.045 * w, shoulder_z - 0.03), geo.merge(arm, hand), look.shirt),
    }
    return PersonGeometry(body, limbs)


def swing_deg(distance_m: np.ndarray, stride_m: float = 1.4, amplitude_deg: float = 22.0) -> np.ndarray:
    """Leg swing angle over the distance walked: one full cycle per stride (two steps)."""
    return amplitude_deg * np.sin(2.0 * np.pi * np.asarray(distance_m) / stride_m)
