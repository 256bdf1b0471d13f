"""Photometric units of rendered images: how renderer radiance relates to luminance in cd/m².

Renders are scene-linear Rec.709. Mitsuba's RGB variants keep emitted spectral radiance per nanometre
(its spectrum-to-RGB conversion divides by the integral of the CIE ȳ matching function), so the
Rec.709 luminance ``Y`` of a pixel is the ȳ-weighted mean spectral radiance in W/(m²·sr·nm), and

    L_v [cd/m²] = 683 lm/W × ∫ȳ(λ) dλ × Y = 683 × 106.857 nm × Y ≈ 72 983 × Y.

Check (``tests/backends/mitsuba/test_sky.py``): Mitsuba's ``sunsky`` emitter with the sun 65° high and
turbidity 3 lights a horizontal plane with ≈ 105 klx, within the 100–120 klx measured under clear noon
skies. Lamps (:mod:`synthua_usd.lamps`) are authored in lumens and cd/m² and converted with the same
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
#: Planckian-locus fit, xy → XYZ → Rec.709 (checked against colour-science in ``tests/test_photometry.py``).
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
