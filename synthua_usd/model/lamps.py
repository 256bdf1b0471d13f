"""The light sources of a twin as plain data: which meshes are lamps, how much light they give, and when
a condition (:mod:`synthua_usd.model.conditions`) turns them on.

A mesh's lamp role is its ``synthua:lamp`` attribute (vehicle assets author ``headlamp`` and
``taillamp`` on their lamp parts), else the role of its class (:data:`ROLE_BY_CLASS`: every luminaire is a
street lamp, every window can be lit from inside), so imported twins light up at night without extra
authoring. Backends make lamp meshes area emitters with the luminance given here; geometry, and so the
labels, never change.

Photometry (sources, rounded): a residential LED street luminaire gives 3 000–8 000 lm (5 000 lm here);
a halogen low-beam headlamp puts out about 1 000 lm; a tail lamp 4–17 cd (UN ECE R7), about 30 lm into its
hemisphere; a window lit from inside is seen at 10–50 cd/m² at night (20 cd/m² here); a 60 x 60 cm LED ceiling
panel of offices, shops and clinics gives 3 000–4 000 lm (3 000 lm here: one a 6–8 m² of floor gives the
300–500 lx that EN 12464-1 asks of such rooms). Colours: 3 000 K street LEDs, 2 700 K interiors, 4 000 K
headlamps and ceiling panels, red tail lamps.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

from synthua_usd.model.photometry import CCT_2700K, CCT_3000K, CCT_4000K, REC709_RED


@dataclass(frozen=True)
class LampKind:
    """One role of lamp meshes.

    ``flux_lm`` is the luminous flux of one lamp *instance* (the labelled object), spread evenly over the
    area of its meshes of this role, which then glow at L = Φ / (π A) cd/m² (a Lambertian emitter); when
    it is 0, every mesh of the role glows at ``luminance_cd_m2``. ``color`` is linear Rec.709 with unit
    luminance. ``switch`` names the :class:`~synthua_usd.model.conditions.Condition` field that turns it on;
    empty, the lamp is always on (a room's ceiling lights, whatever the weather outside).
    """

    role: str
    color: tuple[float, float, float]
    switch: str
    flux_lm: float = 0.0
    luminance_cd_m2: float = 0.0

    def luminance(self, instance_area_m2: float) -> float:
        """cd/m² of a lit mesh of an instance whose meshes of this role have ``instance_area_m2`` in all."""
        if self.flux_lm > 0.0:
            return self.flux_lm / (math.pi * max(instance_area_m2, 1e-6))
        return self.luminance_cd_m2


KINDS: dict[str, LampKind] = {k.role: k for k in (
    LampKind("street", CCT_3000K, "street_lights_on", flux_lm=5000.0),
    LampKind("window", CCT_2700K, "lit_window_fraction", luminance_cd_m2=20.0),
    LampKind("headlamp", CCT_4000K, "vehicle_lamps_on", flux_lm=2000.0),  # two lamps of ~1 000 lm
    LampKind("taillamp", REC709_RED, "vehicle_lamps_on", flux_lm=60.0),  # two lamps of ~30 lm
    LampKind("ceiling", CCT_4000K, "", flux_lm=3000.0),  # a room's lights: on under every condition
)}

#: The lamp role of meshes of a class that carry no ``synthua:lamp`` of their own.
ROLE_BY_CLASS = {"luminaire": "street", "window": "window"}


def lamp_role(authored: str, class_name: str) -> str:
    """The role of a mesh: its authored ``synthua:lamp`` value, else its class's role, else ''."""
    return authored or ROLE_BY_CLASS.get(class_name, "")


def window_is_lit(instance_path: str, fraction: float) -> bool:
    """Whether the window ``instance_path`` is among the lit ``fraction``: a fixed hash of the path (CRC-32)
    so the same windows stay lit across frames, cameras and runs, and more of them as ``fraction`` grows."""
    return zlib.crc32(instance_path.encode("utf-8")) / 2.0**32 < fraction


def is_on(kind: LampKind, condition, instance_path: str) -> bool:
    """Whether lamps of ``kind`` on the instance ``instance_path`` shine under ``condition``."""
    if not kind.switch:
        return True
    value = getattr(condition, kind.switch)
    if isinstance(value, bool):
        return value
    return window_is_lit(instance_path, float(value))
