"""Conditions in the renderer, on a tiny street with a lamp post, a lit window and a car's head lamps:
labels never change, conditions swap in the loaded scene, night is lit by the street, sunset is warm and
low, wet ground is darker, snow lies on upward faces."""

import dataclasses

import numpy as np
import pytest

from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.backends.mitsuba.weather_scene import LightMeter, face_weights, wet_albedo
from synthua_usd.model.conditions import SHIPPED, display_order
from synthua_usd.model.photometry import CD_PER_M2_PER_UNIT, luminance
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.scene import MeshItem
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.conditions import condition_names, read_condition
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_io import open_stage

SIZE, SPP = (64, 48), 8
#: Mean display-linear luminance (after exposure, clipped to 1) a night frame of the lamp street must have.
NIGHT_BAND = (0.05, 0.5)


@pytest.fixture(scope="module")
def street(lamps_scenario, class_map, variant):
    """Stage, snapshot, camera and one session of ``variant`` that has rendered every condition in order."""
    stage = open_stage(lamps_scenario)
    snapshot = StageReader(stage, class_map).snapshot(1)
    camera = read_camera(stage, "/World/Cam", 1)
    session = RenderSession(RenderConfig(width=SIZE[0], height=SIZE[1], spp=SPP, variant=variant))
    conditions = {name: read_condition(stage, name) for name in display_order(condition_names(stage))}
    frames = {name: session.render(snapshot, camera, condition=c) for name, c in conditions.items()}
    counts = (session.loads, session.reloads)
    return dict(stage=stage, snapshot=snapshot, camera=camera, session=session, conditions=conditions,
                frames=frames, counts=counts, variant=variant)


def render(street, condition):
    session = RenderSession(RenderConfig(width=SIZE[0], height=SIZE[1], spp=SPP, variant=street["variant"]))
    return session.render(street["snapshot"], street["camera"], condition=condition)


def class_mask(frame, class_map, name):
    return frame.class_ids == class_map.resolve(name).id


def test_labels_are_byte_identical_under_every_condition(street):
    frames = list(street["frames"].values())
    assert len(frames) == len(SHIPPED) == 7
    first = frames[0]
    for frame in frames[1:]:
        assert frame.class_ids.tobytes() == first.class_ids.tobytes()
        assert frame.instance_ids.tobytes() == first.instance_ids.tobytes()
        assert frame.hits.z_m.tobytes() == first.hits.z_m.tobytes()
    assert len(np.unique(first.instance_ids)) >= 6  # road, house, window, pole, lantern, car, person: seen


def test_conditions_swap_in_the_loaded_scene_and_reload_only_when_they_must(street):
    # clear_day loads; day_fog swaps in place; day_rain_fog (wet), clear_night (dry again), night_rain_fog
    # (wet), sunset (sun up, dry) and snow (snow) each change what the scene is built with.
    assert street["counts"] == (6, 5)
    assert "update" in street["frames"]["day_fog"].seconds and "load" in street["frames"]["snow"].seconds
    session, c = street["session"], street["conditions"]
    assert "load" in session.render(street["snapshot"], street["camera"], condition=c["sunset"]).seconds  # from snow
    loads = session.loads
    for name in ("clear_day", "day_fog", "sunset", "clear_night", "clear_day"):  # the sun moves or sets, fog
        # thickens: parameters only
        frame = session.render(street["snapshot"], street["camera"], condition=c[name])
        assert "update" in frame.seconds
    assert session.loads == loads


def test_a_condition_swapped_in_renders_what_a_fresh_load_renders(street):
    c = street["conditions"]
    session = RenderSession(RenderConfig(width=SIZE[0], height=SIZE[1], spp=SPP, variant=street["variant"]))
    session.render(street["snapshot"], street["camera"], condition=c["sunset"])
    for name in ("day_fog", "clear_night"):
        swapped = session.render(street["snapshot"], street["camera"], condition=c[name])
        fresh = render(street, c[name])
        assert session.loads == 1
        assert np.allclose(swapped.rgb, fresh.rgb, rtol=1e-4, atol=1e-7), name


def test_night_is_lit_by_the_street(street, class_map):
    night = street["frames"]["clear_night"]
    shown = np.clip(night.rgb * night.exposure.scale, 0.0, 1.0)
    assert NIGHT_BAND[0] <= luminance(shown).mean() <= NIGHT_BAND[1]
    assert not night.exposure.clamped
    dark = render(street, dataclasses.replace(street["conditions"]["clear_night"], street_lights_on=False,
                                               vehicle_lamps_on=False, lit_window_fraction=0.0))
    # Without its lamps the same night is at least 10x darker: the light comes from the street, not the sky.
    assert night.exposure.log_average_cd_m2 > 10 * dark.exposure.log_average_cd_m2
    # The lamps themselves glow: the lantern is among the brightest things in the frame.
    lantern = class_mask(night, class_map, "luminaire")
    assert lantern.any() and luminance(night.rgb)[lantern].mean() > np.percentile(luminance(night.rgb), 95)


def test_sunset_is_warmer_and_lower_than_noon(street):
    import mitsuba as mi

    c = street["conditions"]
    noon, sunset = c["clear_day"], c["sunset"]
    assert sunset.sun_direction()[2] < 0.1 < noon.sun_direction()[2]
    meter = LightMeter(mi)
    noon_sun, noon_sky = meter.measure(noon.sun_direction(), noon.turbidity, 0.2, "Z")
    low_sun, low_sky = meter.measure(sunset.sun_direction(), sunset.turbidity, 0.2, "Z")
    assert low_sky[0] / low_sky[2] > noon_sky[0] / noon_sky[2]  # the sky's red/blue ratio
    assert low_sun[0] / low_sun[2] > 3 * noon_sun[0] / noon_sun[2]  # the sun's
    f = street["frames"]
    warmth = {name: f[name].rgb[..., 0].mean() / f[name].rgb[..., 2].mean() for name in ("clear_day", "sunset")}
    assert warmth["sunset"] > warmth["clear_day"]


def test_daylight_illuminance_is_that_of_a_clear_noon():
    import mitsuba as mi

    noon = SHIPPED[0]
    sun, sky = LightMeter(mi).measure(noon.sun_direction(), noon.turbidity, 0.2, "Z")
    lux = float(luminance(sun + sky)) * CD_PER_M2_PER_UNIT
    assert 90_000 < lux < 130_000


def test_wet_ground_is_darker_than_dry(street, class_map):
    assert np.all(wet_albedo(np.linspace(0.01, 1.0, 50)) < np.linspace(0.01, 1.0, 50))
    dry = street["frames"]["clear_day"]
    wet = render(street, dataclasses.replace(street["conditions"]["clear_day"], ground_wetness=1.0))
    road = class_mask(dry, class_map, "road")
    assert luminance(wet.rgb)[road].mean() < 0.8 * luminance(dry.rgb)[road].mean()
    # Only upward faces of ground classes get wet: the road's top, not a house, not the road's underside.
    up = np.array([0.0, 0.0, 1.0])
    wet_condition = dataclasses.replace(street["conditions"]["clear_day"], ground_wetness=1.0)
    road_mesh = next(m for m in street["snapshot"].meshes if m.prim_path == "/World/Road")
    house_mesh = next(m for m in street["snapshot"].meshes if m.prim_path == "/World/House")
    assert np.all(face_weights(road_mesh, "road", up, wet_condition)["face_wet"] == 1.0)
    assert face_weights(house_mesh, "building", up, wet_condition) == {}


def test_snow_lies_on_upward_faces(street, class_map):
    up = np.array([0.0, 0.0, 1.0])
    box = MeshItem("/b", np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1]], float),
                   np.array([[0, 1, 2], [0, 2, 3], [0, 1, 5], [0, 5, 4]]), "m", 1, 1)
    snow = street["conditions"]["snow"]
    weights = face_weights(box, "building", up, snow)["face_snow"]
    assert np.allclose(weights, [1.0, 1.0, 0.0, 0.0])  # the floor up, the wall not
    assert face_weights(box, "person", up, snow) == {}
    dry = street["frames"]["clear_day"]
    white = render(street, dataclasses.replace(street["conditions"]["clear_day"], snow_cover=1.0))
    road = class_mask(dry, class_map, "road")
    assert luminance(white.rgb)[road].mean() > 2 * luminance(dry.rgb)[road].mean()
