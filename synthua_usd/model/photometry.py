"""Photometric units of rendered images: how renderer radiance relates to luminance in cd/m².

Renders are scene-linear Rec.709. Mitsuba's RGB variants keep emitted spectral radiance per nanometre
(its spectrum-to-RGB conversion divides by the integral of the CIE ȳ matching function), so the
Rec.709 luminance ``Y`` of a pixel is the ȳ-weighted mean spectral radiance in W/(m²·sr·nm), and

    L_v [cd/m²] = 683 lm/W × ∫ȳ(λ) dλ × Y = 683 × 106.857 nm × Y ≈ 72 983 × Y.

Check (``tests/backends/mitsuba/test_weather_scene.py``): Mitsuba's ``sunsky`` emitter with the sun 65° high and
turbidity 3 lights a horizontal plane with ≈ 105 klx, within the 100–120 klx measured under clear noon
skies. Lamps (:mod:`synthua_usd.model.lamps`) are authored in lumens and cd/m² and converted with the same
constant, so sun, sky and street lights share one scale and one exposure rule.
"""

from __future__ import annotations

import numpy as np

#: Peak luminous efficacy, lm/W (CIE).
LUMINOUS_EFFICACY_LM_PER_W = 683.0
#: ∫ȳ(λ) dλ of the CIE 1931 2° observer, nm.
YBAR_INTEGRAL_NM = 106.857
#: cd/m² per unit of rendered Rec.709 luminance.
CD_PER_M2_PER_UNIT = LUMINOUS_EFFICACY_LM_PER_W * YBAR_INTEGRAL_NM
#: Rec.709 / sRGB luminance weights of linear R, G, B.
REC709_LUMA = np.array([0.2126, 0.7152, 0.0722])

#: Linear Rec.709 colours with unit luminance (Y = 1) of light sources, from the CCT by Kang et al. (2002)'s
#: Planckian-locus fit, xy → XYZ → Rec.709 (checked against colour-science in ``tests/model/test_photometry.py``).
#: The red of tail lamps is outside Rec.709; its red primary is the nearest colour inside.
CCT_2700K = (1.9298, 0.8051, 0.1929)
CCT_3000K = (1.7670, 0.8454, 0.2726)
CCT_4000K = (1.4150, 0.9238, 0.5333)
REC709_RED = (1.0 / 0.2126, 0.0, 0.0)


def luminance(rgb: np.ndarray) -> np.ndarray:
    """Rec.709 luminance Y of (..., 3) linear RGB, in renderer units (multiply by
    :data:`CD_PER_M2_PER_UNIT` for cd/m²)."""
    return np.asarray(rgb, np.float64)[..., :3] @ REC709_LUMA


def radiance_rgb(luminance_cd_m2: float, color: tuple[float, float, float]) -> tuple[float, float, float]:
    """The renderer RGB radiance of a surface of ``luminance_cd_m2`` with a unit-luminance ``color``."""
    scale = luminance_cd_m2 / CD_PER_M2_PER_UNIT
    return tuple(float(c * scale) for c in color)


# --- UsdLux light strengths from other conventions -------------------------------------------------------------

#: The brightest light strength read as renderer units (irradiance of a distant light, radiance of a dome): 20
#: units is 1.46 Mlx or 1.46 Mcd/m², 11x the brightest clear-noon sun (~130 klx) and ~100x a bright sky. Our
#: own stages author sun 1.2 and sky 0.08. A stronger authored value means the stage follows another convention.
MAX_RENDERER_UNITS = 20.0


def solid_angle_sr(angle_deg: float) -> float:
    """Solid angle (sr) of a disk of apparent diameter ``angle_deg`` (UsdLux DistantLight ``inputs:angle``)."""
    import math

    return 2.0 * math.pi * (1.0 - math.cos(math.radians(angle_deg) / 2.0))


def distant_irradiance(strength: float, angle_deg: float, normalize: bool) -> tuple[float, str]:
    """(irradiance in renderer units, the rule used) of a UsdLux DistantLight whose ``intensity x 2^exposure``
    is ``strength``. Our convention: renderer units (1 = 72,983 lx). A strength above
    :data:`MAX_RENDERER_UNITS` follows another: UsdLux's radiance of the sun's disk (not normalised:
    irradiance = strength x the disk's solid angle; the schema's default 50,000 at 0.53 degrees gives 3.36 units,
    245 klx), or, when that is implausible too or the light is normalised, lux."""
    if strength <= MAX_RENDERER_UNITS:
        return strength, "renderer units"
    if not normalize:
        disk = strength * solid_angle_sr(angle_deg)
        if disk <= MAX_RENDERER_UNITS:
            return disk, f"UsdLux radiance of a {angle_deg:g} degree disk (x {solid_angle_sr(angle_deg):.3g} sr)"
    return strength / CD_PER_M2_PER_UNIT, "lux"


def dome_radiance(strength: float) -> tuple[float, str]:
    """(radiance in renderer units, the rule used) of a UsdLux DomeLight of ``intensity x 2^exposure`` =
    ``strength``: renderer units up to :data:`MAX_RENDERER_UNITS`, nits (cd/m²) above."""
    if strength <= MAX_RENDERER_UNITS:
        return strength, "renderer units"
    return strength / CD_PER_M2_PER_UNIT, "nits (cd/m²)"
