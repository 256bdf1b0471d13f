"""Exposure chosen per image from its luminance, the way a camera's averaging meter does.

Rule: the log-average luminance L̄ = exp(mean(ln(δ + L))) over the pixels that see a surface (Reinhard et
al. 2002, "Photographic tone reproduction"; δ = 10⁻⁴ cd/m² keeps black pixels finite; sky and the void
beyond a twin's edge are left out, as matrix meters discount the sky, so that neither a black void nor a
bright sky sets the exposure of the street; all pixels when none sees a surface) is metered as a reflected-light
meter would (ISO 2720, calibration constant K = 12.5 cd·s/m², ISO 100): EV100 = log2(L̄ · 100 / K). EV100 is
clamped to [−4, 21], the range of a real camera (f/1.4 at 1/4 s and ISO 12 800 up to f/16 at 1/8 000 s and
ISO 100), so a scene darker than any camera could expose stays dark instead of being scaled up. The image
is then scaled so that the metered luminance lands on the key value 0.18 (middle grey):

    display-linear = rgb × CD_PER_M2_PER_UNIT × 0.18 / (K · 2^EV100 / 100)

``rgb.exr`` keeps the unscaled scene-linear render; ``rgb.png`` is the exposed image, clipped and encoded
as sRGB; ``frame.json`` records L̄, EV100, whether it was clamped, and the scale.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from synthua_usd.model.photometry import CD_PER_M2_PER_UNIT, luminance

KEY = 0.18
METER_K = 12.5
ISO = 100.0
EV100_RANGE = (-4.0, 21.0)
DELTA_CD_M2 = 1e-4
RULE = ("log-average luminance of the pixels that see a surface, metered at ISO 100 with K = 12.5 "
        "(EV100 = log2(L*100/12.5), clamped to [-4, 21]) and placed at key 0.18")


@dataclass(frozen=True)
class Exposure:
    """The exposure of one image. ``scale`` multiplies scene-linear renderer RGB into display-linear values
    (1.0 = white, clipped above)."""

    log_average_cd_m2: float
    ev100: float
    clamped: bool
    scale: float
    #: The camera's exposure compensation (stops), already in ``scale``.
    compensation_ev: float = 0.0

    def to_dict(self) -> dict:
        out = {"rule": RULE, "key": KEY, "log_average_luminance_cd_m2": self.log_average_cd_m2,
               "ev100": self.ev100, "ev100_range": list(EV100_RANGE), "clamped": self.clamped,
               "scale": self.scale}
        if self.compensation_ev:
            out["compensation_ev"] = self.compensation_ev
        return out


def choose_exposure(rgb: np.ndarray, metered: np.ndarray | None = None, compensation_ev: float = 0.0) -> Exposure:
    """The exposure of (H, W, 3) scene-linear Rec.709 ``rgb`` in renderer units (see
    :mod:`synthua_usd.model.photometry`), metered over the (H, W) bool mask ``metered`` (pixels that see a
    surface; None or an empty mask: every pixel), then brightened by ``compensation_ev`` stops (the camera's
    USD ``exposure``)."""
    lum = np.maximum(luminance(rgb), 0.0) * CD_PER_M2_PER_UNIT
    if metered is not None and np.any(metered):
        lum = lum[metered]
    log_average = float(np.exp(np.mean(np.log(DELTA_CD_M2 + lum))))
    reading = math.log2(log_average * ISO / METER_K)
    ev100 = float(np.clip(reading, *EV100_RANGE))
    exposed_cd_m2 = METER_K * 2.0 ** ev100 / ISO
    return Exposure(log_average_cd_m2=log_average, ev100=ev100, clamped=ev100 != reading,
                    scale=CD_PER_M2_PER_UNIT * KEY / exposed_cd_m2 * 2.0 ** compensation_ev,
                    compensation_ev=float(compensation_ev))
