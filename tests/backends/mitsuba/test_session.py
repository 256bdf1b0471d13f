"""A render session loads a scene once and updates it between frames; labels stay exact after updates."""

import numpy as np

from conftest import SCENARIO
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import StageReader, read_snapshot

SIZE = (32, 24)  # scalar traces label rays one at a time: tiny images


def camera(stage, name, time_code):
    return read_camera(stage, f"/World/Cameras/{name}", time_code)


def fresh_labels(stage, class_map, variant, name, time_code):
    """Labels of one frame from a new session and a new reader: nothing carried over from other frames."""
    session = RenderSession(RenderConfig(width=SIZE[0], height=SIZE[1], spp=1, variant=variant))
    return session.render(read_snapshot(stage, time_code, class_map), camera(stage, name, time_code), rgb=False)


def test_labels_after_updates_equal_a_fresh_render(demo_stage, class_map, variant):
    """Time code 24 from the CCTV after 1 (pedestrian eye) and 48 (wheelchair eye) through ONE session:
    the agents moved and the sensor moved twice, and class and instance maps are byte for byte those of
    a session that renders only 24."""
    session = RenderSession(RenderConfig(width=SIZE[0], height=SIZE[1], spp=1, variant=variant))
    reader = StageReader(demo_stage, class_map)
    session.render(reader.snapshot(1), camera(demo_stage, "PedestrianEye", 1), rgb=False)
    session.render(reader.snapshot(48), camera(demo_stage, "WheelchairEye", 48), rgb=False)
    updated = session.render(reader.snapshot(24), camera(demo_stage, "CCTV", 24), rgb=False)
    assert (session.loads, session.reloads) == (1, 0) and "update" in updated.seconds
    fresh = fresh_labels(demo_stage, class_map, variant, "CCTV", 24)
    assert updated.class_ids.tobytes() == fresh.class_ids.tobytes()
    assert updated.instance_ids.tobytes() == fresh.instance_ids.tobytes()
    assert np.array_equal(updated.hits.z_m, fresh.hits.z_m)
    # Not vacuous: the CCTV sees the agents move between 1 and 24, so a stale scene would differ.
    before = fresh_labels(demo_stage, class_map, variant, "CCTV", 1)
    assert (before.instance_ids != fresh.instance_ids).sum() > 0


def test_one_load_for_several_cameras_and_time_codes(demo_stage, class_map, variant):
    session = RenderSession(RenderConfig(width=16, height=12, spp=1, variant=variant))
    reader = StageReader(demo_stage, class_map)
    for time_code in (1, 12, 48):
        for name in ("CCTV", "PedestrianEye", "WheelchairEye"):
            frame = session.render(reader.snapshot(time_code), camera(demo_stage, name, time_code))
            assert frame.rgb.shape == (12, 16, 3)
    assert (session.loads, session.reloads) == (1, 0)


def test_another_scene_is_loaded_afresh_and_labelled_exactly(demo_stage, class_map, tiny, variant):
    config = RenderConfig(width=SIZE[0], height=SIZE[1], spp=1, variant=variant)
    session = RenderSession(config)
    session.render(read_snapshot(demo_stage, 1, class_map), camera(demo_stage, "CCTV", 1), rgb=False)
    snap, cam = tiny
    reloaded = session.render(snap, cam, rgb=False)
    assert (session.loads, session.reloads) == (2, 1) and "load" in reloaded.seconds
    fresh = RenderSession(config).render(snap, cam, rgb=False)
    assert reloaded.class_ids.tobytes() == fresh.class_ids.tobytes()
    assert reloaded.instance_ids.tobytes() == fresh.instance_ids.tobytes()


def test_rgb_after_updates_matches_a_fresh_render(demo_stage, class_map, variant):
    """The RGB pass sees the updated scene too: same seed, same image as a fresh session's."""
    config = RenderConfig(width=SIZE[0], height=SIZE[1], spp=2, seed=5, variant=variant)
    session = RenderSession(config)
    reader = StageReader(demo_stage, class_map)
    session.render(reader.snapshot(1), camera(demo_stage, "PedestrianEye", 1))
    updated = session.render(reader.snapshot(24), camera(demo_stage, "CCTV", 24))
    fresh = RenderSession(config).render(read_snapshot(demo_stage, 24, class_map), camera(demo_stage, "CCTV", 24))
    assert np.allclose(updated.rgb, fresh.rgb, rtol=0, atol=1e-5)


def test_time_code_updates_give_the_labels_of_a_fresh_load(class_map, variant):
    """Labels (class, instance, z-depth) of one session carried through time codes 1, 2, 3 and back to 1 of a
    stage with a rigidly moving agent, deforming points, a mirroring scale and a gprim that is hidden at 2
    equal, byte for byte, those of a new session and a new reader at each time code."""
    from conftest import DATA
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(DATA / "valid" / "animated_gprims.usda")
    config = RenderConfig(width=SIZE[0], height=SIZE[1], spp=1, variant=variant)
    session, reader = RenderSession(config), StageReader(stage, class_map)
    cam = read_camera(stage, "/World/Cam", 1)
    frames = {}
    for t in (1, 2, 3, 1):
        carried = session.render(reader.snapshot(t), cam, rgb=False)
        fresh = RenderSession(config).render(read_snapshot(stage, t, class_map), cam, rgb=False)
        assert carried.class_ids.tobytes() == fresh.class_ids.tobytes(), t
        assert carried.instance_ids.tobytes() == fresh.instance_ids.tobytes(), t
        assert np.array_equal(carried.hits.z_m, fresh.hits.z_m), t
        frames[t] = fresh
    # Not vacuous: the images change between time codes, so a stale scene would show.
    assert (frames[1].instance_ids != frames[2].instance_ids).sum() > 0
    assert (frames[2].instance_ids != frames[3].instance_ids).sum() > 0


def test_a_recoloured_material_reloads_and_renders_the_new_colour(class_map, variant):
    """A material edited after the scene loaded (its diffuseColor set in a layer of the session's stage): the
    session must not keep the old BSDF; its render equals a fresh session's of the edited stage."""
    from pxr import Gf, Sdf, Usd, UsdShade

    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(SCENARIO)
    reader = StageReader(stage, class_map)
    config = RenderConfig(width=SIZE[0], height=SIZE[1], spp=4, variant=variant, denoise=False)
    session = RenderSession(config)
    cam = read_camera(stage, "/World/Cameras/CCTV", 1.0)
    before = session.render(reader.snapshot(1.0), cam)
    shader = stage.GetPrimAtPath("/World/Looks/Asphalt/PreviewSurface")
    layer = Sdf.Layer.CreateAnonymous("edit.usda")
    stage.GetSessionLayer().subLayerPaths.insert(0, layer.identifier)
    with Usd.EditContext(stage, layer):
        UsdShade.Shader(shader).CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.9, 0.05, 0.05))
    after = session.render(reader.snapshot(1.0), cam)
    assert session.reloads == 1
    fresh = RenderSession(config).render(StageReader(stage, class_map).snapshot(1.0), cam)
    assert np.array_equal(after.rgb, fresh.rgb) and not np.array_equal(after.rgb, before.rgb)
