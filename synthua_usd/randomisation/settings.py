"""Which setting a randomised scene is in: the scenario's own twin (its district), or a procedural setting built
for the scene (:mod:`synthua_usd.demo.settings`): an indoor room (corridor, hall, shop, clinic, lift lobby), a
park, or a street where a bus or a van has its ramp down by a kerb ramp.

The ``settings`` part of the ``randomise`` block (:class:`SettingsRandomisation`) is drawn once per scene (seed)
from a stream of its own (``setting``, :mod:`synthua_usd.randomisation.streams`), so turning it on moves no other
draw: with probability ``district_share`` the scene stays in the district, else it is one of ``variants``
layouts of a kind drawn uniformly among ``kinds``. A (kind, variant) is a complete scenario, written once into
the dataset and shared by every seed that draws it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from synthua_usd.core.errors import InputError

#: Every procedural setting, in the order the schema lists them.
SETTING_KINDS = ("corridor", "hall", "shop", "clinic", "lift_lobby", "park", "vehicle_ramp")
#: The settings that are closed rooms: lit by their own lights under any condition, without outdoor weather
#: (:func:`synthua_usd.model.conditions.indoors`).
INDOOR_KINDS = ("corridor", "hall", "shop", "clinic", "lift_lobby")
#: Most layouts of one kind a config may ask for (each one drawn is a scenario written into the dataset).
MAX_VARIANTS = 10_000
#: In a setting, nobody is placed within this horizontal distance (plus their own radius) of the view's camera,
#: metres: its cameras stand on the floors people walk, and a person at the lens fills the frame (a room's CCTV
#: hangs only 2-3 m up).
CAMERA_CLEARANCE_M = 1.5


@dataclass(frozen=True)
class SettingsRandomisation:
    """Scenes in procedural settings as well as in the district: a scene stays in the district (the scenario's own
    twin, or the district the ``district`` part draws) with probability ``district_share``, else it is in one of
    ``variants`` layouts of a setting kind drawn uniformly among ``kinds``. Off by default: a config that does not
    ask for it renders as before."""

    enabled: bool = False
    kinds: tuple[str, ...] = SETTING_KINDS
    district_share: float = 0.25
    variants: int = 8

    def __post_init__(self) -> None:
        from synthua_usd.randomisation.config import names_among

        object.__setattr__(self, "kinds", names_among("settings.kinds", self.kinds, SETTING_KINDS))
        share = self.district_share
        if isinstance(share, bool) or not isinstance(share, (int, float)) or not (math.isfinite(share)
                                                                                    and 0.0 <= share <= 1.0):
            raise InputError(f"settings.district_share: {share!r}; expected a share in [0, 1]")
        object.__setattr__(self, "district_share", float(share))
        if isinstance(self.variants, bool) or not isinstance(self.variants, int) or not 1 <= self.variants <= MAX_VARIANTS:
            raise InputError(f"settings.variants: {self.variants!r}; expected a whole number of layouts per kind in "
                             f"[1, {MAX_VARIANTS}]")


@dataclass(frozen=True, order=True)
class SettingDraw:
    """The setting of one scene: its ``kind`` (:data:`SETTING_KINDS`) and ``variant`` (which layout of the kind,
    the seed of its builder)."""

    kind: str
    variant: int

    @property
    def indoor(self) -> bool:
        return self.kind in INDOOR_KINDS

    def to_dict(self) -> dict:
        return {"kind": self.kind, "variant": self.variant, "indoor": self.indoor}


def draw_setting(rng: np.random.Generator, config: SettingsRandomisation) -> SettingDraw | None:
    """The setting of a scene, or None when it stays in the district (``rng`` the scene's ``setting`` stream).
    Always three numbers of ``rng``, whatever is drawn: the share, the kind, the variant."""
    u = float(rng.random())
    kind = config.kinds[int(rng.integers(len(config.kinds)))]
    variant = int(rng.integers(config.variants))
    if u < config.district_share:
        return None
    return SettingDraw(kind, variant)
