"""Brown–Conrady distortion: OpenCV's forward model, its numerical inverse, and refusal of coefficients
that have no inverse over the image."""

import numpy as np
import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.model.distortion import UNDISTORT_TOL, BrownConrady

LENS = BrownConrady(k1=-0.28, k2=0.09, k3=-0.01, p1=0.0012, p2=-0.0008)


def test_forward_model_is_opencvs():
    # Worked by hand from OpenCV's projectPoints formula: x=0.5, y=-0.25, r2 = 0.3125.
    d = BrownConrady(k1=0.1, k2=0.01, k3=0.001, p1=0.002, p2=0.003)
    radial = 1 + 0.1 * 0.3125 + 0.01 * 0.3125 ** 2 + 0.001 * 0.3125 ** 3
    xd, yd = d.distort(0.5, -0.25)
    assert xd == pytest.approx(0.5 * radial + 2 * 0.002 * 0.5 * -0.25 + 0.003 * (0.3125 + 2 * 0.25), abs=1e-15)
    assert yd == pytest.approx(-0.25 * radial + 0.002 * (0.3125 + 2 * 0.0625) + 2 * 0.003 * 0.5 * -0.25, abs=1e-15)


def test_undistort_inverts_the_forward_model_to_its_tolerance():
    rng = np.random.default_rng(0)
    x, y = rng.uniform(-0.8, 0.8, (2, 5000))
    xd, yd = LENS.distort(x, y)
    xu, yu = LENS.undistort(xd, yd)
    assert np.abs(xu - x).max() < 10 * UNDISTORT_TOL and np.abs(yu - y).max() < 10 * UNDISTORT_TOL
    fx, fy = LENS.distort(xu, yu)
    assert np.maximum(np.abs(fx - xd), np.abs(fy - yd)).max() <= UNDISTORT_TOL


def test_jacobian_matches_finite_differences():
    x, y, h = np.array([0.3, -0.6]), np.array([-0.2, 0.45]), 1e-6
    a, b, c, d = LENS.jacobian(x, y)
    dx = [(p - m) / (2 * h) for p, m in zip(LENS.distort(x + h, y), LENS.distort(x - h, y))]
    dy = [(p - m) / (2 * h) for p, m in zip(LENS.distort(x, y + h), LENS.distort(x, y - h))]
    assert np.allclose([a, b, c, d], [dx[0], dy[0], dx[1], dy[1]], atol=1e-8)


def test_zero_distortion_is_the_identity_exactly():
    xd = np.linspace(-0.7, 0.7, 11)
    xu, yu = BrownConrady().undistort(xd, -xd)
    assert xu.tobytes() == xd.tobytes() and yu.tobytes() == (-xd).tobytes()


@pytest.mark.parametrize("coefficients, field, text", [
    ({"k1": -0.5}, (0.75, 0.5), "has no inverse"),  # r (1 - 0.5 r^2) peaks at 0.54: the corners have no preimage
    ({"k1": -0.2, "k2": -0.2}, (0.75, 0.5), "has no inverse"),
    ({"p1": 0.6}, (0.75, 0.5), "has no inverse"),
    ({"k1": 1e-6}, (12.0, 8.0), "86.0 degrees off axis"),  # a 172-degree field: no pinhole ray reaches it
])
def test_coefficients_without_an_inverse_over_the_image_are_refused(coefficients, field, text):
    with pytest.raises(InputError, match=f"camera /Cam: Brown-Conrady distortion .*{text}"):
        BrownConrady(**coefficients).check_field(*field, where="camera /Cam")


def test_a_fold_beyond_the_image_is_accepted_and_one_inside_refused():
    # r (1 - 0.3 r^2) rises to 0.70 at r = 1.05 and falls after: a 0.5 x 0.35 field (corner 0.61) stays
    # below the fold, a field whose corner is at 0.68 still does, one at 0.9 has no preimage.
    fold = BrownConrady(k1=-0.3)
    fold.check_field(0.5, 0.35)
    fold.check_field(0.55, 0.4)
    with pytest.raises(InputError, match="has no inverse"):
        fold.check_field(0.75, 0.5)


@pytest.mark.parametrize("data, text", [
    ({"k4": 0.1}, r"unknown coefficient\(s\) \['k4'\]"),
    ({"k1": float("nan")}, "k1: nan; expected a finite number"),
    ({"p2": "0.1"}, "p2: '0.1'; expected a finite number"),
])
def test_bad_values_are_refused(data, text):
    with pytest.raises(InputError, match=text):
        BrownConrady.from_dict(data)


def test_overflowing_coefficients_are_refused_without_numpy_warnings():
    """k1 = 1e308 overflows inside the Newton iterations: refused in one line, numpy silent about it."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match="has no inverse"):
            BrownConrady(k1=1e308).check_field(0.8, 0.6)
