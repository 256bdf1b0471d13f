"""RGB through a distorting lens: a perspective sensor, written in Python, whose rays go through the same
Brown–Conrady model as the label rays.

Why a sensor and not a resampled image: Mitsuba's ``perspective`` sensor cannot distort, and rendering a
wider undistorted image and warping it afterwards would filter the picture twice (the film's
reconstruction filter, then the warp's interpolation) and blur it unevenly across the frame. A sensor
that maps every sample position on the film through the inverse distortion keeps Mitsuba's own sampling
and pixel filter, so the RGB is distorted exactly as the labels are, sample by sample. Mitsuba 3 lets
Python subclass ``mi.Sensor``; the integrator calls :meth:`sample_ray` with whole wavefronts in the JIT
variants (so it runs vectorised) and once per sample in the scalar ones (slow: keep scalar images tiny).

The inverse runs in float32 inside the sensor (``NEWTON_STEPS`` undamped Newton steps from the distorted
point), while the label rays invert in float64 to 1e-12 (:meth:`BrownConrady.undistort`): the two agree to
float32 rounding, far below a pixel. Coefficients are checked over the image before rendering, so the
undamped steps run only where the map is one-to-one.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.backends.mitsuba.translate import film_dict, sampler_dict
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.render_config import RenderConfig

#: Newton steps of the in-sensor inverse, from the distorted point. With them the sensor's rays agree with
#: the float64 label rays to 1e-6 (measured 1.4e-7 for k1 = -0.25; tests/backends/mitsuba/test_lens.py).
NEWTON_STEPS = 10


def distorted_sensor(mi, camera: PinholeCamera, config: RenderConfig, spp: int | None = None):
    """A sensor object (pass it as ``mi.render(scene, sensor=...)``) that sees through ``camera``'s lens
    distortion, with the film, pixel filter and sampler the scene's own sensor has."""
    import drjit as dr

    camera.check_distortion(config.width, config.height)
    k = camera.intrinsics(config.width, config.height)
    right, up, forward = camera.axes()
    dist = camera.distortion
    width, height = config.width, config.height
    fx, fy, cx, cy = float(k[0, 0]), float(k[1, 1]), float(k[0, 2]), float(k[1, 2])
    origin = [float(v) for v in camera.origin]
    near, far = float(camera.clip_near_m), float(camera.clip_far_m)
    basis = [[float(v) for v in axis] for axis in (right, up, forward)]

    def undistort(xd, yd):
        """Newton on the library's own forward model and Jacobian, in Dr.Jit arithmetic."""
        x, y = xd, yd
        for _ in range(NEWTON_STEPS):
            a, b, c, d = dist.jacobian(x, y)
            fx_, fy_ = dist.distort(x, y)
            rx, ry = fx_ - xd, fy_ - yd
            inv_det = dr.rcp(a * d - b * c)
            x, y = x - (d * rx - b * ry) * inv_det, y - (a * ry - c * rx) * inv_det
        return x, y

    class DistortedPerspective(mi.Sensor):
        """Brown–Conrady perspective camera (see the module docstring)."""

        def sample_ray(self, time, wavelength_sample, position_sample, aperture_sample, active=True):
            # Film position [0, 1]^2 -> pixel -> distorted normalised (OpenCV: y down) -> undistorted.
            xd = (position_sample.x * width - cx) / fx
            yd = (position_sample.y * height - cy) / fy
            x, y = undistort(xd, yd)
            right_, up_, fwd = basis
            d = dr.normalize(mi.Vector3f(*(x * right_[i] - y * up_[i] + fwd[i] for i in range(3))))
            cos = d.x * fwd[0] + d.y * fwd[1] + d.z * fwd[2]
            o = mi.Point3f(*origin) + d * (near / cos)
            return mi.Ray3f(o, d, (far - near) / cos, time, []), mi.Spectrum(1.0)

        def sample_ray_differential(self, time, wavelength_sample, position_sample, aperture_sample, active=True):
            ray, weight = self.sample_ray(time, wavelength_sample, position_sample, aperture_sample, active)
            return mi.RayDifferential3f(ray), weight

        def to_string(self):
            return f"DistortedPerspective[{camera.path}, {dist}]"

    props = mi.Properties()
    props["film"] = mi.load_dict(film_dict(config, width, height))
    props["sampler"] = mi.load_dict(sampler_dict(config, spp))
    return DistortedPerspective(props)


def sensor_rays(mi, sensor, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The sensor's rays at film positions (n, 2) in [0, 1]^2: origins and directions (n, 3) float64. For
    tests and measurements (scalar and JIT variants alike)."""
    if mi.variant().startswith("scalar"):
        out = [sensor.sample_ray(0.0, 0.5, mi.Point2f(*map(float, p)), mi.Point2f(0.5, 0.5))[0] for p in positions]
        return (np.array([[r.o[0], r.o[1], r.o[2]] for r in out]), np.array([[r.d[0], r.d[1], r.d[2]] for r in out]))
    pos = mi.Point2f(mi.Float(positions[:, 0].astype(np.float32)), mi.Float(positions[:, 1].astype(np.float32)))
    ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    return (np.stack([np.asarray(ray.o[i], np.float64) for i in range(3)], axis=1),
            np.stack([np.asarray(ray.d[i], np.float64) for i in range(3)], axis=1))
