"""Exposure from the image's log-average luminance, clamped to a camera's range."""

import numpy as np
import pytest

from synthua_usd.backends.exposure import EV100_RANGE, KEY, choose_exposure
from synthua_usd.model.photometry import CD_PER_M2_PER_UNIT


def grey(cd_m2: float) -> np.ndarray:
    return np.full((12, 16, 3), cd_m2 / CD_PER_M2_PER_UNIT, np.float32)


@pytest.mark.parametrize("cd_m2", [0.5, 100.0, 5000.0])
def test_a_uniform_image_lands_on_the_key(cd_m2):
    exposure = choose_exposure(grey(cd_m2))
    assert exposure.log_average_cd_m2 == pytest.approx(cd_m2, rel=1e-3)
    assert exposure.ev100 == pytest.approx(np.log2(cd_m2 * 100 / 12.5), rel=1e-3)
    assert not exposure.clamped
    assert (grey(cd_m2) * exposure.scale)[0, 0, 0] == pytest.approx(KEY, rel=1e-3)


def test_darker_than_a_camera_can_expose_stays_dark():
    exposure = choose_exposure(grey(1e-4))
    assert exposure.clamped and exposure.ev100 == EV100_RANGE[0]
    assert (grey(1e-4) * exposure.scale)[0, 0, 0] < 0.01


def test_only_pixels_that_see_a_surface_are_metered():
    image = grey(100.0)
    image[:6] = 0.0  # a black void above the twin
    seen = np.ones((12, 16), bool)
    seen[:6] = False
    assert choose_exposure(image, seen).log_average_cd_m2 == pytest.approx(100.0, rel=1e-3)
    assert choose_exposure(image).log_average_cd_m2 < 1.0
    document = choose_exposure(image, seen).to_dict()
    assert set(document) == {"rule", "key", "log_average_luminance_cd_m2", "ev100", "ev100_range", "clamped", "scale"}
