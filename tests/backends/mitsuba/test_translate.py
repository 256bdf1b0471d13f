"""The Mitsuba backend: translation without rendering, variants, and tiny renders."""

import math

import numpy as np
import pytest
from pxr import UsdGeom

from conftest import DATA
from synthua_usd.backends.mitsuba import variants
from synthua_usd.backends.mitsuba.render import load_scene, render_frame, trace_pixel_centres
from synthua_usd.backends.mitsuba.translate import bsdf_dict, translate
from synthua_usd.errors import InputError
from synthua_usd.render_config import RenderConfig
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.stage_io import open_stage


@pytest.fixture(scope="module")
def tiny(class_map):
    stage = open_stage(DATA / "valid" / "tiny_scene.usda")
    return read_snapshot(stage, 1.0, class_map), read_camera(stage, "/World/Cam", 1.0)


def test_translation_without_rendering(tiny):
    snap, cam = tiny
    mi = variants.activate(None)
    config = RenderConfig(width=64, height=48, spp=4)
    tr = translate(mi, snap, cam, config)
    sensor = tr.scene["sensor"]
    assert sensor["fov_axis"] == "x"
    assert sensor["fov"] == pytest.approx(math.degrees(2 * math.atan(36 / 2 / 20)))  # 20 mm on 36 mm film
    assert (sensor["film"]["width"], sensor["film"]["height"]) == (64, 48)
    assert sensor["sampler"]["sample_count"] == 4
    assert [s.prim_path for s in tr.shapes] == ["/World/Ground", "/World/Box"]
    assert [s.class_id for s in tr.shapes] == [1, 18]
    assert tr.scene["light_000"] == {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}


def test_loading_keeps_one_shape_per_gprim(demo_stage, class_map):
    mi = variants.activate(None)
    snap = read_snapshot(demo_stage, 1.0, class_map)
    cam = read_camera(demo_stage, "/World/Cameras/CCTV", 1.0)
    scene = load_scene(mi, translate(mi, snap, cam, RenderConfig(width=8, height=6, spp=1)))
    gprims = sum(1 for p in demo_stage.Traverse() if p.IsA(UsdGeom.Gprim))
    assert len(scene.shapes()) == len(snap.meshes) == gprims


def test_preview_surface_to_principled():
    from synthua_usd.scene import Material

    d = bsdf_dict(Material("m", (0.2, 0.3, 0.4), roughness=1.5, metallic=0.25))
    assert d == {"type": "principled", "base_color": {"type": "rgb", "value": [0.2, 0.3, 0.4]},
                 "roughness": 1.0, "metallic": 0.25}


def test_unknown_variant_is_an_input_error():
    with pytest.raises(InputError, match="variant 'teapot_rgb' is not in this Mitsuba build"):
        variants.activate("teapot_rgb")
    with pytest.raises(InputError, match="not an RGB variant"):
        variants.activate("scalar_spectral")


def test_scalar_and_jit_labels_are_identical(tiny):
    snap, cam = tiny
    config = RenderConfig(width=32, height=24, spp=1)
    results = {}
    for name in ("scalar_rgb", variants.activate(None).variant()):
        mi = variants.activate(name)
        tr = translate(mi, snap, cam, config)
        results[name] = trace_pixel_centres(mi, load_scene(mi, tr), tr, cam, 32, 24)
    a, b = results.values()
    # Scalar uses Mitsuba's own kd-tree, the JIT variants Embree/OptiX: both in float32, so a ray grazing
    # the far edge of the ground may land on either side. Everywhere else they agree exactly.
    differ = a.mesh_index != b.mesh_index
    assert differ.sum() <= 2, np.argwhere(differ)
    assert np.allclose(a.z_m[~differ], b.z_m[~differ], rtol=1e-4)


def test_tiny_render_rgb_is_lit_and_seeded(tiny):
    snap, cam = tiny
    config = RenderConfig(width=32, height=24, spp=4, seed=3)
    a = render_frame(snap, cam, config)
    b = render_frame(snap, cam, config)
    assert a.rgb.shape == (24, 32, 3) and a.rgb.dtype == np.float32
    # Same seed, same variant: the same image up to float32 rounding (LLVM's threads may accumulate the
    # film in another order, seen as 1-ulp differences).
    assert np.allclose(a.rgb, b.rgb, rtol=0, atol=1e-6)
    # Under a uniform white dome of radiance 1, a diffuse grey surface is lit but below 1.
    ground = a.class_ids == 1
    assert ground.any() and 0.02 < a.rgb[ground].mean() < 1.0
    # Rows that see only sky (and whose filter footprint does too) show the dome's radiance exactly.
    sky_rows = np.flatnonzero((a.class_ids == 0).all(axis=1))[:-2]
    assert len(sky_rows) > 3 and np.allclose(a.rgb[sky_rows], 1.0, atol=1e-5)


def test_render_config_refuses_bad_values():
    with pytest.raises(InputError, match="spp should be an integer >= 1, but was 0"):
        RenderConfig(spp=0)
    with pytest.raises(InputError, match=r"unknown keys \['colour'\]"):
        RenderConfig.from_dict({"colour": 1})
