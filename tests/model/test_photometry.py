"""Photometric constants checked against colour-science."""

import numpy as np
import pytest

from synthua_usd.model.photometry import CCT_2700K, CCT_3000K, CCT_4000K, CD_PER_M2_PER_UNIT, REC709_LUMA, luminance


@pytest.mark.parametrize("cct,rgb", [(2700, CCT_2700K), (3000, CCT_3000K), (4000, CCT_4000K)])
def test_light_colours_are_planckian_with_unit_luminance(cct, rgb):
    colour = pytest.importorskip("colour")
    xyz = colour.xy_to_XYZ(colour.temperature.CCT_to_xy_Kang2002(cct))
    expected = colour.models.RGB_COLOURSPACE_BT709.matrix_XYZ_to_RGB @ xyz
    expected = expected / (REC709_LUMA @ expected)
    assert np.allclose(rgb, expected, atol=2e-4)
    assert luminance(np.array(rgb)) == pytest.approx(1.0, abs=1e-4)


def test_candela_per_unit_is_683_times_the_ybar_integral():
    colour = pytest.importorskip("colour")
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    assert CD_PER_M2_PER_UNIT == pytest.approx(683.0 * cmfs.values[:, 1].sum() * 1.0, rel=1e-3)
