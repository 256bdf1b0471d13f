"""Mobility aids: manual and electric wheelchairs, walker, crutch and the cane types of the taxonomy.

Sizes follow common products (ISO 7176 wheelchair envelopes; walkers ~0.6 m wide); seat height and width
and grip heights are fitted to the user (:class:`synthua_usd.assets.postures.DeviceFit`; the defaults are an
average adult's). Each device faces +X with its footprint centre at the origin on z = 0. Class names match
the class map.

Each class has a ``standard`` low-poly model (what the plain crowd and the committed stages use) and a
``detailed`` one with the parts a detector trained on photos knows (spoked wheels, tyres, tubes, grips,
ferrules), under :data:`MAX_TRIANGLES`; randomised scenes draw among both (:data:`DEVICE_MODELS`). Both keep
the fit: seat tops at the fitted seat height and width, grips at the fitted grip height where the posture
puts the hands (:mod:`synthua_usd.assets.postures`), tips at the origin.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.assets.postures import REAR_WHEEL_X, RIM_RADIUS_M, DeviceFit
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


#: Most triangles a detailed model has (all its parts together): what keeps a crowd's render time.
MAX_TRIANGLES = 6000
#: Radius of the detailed models' frame tubes, m (22-25 mm aluminium tube).
TUBE_M = 0.012


def _tubes(radius: float, *polylines, sections: int = 8) -> geo.Mesh:
    return geo.merge(*[geo.tube(line, radius, sections) for line in polylines])


def _arc(centre, radius: float, start_deg: float, stop_deg: float, count: int, plane: str = "xz") -> np.ndarray:
    """``count`` points on a circular arc about ``centre`` in ``plane`` ("xz" or "xy"), angles from the first
    axis towards the second."""
    a = np.radians(np.linspace(start_deg, stop_deg, count))
    offsets = np.zeros((count, 3))
    offsets[:, 0], offsets[:, 2 if plane == "xz" else 1] = radius * np.cos(a), radius * np.sin(a)
    return np.asarray(centre, float) + offsets


def _spoked_wheel(x: float, y: float, radius: float, spokes: int, dish: float,
                  tyre_m: float | None = None) -> tuple[geo.Mesh, geo.Mesh]:
    """(tyre, rim with hub and spokes) of a wheel of outer ``radius`` touching the ground at (x, y), axle
    along y; spokes laced to both hub flanges ``dish`` apart; the tyre's section radius ``tyre_m`` (default
    5 % of ``radius``)."""
    tyre_r = 0.05 * radius if tyre_m is None else tyre_m
    centre = (x, y, radius)
    tyre = geo.torus(centre, radius - tyre_r, tyre_r, axis="y", major_sections=32, minor_sections=8)
    rim_r = radius - 2 * tyre_r
    lines = []
    for k in range(spokes):
        a = 2 * np.pi * k / spokes
        flange = y + (dish / 2 if k % 2 else -dish / 2)
        lines.append([(x + 0.025 * np.cos(a), flange, radius + 0.025 * np.sin(a)),
                      (x + rim_r * np.cos(a + 0.3), y, radius + rim_r * np.sin(a + 0.3))])
    rim = geo.merge(geo.torus(centre, rim_r, 0.009, axis="y", major_sections=32, minor_sections=6),
                    geo.cylinder(centre, 0.03, dish + 0.03, axis="y", sections=12), _tubes(0.002, *lines, sections=4))
    return tyre, rim


def _caster(x: float, y: float, radius: float, stem_top: float) -> tuple[geo.Mesh, geo.Mesh]:
    """(tyre, fork with hub) of a swivel caster touching the ground at (x, y); the fork's stem 3 cm behind
    the axle (trail) rising to ``stem_top``."""
    tyre_r = 0.22 * radius
    tyre = geo.torus((x, y, radius), radius - tyre_r, tyre_r, axis="y", major_sections=16, minor_sections=6)
    crown = radius * 2 + 0.02
    fork = _tubes(0.006, *[[(x, y + s * 0.025, radius), (x - 0.03, y + s * 0.025, crown)] for s in (-1, 1)],
                  [(x - 0.03, y - 0.03, crown), (x - 0.03, y + 0.03, crown)], [(x - 0.03, y, crown), (x - 0.03, y, stem_top)],
                  sections=6)
    return tyre, geo.merge(fork, geo.cylinder((x, y, radius), 0.4 * radius, 0.045, axis="y", sections=10))


def manual_wheelchair_detailed(fit: DeviceFit = DeviceFit()) -> list[TwinPart]:
    """Folding manual wheelchair, as the standard steel chairs of hospitals and streets: 0.6 m rear wheels of
    24 spokes with pneumatic tyres (36 mm) and push rims (where the posture's hands push), 0.14 m casters on
    forks, a tubular frame with a cross brace, an upholstered seat (its top at the fitted seat height, its
    width the fitted width) and backrest, padded armrests on posts with clothing guards under them between
    seat and wheel, push handles, two footplates under the feet. Upholstery, pads and guards take the seat's
    fabric."""
    h, w = fit.seat_height_m, fit.seat_width_m / 2
    side, wheel, push = w + 0.015, w + 0.06, w + 0.095
    tyres, rims, casters, forks, frame, grips, upholstery = [], [], [], [], [], [], []
    for s in (-1, 1):
        tyre, rim = _spoked_wheel(REAR_WHEEL_X, s * wheel, 0.3, 24, 0.05, tyre_m=0.018)
        standoffs = [[(REAR_WHEEL_X + 0.25 * np.cos(a), s * (wheel + 0.01), 0.3 + 0.25 * np.sin(a)),
                      (REAR_WHEEL_X + RIM_RADIUS_M * np.cos(a), s * push, 0.3 + RIM_RADIUS_M * np.sin(a))]
                     for a in np.linspace(0, 2 * np.pi, 6, endpoint=False) + 0.2]
        rims += [rim, geo.torus((REAR_WHEEL_X, s * push, 0.3), RIM_RADIUS_M, 0.008, axis="y", major_sections=32,
                                minor_sections=6), _tubes(0.004, *standoffs, sections=4)]
        tyres.append(tyre)
        tyre, fork = _caster(0.4, s * side, 0.07, 0.24)
        casters.append(tyre)
        forks.append(fork)
        y = s * side
        frame.append(_tubes(TUBE_M, [(-0.19, y, 0.24), (-0.2, y, h + 0.38), (-0.24, y, h + 0.44), (-0.27, y, h + 0.45)],
                            [(-0.19, y, 0.24), (0.37, y, 0.24)], [(-0.2, y, h - 0.03), (0.3, y, h - 0.03), (0.44, y, 0.1)],
                            [(0.37, y, 0.22), (0.37, y, 0.26)], [(REAR_WHEEL_X, y, 0.24), (REAR_WHEEL_X, s * (wheel - 0.03), 0.3)]))
        grips.append(geo.tube([(-0.26, y, h + 0.45), (-0.36, y, h + 0.45)], 0.016, 8))
        frame.append(geo.box((0.32, min(s * 0.01, s * (w + 0.01)), 0.055), (0.5, max(s * 0.01, s * (w + 0.01)), 0.07)))
        frame.append(_tubes(TUBE_M, *[[(x, y, h - 0.03), (x, y, h + 0.2)] for x in (-0.14, 0.16)]))  # armrest posts
        pad, guard = sorted((s * (w + 0.005), s * (w + 0.065))), sorted((s * (w + 0.025), s * (w + 0.035)))
        upholstery += [geo.box((-0.18, pad[0], h + 0.2), (0.2, pad[1], h + 0.24)),  # armrest pad
                       geo.box((-0.15, guard[0], h - 0.01), (0.13, guard[1], h + 0.2))]  # clothing guard
    frame.append(_tubes(0.01, [(0.0, -side, 0.25), (0.0, side, h - 0.04)], [(0.0, side, 0.25), (0.0, -side, h - 0.04)]))
    return [
        TwinPart.of("RearWheels", geo.merge(*tyres), "Tyre"),
        TwinPart.of("Rims", geo.merge(*rims), "Frame"),
        TwinPart.of("Casters", geo.merge(*casters), "Tyre"),
        TwinPart.of("Seat", geo.merge(geo.box((-0.18, -w, h - 0.04), (0.3, w, h)),
                                      geo.box((-0.22, -w, h + 0.04), (-0.185, w, h + 0.44)), *upholstery), "Seat"),
        TwinPart.of("Frame", geo.merge(*frame, *forks), "Frame"),
        TwinPart.of("Grips", geo.merge(*grips), "Tyre"),
    ]


def electric_wheelchair_detailed(fit: DeviceFit = DeviceFit(seat_height_m=0.52, seat_width_m=0.5)) -> list[TwinPart]:
    """Mid-wheel-drive power chair: 0.34 m drive wheels and four 0.16 m casters around a battery base, a
    captain seat (cushion top at the fitted seat height and width) with armrests, backrest and headrest,
    the joystick box on the left armrest under the posture's left hand, a footplate under the feet."""
    h, w = fit.seat_height_m, fit.seat_width_m / 2
    tyres, hubs = [], []
    for s in (-1, 1):
        tyres.append(geo.torus((0.0, s * 0.27, 0.17), 0.14, 0.03, axis="y", major_sections=24, minor_sections=8))
        hubs.append(geo.cylinder((0.0, s * 0.27, 0.17), 0.1, 0.05, axis="y", sections=16))
        for x in (-0.38, 0.36):
            tyre, fork = _caster(x, s * 0.2, 0.08, 0.2)
            tyres.append(tyre)
            hubs.append(fork)
    pan = min(0.34, h - 0.1)
    armrests = [geo.box((-0.16, min(s * (w + 0.01), s * (w + 0.07)), h + 0.2), (0.2, max(s * (w + 0.01), s * (w + 0.07)), h + 0.23))
                for s in (-1, 1)]
    posts = [[(x, s * (w + 0.04), pan), (x, s * (w + 0.04), h + 0.2)] for x in (-0.12, 0.14) for s in (-1, 1)]
    return [
        TwinPart.of("Base", geo.merge(geo.box((-0.4, -0.22, 0.1), (0.3, 0.22, pan)), *hubs,
                                      _tubes(0.025, [(0.0, 0.0, pan - 0.02), (0.0, 0.0, h - 0.06)], sections=10),
                                      geo.box((-0.2, -w, h - 0.1), (0.22, w, h - 0.08)),
                                      _tubes(TUBE_M, *posts, *[[(0.2, s * 0.12, h - 0.09), (0.4, s * 0.12, 0.08)] for s in (-1, 1)],
                                             [(-0.25, -0.12, h + 0.5), (-0.25, -0.12, h + 0.64)],
                                             [(-0.25, 0.12, h + 0.5), (-0.25, 0.12, h + 0.64)]),
                                      geo.box((0.34, -0.2, 0.06), (0.52, 0.2, 0.08))), "Frame"),
        TwinPart.of("Wheels", geo.merge(*tyres), "Tyre"),
        TwinPart.of("Seat", geo.merge(geo.box((-0.2, -w, h - 0.08), (0.25, w, h)),
                                      geo.box((-0.3, -w, h + 0.02), (-0.2, w, h + 0.55)),
                                      geo.box((-0.29, -0.14, h + 0.62), (-0.21, 0.14, h + 0.78)), *armrests), "Seat"),
        TwinPart.of("Controls", geo.merge(geo.box((0.1, w + 0.015, h + 0.23), (0.29, w + 0.085, h + 0.27)),
                                          geo.tube([(0.25, w + 0.05, h + 0.27), (0.25, w + 0.05, h + 0.3)], 0.005, 6)), "Frame"),
        TwinPart.of("Knob", geo.sphere((0.25, w + 0.05, h + 0.31), 0.016, subdivisions=1), "Tyre"),
    ]


def rollator(fit: DeviceFit = DeviceFit()) -> list[TwinPart]:
    """Four-wheel rollator: 0.2 m wheels (front ones on swivel forks), side frames of tube, handles at the
    fitted grip height where the posture's hands are, hand-brake levers with cables to the rear wheels, a
    seat at 0.56 m between the sides, a cross brace under it."""
    g = fit.grip_height_m
    tyres, frame, grips, cables = [], [], [], []
    for s in (-1, 1):
        y = s * 0.27
        tyres.append(geo.torus((-0.24, s * 0.3, 0.1), 0.085, 0.015, axis="y", major_sections=24, minor_sections=6))
        frame.append(geo.cylinder((-0.24, s * 0.3, 0.1), 0.03, 0.035, axis="y", sections=10))
        tyre, fork = _caster(0.24, s * 0.3, 0.1, 0.3)
        tyres.append(tyre)
        frame += [fork, _tubes(TUBE_M, [(-0.24, y, 0.1), (-0.1, y, 0.52), (-0.09, y, g - 0.05), (-0.11, y, g - 0.005)],
                               [(0.21, s * 0.3, 0.3), (0.17, y, 0.34), (-0.1, y, 0.52)], [(-0.11, y, g - 0.05), (-0.2, y, g - 0.06)]),
                  _tubes(0.006, [(-0.12, y, g - 0.035), (-0.18, y, g - 0.03)], sections=6)]
        grips.append(geo.tube([(-0.08, y, g - 0.005), (-0.2, y, g - 0.005)], 0.016, 8))
        cables.append(geo.tube([(-0.11, y, g - 0.04), (-0.06, y + s * 0.02, g - 0.15), (-0.09, y + s * 0.02, 0.5),
                                (-0.2, y + s * 0.02, 0.2)], 0.003, 4))
    frame.append(_tubes(0.01, [(0.05, -0.27, 0.3), (0.05, 0.27, 0.53)], [(0.05, 0.27, 0.3), (0.05, -0.27, 0.53)],
                        [(-0.12, -0.27, 0.53), (-0.12, 0.27, 0.53)]))
    return [TwinPart.of("Frame", geo.merge(*frame), "Frame"),
            TwinPart.of("Wheels", geo.merge(*tyres), "Tyre"),
            TwinPart.of("Seat", geo.box((-0.12, -0.24, 0.54), (0.14, 0.24, 0.565)), "Seat"),
            TwinPart.of("Grips", geo.merge(*grips, *cables), "Tyre")]


def _ferrule(radius: float, height: float = 0.045) -> geo.Mesh:
    """A rubber tip standing on the origin."""
    return geo.merge(geo.cylinder((0, 0, height / 2), radius, height, sections=12),
                     geo.cylinder((0, 0, 0.005), radius + 0.003, 0.01, sections=12))


def forearm_crutch(fit: DeviceFit = DeviceFit(grip_height_m=0.76)) -> list[TwinPart]:
    """Forearm (Lofstrand) crutch: adjustable 19/22 mm tubes on a rubber ferrule, a 12 cm handgrip forward at
    the fitted grip height, the upper tube angled 15 degrees back to an open cuff 0.21 m above the grip."""
    g = fit.grip_height_m
    cuff = _arc((-0.015, 0.0, g + 0.215), 0.045, 40, 320, 10, plane="xy")
    return [TwinPart.of("Shaft", geo.merge(geo.tube([(0, 0, 0.04), (0, 0, 0.45)], 0.0095, 10),
                                           geo.tube([(0, 0, 0.4), (0, 0, g - 0.015), (-0.055, 0, g + 0.19)], TUBE_M, 10),
                                           geo.tube(cuff, 0.01, 6)), "Frame"),
            TwinPart.of("Grip", geo.tube([(0.005, 0, g - 0.015), (0.125, 0, g - 0.015)], 0.015, 10), "Tyre"),
            TwinPart.of("Tip", _ferrule(0.019), "Tyre")]


def _offset_handle(g: float) -> tuple[geo.Mesh, geo.Mesh]:
    """(shaft top, grip) of an offset cane: the shaft bends forward below the grip so that the grip's middle
    stands over the shaft; the grip's top at the fitted height ``g``."""
    top = geo.tube([(0, 0, 0.4), (0, 0, g - 0.17), (0.035, 0, g - 0.11), (0.04, 0, g - 0.05), (0.03, 0, g - 0.014)], 0.011, 10)
    return top, geo.tube([(0.05, 0, g - 0.014), (-0.09, 0, g - 0.014)], 0.014, 10)


def wooden_cane_detailed(fit: DeviceFit = DeviceFit(grip_height_m=0.9)) -> list[TwinPart]:
    """Crook-handled wooden walking stick: a 25 mm shaft bending over in a 9 cm hook at the fitted grip
    height, a rubber ferrule."""
    g = fit.grip_height_m
    crook = _arc((-0.045, 0, g - 0.0575), 0.045, 0, 200, 14)
    return [TwinPart.of("Shaft", geo.tube(np.concatenate([[(0, 0, 0.035)], crook]), 0.0125, 10), "Wood"),
            TwinPart.of("Tip", _ferrule(0.016, 0.04), "Tyre")]


def orthopedic_cane_detailed(fit: DeviceFit = DeviceFit(grip_height_m=0.92)) -> list[TwinPart]:
    """Adjustable aluminium offset cane: an inner tube in the outer one, the offset handle with a foam grip,
    a rubber ferrule."""
    top, grip = _offset_handle(fit.grip_height_m)
    return [TwinPart.of("Shaft", geo.merge(geo.tube([(0, 0, 0.035), (0, 0, 0.5)], 0.0095, 10), top), "Frame"),
            TwinPart.of("Grip", grip, "Tyre"), TwinPart.of("Tip", _ferrule(0.018), "Tyre")]


def tripod_cane_detailed(fit: DeviceFit = DeviceFit(grip_height_m=0.88)) -> list[TwinPart]:
    """Tripod cane: the offset handle on a shaft into a hub from which three legs splay to rubber feet 0.1 m
    out (their centre at the origin)."""
    top, grip = _offset_handle(fit.grip_height_m)
    angles = np.linspace(0, 2 * np.pi, 3, endpoint=False)
    legs = [[(0.02 * np.cos(a), 0.02 * np.sin(a), 0.15), (0.1 * np.cos(a), 0.1 * np.sin(a), 0.035)] for a in angles]
    feet = [geo.translate(_ferrule(0.014, 0.035), (0.1 * np.cos(a), 0.1 * np.sin(a), 0.0)) for a in angles]
    return [TwinPart.of("Shaft", geo.merge(geo.tube([(0, 0, 0.14), (0, 0, 0.5)], 0.0095, 10), top), "Frame"),
            TwinPart.of("Base", geo.merge(geo.cylinder((0, 0, 0.15), 0.03, 0.04, sections=12), _tubes(0.008, *legs)), "Frame"),
            TwinPart.of("Grip", grip, "Tyre"), TwinPart.of("Tip", geo.merge(*feet), "Tyre")]


def white_cane(fit: DeviceFit = DeviceFit()) -> list[TwinPart]:
    """Smart long white cane: a 13 mm white shaft with the red band above a roller tip, a rubber grip
    ending at the fitted grip height with the sensor unit below it."""
    g = fit.grip_height_m
    return [TwinPart.of("Shaft", geo.tube([(0, 0, 0.03), (0, 0, g - 0.12)], 0.0065, 8), "CaneWhite"),
            TwinPart.of("Band", geo.tube([(0, 0, 0.08), (0, 0, 0.26)], 0.0072, 8), "CaneRed"),
            TwinPart.of("Grip", geo.tube([(0, 0, g - 0.2), (0, 0, g)], 0.012, 10), "Tyre"),
            TwinPart.of("Sensor", geo.box((-0.015, -0.017, g - 0.24), (0.03, 0.017, g - 0.17)), "Frame"),
            TwinPart.of("Tip", geo.merge(geo.cylinder((0, 0, 0.02), 0.02, 0.035, axis="y", sections=16),
                                         geo.tube([(0, 0, 0.02), (0, 0, 0.045)], 0.008, 8)), "CaneWhite")]


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

#: class name → builder of its detailed model.
DETAILED = {
    "manual_wheelchair": manual_wheelchair_detailed,
    "electric_wheelchair": electric_wheelchair_detailed,
    "walker": rollator,
    "crutch": forearm_crutch,
    "smart_cane": white_cane,
    "wooden_cane": wooden_cane_detailed,
    "orthopedic_cane": orthopedic_cane_detailed,
    "tripod_cane": tripod_cane_detailed,
}

#: class name → {model name: builder}: the models a randomised scene draws among.
DEVICE_MODELS = {name: {"standard": builder, "detailed": DETAILED[name]} for name, builder in DEVICES.items()}
