"""Procedural settings beyond the demo district, as plain data: rooms (corridor, hall, shop, clinic, lift lobby),
a park, and a street where a bus or a van has its wheelchair ramp down by a kerb ramp (the kinds of
:data:`synthua_usd.randomisation.settings.SETTING_KINDS`).

:func:`build_setting` makes the :class:`Setting` of a kind and variant (the variant seeds its builder: the same
pair gives the same twin, byte for byte once authored): a :class:`~synthua_usd.model.twin.TwinModel` with its
procedural textures (the district's, :mod:`synthua_usd.demo.district_textures`), and where cameras go in it
(:mod:`synthua_usd.demo.settings.cameras`). :mod:`synthua_usd.pipeline.setting_scenes` writes it as a scenario.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd.core.errors import InputError
from synthua_usd.demo.district_textures import add_textures
from synthua_usd.demo.settings import indoor, outdoor
from synthua_usd.demo.settings.layout import Layout
from synthua_usd.model.materials import subset
from synthua_usd.model.twin import TwinModel
from synthua_usd.randomisation.settings import INDOOR_KINDS, SETTING_KINDS

#: Kind -> builder of its layout from a seeded generator.
BUILDERS = {"corridor": indoor.corridor, "hall": indoor.hall, "shop": indoor.shop, "clinic": indoor.clinic,
            "lift_lobby": indoor.lift_lobby, "park": outdoor.park, "vehicle_ramp": outdoor.vehicle_ramp}
#: What a setting's twin layer says it is (``customLayerData`` ``synthua:source``), before its kind and variant.
SETTING_SOURCE = "synthua procedural setting"


@dataclass(frozen=True, eq=False)
class Setting:
    """One setting: its ``kind`` and ``variant``, its ``twin`` (textured) and its ``layout`` (where people stand
    and where cameras go)."""

    kind: str
    variant: int
    twin: TwinModel
    layout: Layout

    @property
    def indoor(self) -> bool:
        return self.kind in INDOOR_KINDS


def build_setting(kind: str, variant: int, textures: bool = True) -> Setting:
    """The setting ``kind`` (:data:`SETTING_KINDS`) of layout ``variant`` (an integer >= 0), textured unless
    ``textures`` is False."""
    if kind not in BUILDERS:
        raise InputError(f"setting kind {kind!r}; expected one of {', '.join(SETTING_KINDS)}")
    if isinstance(variant, bool) or not isinstance(variant, (int, np.integer)) or variant < 0:
        raise InputError(f"setting variant {variant!r}; expected an integer >= 0")
    rng = np.random.default_rng([SETTING_KINDS.index(kind), int(variant), 0x5E77])
    objects, layout = BUILDERS[kind](rng)
    model = TwinModel(objects=tuple(objects), materials=subset(p.material for o in objects for p in o.parts),
                      source=f"{SETTING_SOURCE} {kind} (variant {variant})", report={"kind": kind, "variant": variant})
    # the district's texture images for a seed of their own (their generator is seeded by it alone)
    seed = SETTING_KINDS.index(kind) * 1_000_003 + int(variant)
    return Setting(kind, int(variant), add_textures(model, seed) if textures else model, layout)
