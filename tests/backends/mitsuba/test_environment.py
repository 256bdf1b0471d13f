"""The environment of a condition: the sky above the horizon and, below it, the ground beyond the twin, so that
a camera looking past the modelled ground sees a plain to the horizon, never black.

Checked against independent computations: the map's sky is Mitsuba ``sunsky``'s own ``eval`` in the same
directions; its ground is the radiance a real, rendered Lambertian plane of the same albedo gets from the
condition's sun and sky; and rendered frames of the demo street and the district, under every shipped
condition the sun is up in, have no black pixel at all."""

import math

import numpy as np
import pytest

from conftest import DISTRICT, SCENARIO
from frame_checks import black_shares
from synthua_usd.backends.mitsuba import weather_scene
from synthua_usd.model.conditions import SHIPPED
from test_sun import plane_radiance

CONDITIONS = {c.name: c for c in SHIPPED}


def loaded_environment(mi, condition, up_axis: str):
    """(scene, the condition's Lighting): a scene holding only the condition's environment and sun."""
    scene = mi.load_dict({"type": "scene", **weather_scene.sky_emitter(mi, up_axis)})
    params = mi.traverse(scene)
    lighting = weather_scene.apply_condition(mi, params, (), (), condition, up_axis, weather_scene.LightMeter(mi))
    params.update()
    return scene, lighting


def environment_of(scene):
    return next(e for e in scene.emitters() if e.is_environment())


def directions(up_axis: str, elevation_deg: np.ndarray, azimuth_deg: np.ndarray) -> np.ndarray:
    e, a = np.radians(elevation_deg), np.radians(azimuth_deg)
    east, north = np.cos(e) * np.cos(a), np.cos(e) * np.sin(a)
    if up_axis == "Y":
        return np.column_stack([east, np.sin(e), -north])
    return np.column_stack([east, north, np.sin(e)])


@pytest.mark.parametrize("up_axis", ["Z", "Y"])
@pytest.mark.parametrize("name", ["clear_day", "sunset"])
def test_the_environment_is_the_sunsky_above_the_horizon(variant, name, up_axis):
    import mitsuba as mi

    condition = CONDITIONS[name]
    scene, lighting = loaded_environment(mi, condition, up_axis)
    rng = np.random.default_rng(3)
    # Away from the horizon texel row and from the circumsolar peak, where the map's bilinear texels and the
    # analytic sky differ most.
    dirs = directions(up_axis, rng.uniform(5.0, 85.0, 200), rng.uniform(0.0, 360.0, 200))
    sun = condition.sun_direction(up_axis)
    dirs = dirs[dirs @ sun < math.cos(math.radians(15.0))]
    got = weather_scene.radiance_towards(mi, environment_of(scene), dirs)
    reference = mi.load_dict({"type": "scene", "sky": dict(
        weather_scene.sunsky_dict(mi, up_axis), sun_direction=[float(x) for x in sun],
        turbidity=float(condition.turbidity), albedo=weather_scene.GROUND_ALBEDO, sky_scale=lighting.sky_scale)})
    expected = weather_scene.radiance_towards(mi, reference.emitters()[0], dirs)
    # the map's texels are 0.35° at JIT variants, 1.4° at scalar ones
    np.testing.assert_allclose(got, expected, rtol=0.1 if mi.variant().startswith("scalar") else 0.03)


def test_texel_directions_are_computed_once_per_up_axis_and_read_only(variant):
    """Every new sky is evaluated at the map's texel directions: they are cached per map size and up axis (a
    Y-up stage after a Z-up one gets its own), unit length, the first row at the zenith, and cannot be changed."""
    import mitsuba as mi

    z, y = weather_scene.texel_directions(mi, "Z"), weather_scene.texel_directions(mi, "Y")
    assert weather_scene.texel_directions(mi, "Z") is z and weather_scene.texel_directions(mi, "Y") is y
    w, h = weather_scene.environment_texels(mi)
    assert z.shape == y.shape == (h, w, 3)
    np.testing.assert_allclose(np.linalg.norm(z, axis=2), 1.0, atol=1e-12)
    assert (z[0, :, 2] > 0.999).all() and (y[0, :, 1] > 0.999).all()       # the first row: the zenith
    np.testing.assert_allclose(y[..., 1], z[..., 2], atol=1e-6)              # the same map, turned
    with pytest.raises(ValueError):
        z[0, 0, 0] = 1.0


@pytest.mark.parametrize("name", ["clear_day", "sunset", "day_fog", "snow", "clear_night"])
def test_below_the_horizon_is_the_ground_a_real_plain_would_show(variant, name):
    import mitsuba as mi

    condition = CONDITIONS[name]
    scene, lighting = loaded_environment(mi, condition, "Z")
    dirs = directions("Z", np.array([-1.0, -10.0, -45.0, -89.0]), np.array([0.0, 90.0, 200.0, 300.0]))
    ground = weather_scene.radiance_towards(mi, environment_of(scene), dirs)
    assert np.all(ground > 0), ground
    np.testing.assert_allclose(ground, np.broadcast_to(ground[0], ground.shape), rtol=1e-5)  # one plain, any way
    albedo = weather_scene.GROUND_ALBEDO + (weather_scene.SNOW_ALBEDO - weather_scene.GROUND_ALBEDO) * condition.snow_cover
    if condition.sun_up:  # rendered: the sun and the sky of the map's upper half light a real plane
        lit = plane_radiance(mi, condition, "Z", np.array([0.0, 0.0, 1.0]), albedo, sky=True, spp=256)
        np.testing.assert_allclose(ground[0], lit, rtol=0.03)
    else:  # a uniform night sky of radiance L gives E = pi L
        np.testing.assert_allclose(ground[0], albedo * lighting.airlight, rtol=1e-5)


DAY = [c.name for c in SHIPPED if c.sun_up]


@pytest.mark.parametrize("scenario, camera, condition",
                         [(SCENARIO, "/World/Cameras/CCTV", name) for name in DAY]
                         + [(SCENARIO, "/World/Cameras/PedestrianEye", "clear_day"),
                            (DISTRICT / "scenario.usda", "/World/Cameras/PedestrianEye_Street", "clear_day")])
def test_views_past_the_modelled_ground_have_no_black_pixels(run_cli, tmp_path, scenario, camera, condition):
    """The demo street's CCTV looks past the street's end (15 % of its frame was black before the ground was in
    the environment), under every shipped day condition; its pedestrian eye and the district's street camera
    look at the horizon."""
    code, out, err = run_cli("render", scenario, "--camera", camera, "--condition", condition, "--width", "96",
                             "--height", "72", "--spp", "4", "--no-denoise", "--out", tmp_path / "r")
    assert code == 0, err
    overall, past_the_twin = black_shares(tmp_path / "r")
    assert past_the_twin == 0.0
    assert overall < 0.001  # a pixel of a deep shadow may come out black at 4 samples undenoised
