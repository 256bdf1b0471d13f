"""Mobility aids: manual and electric wheelchairs, walker, crutch and the cane types of the taxonomy.

Sizes follow common products (ISO 7176 wheelchair envelopes; walkers ~0.6 m wide); seat height and width
and grip heights are fitted to the user (:class:`synthua_usd.assets.postures.DeviceFit`; the defaults are an
average adult's). Each device faces +X with its footprint centre at the origin on z = 0. Class names match
the class map.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.assets.postures import DeviceFit
from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart


def manual_wheelchair(fit: DeviceFit = DeviceFit()) -> list[TwinPart]:
    """0.6 m push-rim rear wheels beside the seat, casters, sling seat (its top at the fitted seat height),
    backrest with push handles; ~(seat width + 0.2) x 1.0 m."""
    h, w = fit.seat_height_m, fit.seat_width_m / 2
    wheel = w + 0.06
    return [
        TwinPart.of("RearWheels", geo.merge(geo.cylinder((-0.1, -wheel, 0.3), 0.3, 0.03, axis="y", sections=24),
                                      geo.cylinder((-0.1, wheel, 0.3), 0.3, 0.03, axis="y", sections=24)), "Tyre"),
        TwinPart.of("Casters", geo.merge(geo.cylinder((0.38, -w + 0.02, 0.07), 0.07, 0.03, axis="y", sections=12),
                                   geo.cylinder((0.38, w - 0.02, 0.07), 0.07, 0.03, axis="y", sections=12)), "Tyre"),
        TwinPart.of("Seat", geo.merge(geo.box((-0.18, -w, h - 0.02), (0.3, w, h)),
                                geo.box((-0.2, -w, h), (-0.18, w, h + 0.5))), "Seat"),
        TwinPart.of("Frame", geo.merge(geo.box((-0.2, -w - 0.02, 0.14), (0.42, -w, h)),
                                 geo.box((-0.2, w, 0.14), (0.42, w + 0.02, h)),
                                 geo.box((0.36, -w + 0.04, 0.08), (0.44, w - 0.04, 0.12)),
                                 geo.box((-0.3, -w - 0.02, h + 0.45), (-0.2, -w + 0.01, h + 0.48)),
                                 geo.box((-0.3, w - 0.01, h + 0.45), (-0.2, w + 0.02, h + 0.48))), "Frame"),
    ]


def electric_wheelchair(fit: DeviceFit = DeviceFit(seat_height_m=0.52, seat_width_m=0.5)) -> list[TwinPart]:
    """Power chair: battery base, six small wheels, captain seat (top at the fitted seat height), joystick
    arm on the user's left with the knob 0.25 m above the seat; ~0.65 x 1.1 m."""
    h, w = fit.seat_height_m, fit.seat_width_m / 2
    wheels = [geo.cylinder((x, y, 0.15), 0.15 if x == 0.0 else 0.09, 0.08, axis="y", sections=16)
              for x in (-0.4, 0.0, 0.4) for y in (-0.28, 0.28)]
    return [
        TwinPart.of("Base", geo.box((-0.45, -0.25, 0.12), (0.25, 0.25, 0.35)), "Frame"),
        TwinPart.of("Wheels", geo.merge(*wheels), "Tyre"),
        TwinPart.of("Seat", geo.merge(geo.box((-0.25, -w, 0.35), (0.25, w, h)),
                                geo.box((-0.3, -w, h), (-0.2, w, h + 0.53))), "Seat"),
        TwinPart.of("Controls", geo.merge(geo.box((-0.1, w + 0.01, h + 0.06), (0.3, w + 0.06, h + 0.1)),
                                    geo.box((0.25, w + 0.01, h + 0.1), (0.3, w + 0.06, h + 0.25))), "Frame"),
    ]


def walker(fit: DeviceFit = DeviceFit()) -> list[TwinPart]:
    """Four-leg rollator frame, 0.6 m wide, handles at the fitted grip height, front wheels."""
    g = fit.grip_height_m
    legs = [geo.box((x - 0.015, y - 0.015, 0.0), (x + 0.015, y + 0.015, g)) for x in (-0.2, 0.2) for y in (-0.28, 0.28)]
    rails = [geo.box((-0.2, y - 0.015, g - 0.02), (0.2, y + 0.015, g + 0.01)) for y in (-0.28, 0.28)]
    return [TwinPart.of("Frame", geo.merge(*legs, *rails, geo.box((0.185, -0.28, 0.5), (0.215, 0.28, 0.53))), "Frame"),
            TwinPart.of("Wheels", geo.merge(*[geo.cylinder((0.2, y, 0.07), 0.07, 0.03, axis="y", sections=12)
                                        for y in (-0.28, 0.28)]), "Tyre")]


def crutch(fit: DeviceFit = DeviceFit(grip_height_m=0.76)) -> list[TwinPart]:
    """Forearm crutch standing upright: grip at the fitted height, shaft on to the cuff 0.22 m above it."""
    g = fit.grip_height_m
    return [TwinPart.of("Shaft", geo.merge(geo.cylinder((0, 0, (g + 0.25) / 2), 0.012, g + 0.25, sections=8),
                                     geo.box((0.0, -0.012, g - 0.03), (0.12, 0.012, g)),
                                     geo.box((-0.05, -0.04, g + 0.17), (0.0, 0.04, g + 0.24))), "Frame"),
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


def smart_cane(fit: DeviceFit = DeviceFit()) -> list[TwinPart]:
    """Long white cane held upright (its grip at the fitted height) with a red band and sensor grip."""
    g = fit.grip_height_m
    return [TwinPart.of("Shaft", geo.cylinder((0, 0, (g - 0.05) / 2), 0.01, g - 0.05, sections=8), "CaneWhite"),
            TwinPart.of("Band", geo.cylinder((0, 0, 0.15), 0.011, 0.1, sections=8), "CaneRed"),
            TwinPart.of("Grip", geo.box((-0.02, -0.02, g - 0.08), (0.02, 0.02, g + 0.05)), "Frame")]


def wooden_cane(fit: DeviceFit = DeviceFit(grip_height_m=0.9)) -> list[TwinPart]:
    return _cane(fit.grip_height_m, "Wood")


def orthopedic_cane(fit: DeviceFit = DeviceFit(grip_height_m=0.92)) -> list[TwinPart]:
    """Adjustable aluminium cane with an offset handle."""
    return _cane(fit.grip_height_m, "Frame")


def tripod_cane(fit: DeviceFit = DeviceFit(grip_height_m=0.88)) -> list[TwinPart]:
    return _cane(fit.grip_height_m, "Frame", feet=3)


#: class name → builder of its standard model.
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

#: class name → {model name: builder}: the models a randomised scene draws among (one per class so far).
DEVICE_MODELS = {name: {"standard": builder} for name, builder in DEVICES.items()}
