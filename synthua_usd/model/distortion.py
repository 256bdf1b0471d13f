"""Brown–Conrady lens distortion (radial k1, k2, k3 and tangential p1, p2), OpenCV's convention.

Coordinates are *normalised image coordinates* of the OpenCV camera frame (x right, y down, z forward):
``x = X / Z``, ``y = Y / Z`` for the ideal pinhole (undistorted), and the distorted ones the lens
forms, so that pixel ``u = fx * x_d + cx``, ``v = fy * y_d + cy`` (``K`` of
:meth:`synthua_usd.model.cameras.PinholeCamera.intrinsics`). The forward model::

    r2 = x^2 + y^2,  radial = 1 + k1 r2 + k2 r2^2 + k3 r2^3
    x_d = x radial + 2 p1 x y + p2 (r2 + 2 x^2)
    y_d = y radial + p1 (r2 + 2 y^2) + 2 p2 x y

is what OpenCV's ``projectPoints`` applies with ``distCoeffs = (k1, k2, p1, p2, k3)``, so coefficients
calibrated with OpenCV can be used as they are.

A pixel-centre ray needs the inverse (distorted → undistorted), which has no closed form:
:meth:`BrownConrady.undistort` solves it per point by Newton's method with the analytic 2×2 Jacobian,
damped (step halving) where a full step would grow the residual, to ``UNDISTORT_TOL`` in normalised units
(1e-12: below 1e-8 pixel for any focal length under 10,000 pixels). Coefficients whose forward map is not
one-to-one over the image (the radial curve folds back, the Jacobian vanishes, or the corners would lie
beyond ``MAX_FIELD_DEG`` off axis) are refused with :class:`InputError`: no exact ray exists for them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from synthua_usd.core.errors import InputError

MODEL = "brown_conrady"
#: Newton stops when every residual |forward(x) - x_d| is below this (normalised units).
UNDISTORT_TOL = 1e-12
UNDISTORT_MAX_ITER = 60
#: The undistorted field may reach at most this far off the optical axis (a pinhole cannot see 90°).
MAX_FIELD_DEG = 85.0
COEFFICIENTS = ("k1", "k2", "k3", "p1", "p2")


@dataclass(frozen=True)
class BrownConrady:
    """Distortion coefficients (dimensionless, for normalised coordinates). All zero is no distortion."""

    k1: float = 0.0
    k2: float = 0.0
    k3: float = 0.0
    p1: float = 0.0
    p2: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise InputError(f"distortion {f.name}: {value!r}; expected a finite number")
            object.__setattr__(self, f.name, float(value))

    @classmethod
    def from_dict(cls, data: dict, source: str = "distortion") -> "BrownConrady":
        """From ``{"k1": ..., ...}``; unknown keys are refused (missing ones are 0)."""
        unknown = sorted(set(data) - set(COEFFICIENTS))
        if unknown:
            raise InputError(f"{source}: unknown coefficient(s) {unknown}; expected {', '.join(COEFFICIENTS)}")
        return cls(**data)

    def to_dict(self) -> dict:
        return {"model": MODEL, **{name: getattr(self, name) for name in COEFFICIENTS}}

    @property
    def is_zero(self) -> bool:
        return all(getattr(self, name) == 0.0 for name in COEFFICIENTS)

    def __str__(self) -> str:
        return ", ".join(f"{name}={getattr(self, name):g}" for name in COEFFICIENTS)

    # --- the model --------------------------------------------------------------------------------------

    def distort(self, x, y):
        """Undistorted → distorted normalised coordinates. Plain arithmetic, so ``x``, ``y`` may be numbers,
        numpy arrays (float64 here) or the renderer's own arrays (the distorting sensor runs it in Dr.Jit)."""
        r2 = x * x + y * y
        radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3))
        xd = x * radial + 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x)
        yd = y * radial + self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y
        return xd, yd

    def jacobian(self, x, y) -> tuple:
        """The forward map's partial derivatives (dxd/dx, dxd/dy, dyd/dx, dyd/dy) at (x, y) (any array type,
        as :meth:`distort`)."""
        r2 = x * x + y * y
        radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3))
        dradial = self.k1 + r2 * (2.0 * self.k2 + 3.0 * self.k3 * r2)  # d radial / d r2
        cross = 2.0 * x * y * dradial + 2.0 * self.p1 * x + 2.0 * self.p2 * y
        return (radial + 2.0 * x * x * dradial + 2.0 * self.p1 * y + 6.0 * self.p2 * x, cross,
                cross, radial + 2.0 * y * y * dradial + 6.0 * self.p1 * y + 2.0 * self.p2 * x)

    def undistort(self, xd: np.ndarray, yd: np.ndarray, where: str = "camera") -> tuple[np.ndarray, np.ndarray]:
        """Distorted → undistorted normalised coordinates (float64, same shape), to ``UNDISTORT_TOL``.

        Raises :class:`InputError` naming ``where`` when the map cannot be inverted at some point (see the
        module docstring). All-zero coefficients return copies of the input unchanged."""
        xd, yd = np.asarray(xd, np.float64), np.asarray(yd, np.float64)
        x, y = xd.copy(), yd.copy()
        if self.is_zero:
            return x, y
        # Coefficients such as k1 = 1e308 overflow to inf and NaN along the way: the residual check below
        # refuses them in one line, so numpy's warnings about the same points would only repeat it.
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            x, y, err = self._newton(x, y, xd, yd)
        bad = ~(err <= UNDISTORT_TOL)
        if bad.any():
            k = int(np.flatnonzero(bad.ravel())[0])
            raise InputError(f"{where}: Brown-Conrady distortion ({self}) has no inverse at normalised image point "
                             f"({xd.ravel()[k]:.4g}, {yd.ravel()[k]:.4g}) (residual {err.ravel()[k]:.2g}); expected "
                             f"coefficients whose forward map is one-to-one over the image")
        self._check_one_to_one(x, y, where)
        return x, y

    def _newton(self, x: np.ndarray, y: np.ndarray, xd: np.ndarray, yd: np.ndarray) -> tuple:
        """Damped Newton iterations from (x, y) towards distort(x, y) = (xd, yd): (x, y, max-norm residual)."""
        fx, fy = self.distort(x, y)
        rx, ry = fx - xd, fy - yd
        err = np.maximum(np.abs(rx), np.abs(ry))
        for _ in range(UNDISTORT_MAX_ITER):
            todo = err > UNDISTORT_TOL
            if not todo.any():
                break
            a, b, c, d = self.jacobian(x, y)
            det = a * d - b * c
            safe = np.where(np.abs(det) > 1e-300, det, 1.0)
            step_x = np.where(todo, (d * rx - b * ry) / safe, 0.0)
            step_y = np.where(todo, (a * ry - c * rx) / safe, 0.0)
            scale = np.ones_like(x)
            for _halving in range(30):  # damped Newton: halve the step until the residual shrinks
                nx, ny = x - scale * step_x, y - scale * step_y
                fx, fy = self.distort(nx, ny)
                new_err = np.maximum(np.abs(fx - xd), np.abs(fy - yd))
                worse = todo & ~(new_err < err) & (new_err > UNDISTORT_TOL)
                if not worse.any():
                    break
                scale = np.where(worse, scale * 0.5, scale)
            x, y = np.where(todo, nx, x), np.where(todo, ny, y)
            rx, ry = np.where(todo, fx - xd, rx), np.where(todo, fy - yd, ry)
            err = np.where(todo, new_err, err)
        return x, y, err

    def _check_one_to_one(self, x: np.ndarray, y: np.ndarray, where: str) -> None:
        """The solutions lie where the map is one-to-one: the radial curve r (1 + k1 r^2 + k2 r^4 + k3 r^6)
        still rises at the largest radius reached (its derivative 1 + 3 k1 s + 5 k2 s^2 + 7 k3 s^3, s = r^2,
        has no root below), the Jacobian is positive at every solution, and the field stays within
        MAX_FIELD_DEG."""
        s_max = float(np.max(x * x + y * y)) if x.size else 0.0
        limit = math.tan(math.radians(MAX_FIELD_DEG)) ** 2
        if s_max > limit:
            raise InputError(f"{where}: Brown-Conrady distortion ({self}) spreads the image over "
                             f"{math.degrees(math.atan(math.sqrt(s_max))):.1f} degrees off axis; expected at most "
                             f"{MAX_FIELD_DEG:g} (smaller coefficients or a longer lens)")
        roots = np.roots([7.0 * self.k3, 5.0 * self.k2, 3.0 * self.k1, 1.0]) if (self.k1 or self.k2 or self.k3) else []
        folds = [r.real for r in roots if abs(r.imag) < 1e-12 and 0.0 < r.real <= s_max]
        if folds:
            raise InputError(f"{where}: Brown-Conrady distortion ({self}) folds back at "
                             f"{math.degrees(math.atan(math.sqrt(min(folds)))):.1f} degrees off axis, inside the image; "
                             f"expected a radial curve that rises over the whole image")
        a, b, c, d = self.jacobian(x, y)
        if np.any(a * d - b * c <= 0):
            raise InputError(f"{where}: Brown-Conrady distortion ({self}) is not one-to-one over the image (its "
                             f"Jacobian vanishes); expected smaller tangential coefficients")

    def check_field(self, half_width: float, half_height: float, where: str = "camera") -> None:
        """Refuse coefficients that cannot be inverted over the rectangle of distorted normalised coordinates
        ``[-half_width, half_width] x [-half_height, half_height]`` (sampled on a 65 x 65 grid with its edges)."""
        gx, gy = np.meshgrid(np.linspace(-half_width, half_width, 65), np.linspace(-half_height, half_height, 65))
        self.undistort(gx, gy, where)
