"""The sun of a condition: a directional emitter with the irradiance of Mitsuba ``sunsky``'s own sun disk, in
the condition's direction, on Z-up and Y-up stages; and its disk drawn in image space where a camera sees it."""

import math

import numpy as np
import pytest

from synthua_usd.backends import weather
from synthua_usd.backends.mitsuba import weather_scene
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.conditions import SHIPPED

CONDITIONS = {c.name: c for c in SHIPPED}
ALBEDO = 0.5


def disk_quadrature(mi, condition, up_axis: str) -> np.ndarray:
    """(3,) horizontal irradiance of ``sunsky``'s sun alone, by a midpoint rule in (cos θ, φ) over a cone of 0.3°
    around the sun (the disk is 0.268°) of the emitter's own ``eval``: independent of :class:`LightMeter`,
    which samples the emitter's ``sample_direction``."""
    d = condition.sun_direction(up_axis)
    base = weather_scene.sunsky_dict(mi, up_axis)
    base.update(sun_direction=[float(x) for x in d], turbidity=float(condition.turbidity), albedo=0.2,
                sun_scale=1.0, sky_scale=0.0)
    emitter = mi.load_dict({"type": "scene", "sky": base}).emitters()[0]
    n, half = 48, math.radians(0.3)
    cos_t = 1.0 - (np.arange(n) + 0.5) / n * (1.0 - math.cos(half))
    phi = 2.0 * math.pi * (np.arange(n) + 0.5) / n
    c, p = (a.ravel() for a in np.meshgrid(cos_t, phi))
    s = np.sqrt(1.0 - c * c)
    t1 = np.cross(d, np.eye(3)[int(np.argmin(np.abs(d)))])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(d, t1)
    dirs = (s * np.cos(p))[:, None] * t1 + (s * np.sin(p))[:, None] * t2 + c[:, None] * d
    radiance = weather_scene.radiance_towards(mi, emitter, dirs)
    up = weather_scene.up_vector(up_axis)
    solid_angle = 2.0 * math.pi * (1.0 - math.cos(half))
    return (radiance * (dirs @ up)[:, None]).mean(axis=0) * solid_angle


def plane_radiance(mi, condition, up_axis: str, normal: np.ndarray, albedo: float = ALBEDO, sky: bool = False,
                   spp: int = 4) -> np.ndarray:
    """(3,) mean radiance of a diffuse plane of ``albedo`` facing ``normal``, lit by the condition's sun alone (sky
    scale 0) as :func:`weather_scene.apply_condition` sets it, or with ``sky`` by its sun and sky, seen along
    its normal."""
    side = np.cross(normal, np.eye(3)[int(np.argmin(np.abs(normal)))])
    frame = mi.ScalarTransform4f().look_at(origin=[0, 0, 0], target=normal.tolist(), up=side.tolist())
    camera = mi.ScalarTransform4f().look_at(origin=(2.0 * normal).tolist(), target=[0, 0, 0], up=side.tolist())
    scene = mi.load_dict({
        "type": "scene", "integrator": {"type": "path", "max_depth": 2},
        "plane": {"type": "rectangle", "to_world": frame,
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [albedo] * 3}}},
        "sensor": {"type": "perspective", "fov": 5.0, "to_world": camera,
                   "sampler": {"type": "independent", "sample_count": spp},
                   "film": {"type": "hdrfilm", "width": 4, "height": 4, "rfilter": {"type": "box"}}},
        **weather_scene.sky_emitter(mi, up_axis)})
    params = mi.traverse(scene)
    weather_scene.apply_condition(mi, params, (), (), condition, up_axis, weather_scene.LightMeter(mi))
    if not sky:
        params[f"{weather_scene.SKY}.scale"] = 0.0
        params[f"{weather_scene.SKY}.sampling_weight"] = 1e-9  # every shadow ray to the sun: no choice, no noise
    params.update()
    return np.asarray(mi.render(scene), np.float64).reshape(-1, 3).mean(axis=0)


@pytest.mark.parametrize("name", ["clear_day", "sunset"])
def test_the_light_meter_integrates_the_sun_disk(variant, name):
    import mitsuba as mi

    condition = CONDITIONS[name]
    e_sun, _ = weather_scene.LightMeter(mi).measure(condition.sun_direction("Z"), condition.turbidity, 0.2, "Z")
    np.testing.assert_allclose(e_sun, disk_quadrature(mi, condition, "Z"), rtol=0.01)


@pytest.mark.parametrize("name", ["clear_day", "sunset"])
@pytest.mark.parametrize("up_axis", ["Z", "Y"])
def test_the_directional_sun_gives_the_disk_irradiance_in_the_condition_direction(variant, name, up_axis):
    import mitsuba as mi

    condition = CONDITIONS[name]
    sun = condition.sun_direction(up_axis)
    up = weather_scene.up_vector(up_axis)
    e_sun, _ = weather_scene.LightMeter(mi).measure(sun, condition.turbidity, 0.2, up_axis)
    # A Lambertian plane has radiance albedo * E / pi: E_horizontal on the ground, E_horizontal / cos(zenith)
    # facing the sun. A sun in the wrong direction would light the two planes in another ratio, or not at all.
    np.testing.assert_allclose(plane_radiance(mi, condition, up_axis, up), ALBEDO * e_sun / math.pi, rtol=1e-3)
    facing = ALBEDO * e_sun / float(sun @ up) / math.pi
    np.testing.assert_allclose(plane_radiance(mi, condition, up_axis, sun), facing, rtol=1e-3)


def looking_at(direction: np.ndarray) -> PinholeCamera:
    """A 20 mm lens on a 36 mm back, at the origin, looking along ``direction`` (Z up)."""
    forward = np.asarray(direction, np.float64) / np.linalg.norm(direction)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    to_world = np.eye(4)
    to_world[:3, :3] = np.column_stack([right, up, -forward])
    return PinholeCamera(path="/Cam", focal_length_mm=20.0, horizontal_aperture_mm=36.0,
                         vertical_aperture_mm=24.0, clip_near_m=0.1, clip_far_m=1e6, camera_to_world=to_world)


def pixel_solid_angles(camera: PinholeCamera, width: int, height: int) -> np.ndarray:
    """(H, W) steradians of each pixel of a pinhole camera: cos³θ / (fx fy), θ the angle off the axis."""
    k = camera.intrinsics(width, height)
    x = (np.arange(width) + 0.5 - k[0, 2]) / k[0, 0]
    y = (np.arange(height) + 0.5 - k[1, 2]) / k[1, 1]
    gx, gy = np.meshgrid(x, y)
    return (1.0 + gx ** 2 + gy ** 2) ** -1.5 / (k[0, 0] * k[1, 1])


def test_the_sun_disk_carries_the_sun_irradiance_where_the_camera_sees_it():
    w, h = 96, 64
    sun = np.array([0.3, 0.8, 0.52])
    sun /= np.linalg.norm(sun)
    irradiance = np.array([1.5, 1.25, 1.0])
    black = np.zeros((h, w, 3), np.float32)
    # Off the optical axis (the camera looks 10° beside the sun): the disk's energy is still the irradiance.
    side = np.cross(sun, [0.0, 0.0, 1.0])
    camera = looking_at(sun * math.cos(math.radians(10)) + side / np.linalg.norm(side) * math.sin(math.radians(10)))
    drawn = weather.sun_disk(black, np.ones((h, w), bool), camera, sun, irradiance)
    energy = (drawn.astype(np.float64) * pixel_solid_angles(camera, w, h)[..., None]).sum(axis=(0, 1))
    np.testing.assert_allclose(energy, irradiance, rtol=0.02)
    # Where it is: centred on the sun's projection.
    px, py = camera.project(sun[None, :], w, h)[0][0]
    lit = drawn[..., 0] > 0
    ys, xs = np.nonzero(lit)
    assert abs(xs.mean() + 0.5 - px) < 0.5 and abs(ys.mean() + 0.5 - py) < 0.5
    # Only on pixels whose ray escapes: a wall in front hides it.
    assert not weather.sun_disk(black, np.zeros((h, w), bool), camera, sun, irradiance).any()
    # Not drawn when the sun is behind the camera or outside the frame; the input is never changed.
    assert weather.sun_disk(black, np.ones((h, w), bool), looking_at(-sun), sun, irradiance) is black
    assert weather.sun_disk(black, np.ones((h, w), bool), looking_at(side), sun, irradiance) is black
    assert not black.any()
