"""Mobility aids: manual and electric wheelchairs, walker, crutch and the cane types of the taxonomy.

Sizes follow common products (ISO 7176 wheelchair envelopes; walkers ~0.6 m wide; canes 0.85-0.95 m).
Each device faces +X with its footprint centre at the origin on z = 0. Class names match the class map.
"""

from __future__ import annotations

import numpy as np

from synthua_usd import geometry as geo
from synthua_usd.twin import TwinPart


def manual_wheelchair() -> list[TwinPart]:
    """0.6 m push-rim rear wheels, casters, sling seat, backrest with push handles; ~0.65 x 1.0 m."""
    return [
        TwinPart.of("RearWheels", geo.merge(geo.cylinder((-0.1, -0.3, 0.3), 0.3, 0.03, axis="y", sections=24),
                                      geo.cylinder((-0.1, 0.3, 0.3), 0.3, 0.03, axis="y", sections=24)), "Tyre"),
        TwinPart.of("Casters", geo.merge(geo.cylinder((0.38, -0.22, 0.07), 0.07, 0.03, axis="y", sections=12),
                                   geo.cylinder((0.38, 0.22, 0.07), 0.07, 0.03, axis="y", sections=12)), "Tyre"),
        TwinPart.of("Seat", geo.merge(geo.box((-0.18, -0.24, 0.43), (0.3, 0.24, 0.45)),
                                geo.box((-0.2, -0.24, 0.45), (-0.18, 0.24, 0.95))), "Seat"),
        TwinPart.of("Frame", geo.merge(geo.box((-0.2, -0.26, 0.14), (0.42, -0.24, 0.45)),
                                 geo.box((-0.2, 0.24, 0.14), (0.42, 0.26, 0.45)),
                                 geo.box((0.36, -0.2, 0.08), (0.44, 0.2, 0.12)),
                                 geo.box((-0.3, -0.26, 0.9), (-0.2, -0.23, 0.93)),
                                 geo.box((-0.3, 0.23, 0.9), (-0.2, 0.26, 0.93))), "Frame"),
    ]


def electric_wheelchair() -> list[TwinPart]:
    """Power chair: battery base, six small wheels, captain seat, joystick arm; ~0.65 x 1.1 m."""
    wheels = [geo.cylinder((x, y, 0.15), 0.15 if x == 0.0 else 0.09, 0.08, axis="y", sections=16)
              for x in (-0.4, 0.0, 0.4) for y in (-0.28, 0.28)]
    return [
        TwinPart.of("Base", geo.box((-0.45, -0.25, 0.12), (0.45, 0.25, 0.35)), "Frame"),
        TwinPart.of("Wheels", geo.merge(*wheels), "Tyre"),
        TwinPart.of("Seat", geo.merge(geo.box((-0.25, -0.25, 0.4), (0.25, 0.25, 0.52)),
                                geo.box((-0.3, -0.25, 0.52), (-0.2, 0.25, 1.05))), "Seat"),
        TwinPart.of("Controls", geo.merge(geo.box((-0.1, 0.25, 0.55), (0.3, 0.3, 0.65)),
                                    geo.box((0.25, 0.25, 0.65), (0.3, 0.3, 0.75))), "Frame"),
    ]


def walker() -> list[TwinPart]:
    """Four-leg rollator frame, 0.6 m wide, 0.85 m handles, front wheels."""
    legs = [geo.box((x - 0.015, y - 0.015, 0.0), (x + 0.015, y + 0.015, 0.85)) for x in (-0.2, 0.2) for y in (-0.28, 0.28)]
    rails = [geo.box((-0.2, y - 0.015, 0.83), (0.2, y + 0.015, 0.86)) for y in (-0.28, 0.28)]
    return [TwinPart.of("Frame", geo.merge(*legs, *rails, geo.box((0.185, -0.28, 0.5), (0.215, 0.28, 0.53))), "Frame"),
            TwinPart.of("Wheels", geo.merge(*[geo.cylinder((0.2, y, 0.07), 0.07, 0.03, axis="y", sections=12)
                                        for y in (-0.28, 0.28)]), "Tyre")]


def crutch() -> list[TwinPart]:
    """Forearm crutch standing upright: shaft 1.0 m, handle and cuff."""
    return [TwinPart.of("Shaft", geo.merge(geo.cylinder((0, 0, 0.5), 0.012, 1.0, sections=8),
                                     geo.box((0.0, -0.012, 0.75), (0.12, 0.012, 0.78)),
                                     geo.box((-0.05, -0.04, 0.95), (0.0, 0.04, 1.02))), "Frame"),
            TwinPart.of("Tip", geo.cylinder((0, 0, 0.02), 0.02, 0.04, sections=8), "Tyre")]


def _cane(height: float, material: str, feet: int = 1) -> list[TwinPart]:
    shaft = geo.merge(geo.cylinder((0, 0, height / 2), 0.011, height, sections=8),
                      geo.box((-0.1, -0.012, height - 0.02), (0.02, 0.012, height + 0.01)))
    if feet == 1:
        return [TwinPart.of("Shaft", shaft, material)]
    spread = 0.08
    angles = np.linspace(0, 2 * np.pi, feet, endpoint=False)
    base = geo.merge(*[geo.box((spread * np.cos(a) - 0.01, spread * np.sin(a) - 0.01, 0.0),
                               (spread * np.cos(a) + 0.01, spread * np.sin(a) + 0.01, 0.12)) for a in angles],
                     geo.box((-spread, -spread, 0.1), (spread, spread, 0.13)))
    return [TwinPart.of("Shaft", shaft, material), TwinPart.of("Base", base, "Frame")]


def smart_cane() -> list[TwinPart]:
    """Long white cane (1.2 m) with a red band and sensor grip."""
    return [TwinPart.of("Shaft", geo.cylinder((0, 0, 0.6), 0.01, 1.2, sections=8), "CaneWhite"),
            TwinPart.of("Band", geo.cylinder((0, 0, 0.15), 0.011, 0.1, sections=8), "CaneRed"),
            TwinPart.of("Grip", geo.box((-0.02, -0.02, 1.15), (0.02, 0.02, 1.28)), "Frame")]


def wooden_cane() -> list[TwinPart]:
    return _cane(0.9, "Wood")


def orthopedic_cane() -> list[TwinPart]:
    """Adjustable aluminium cane with an offset handle."""
    return _cane(0.92, "Frame")


def tripod_cane() -> list[TwinPart]:
    return _cane(0.88, "Frame", feet=3)


#: class name → builder.
DEVICES = {
    "manual_wheelchair": manual_wheelchair,
    "electric_wheelchair": electric_wheelchair,
    "walker": walker,
    "crutch": crutch,
    "smart_cane": smart_cane,
    "wooden_cane": wooden_cane,
    "orthopedic_cane": orthopedic_cane,
    "tripod_cane": tripod_cane,
}
