"""Rendering a translated scene: path-traced RGB and exact pixel-centre labels, on tiny images."""

import numpy as np

from conftest import activate_variant
from synthua_usd.backends.mitsuba.render import trace_pixel_centres
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.backends.mitsuba.translate import translate
from synthua_usd.model.render_config import RenderConfig


def test_scalar_and_jit_labels_are_identical(tiny):
    snap, cam = tiny
    config = RenderConfig(width=32, height=24, spp=1)
    results = {}
    for name in ("scalar_rgb", "llvm_ad_rgb"):
        mi = activate_variant(name)
        tr = translate(mi, snap, cam, config)
        results[name] = trace_pixel_centres(mi, tr.load(mi), tr.shape_ids, cam, 32, 24)
    a, b = results.values()
    # Scalar uses Mitsuba's own kd-tree, the JIT variants Embree/OptiX: both in float32, so a ray grazing
    # the far edge of the ground may land on either side. Everywhere else they agree exactly.
    assert (a.mesh_index >= 0).any() and (a.mesh_index == 1).any()  # both the ground and the box are seen
    differ = a.mesh_index != b.mesh_index
    assert differ.sum() <= 2, np.argwhere(differ)
    assert np.allclose(a.z_m[~differ], b.z_m[~differ], rtol=1e-4)


def test_labels_are_the_classes_and_instances_of_the_hit_meshes(tiny, variant):
    snap, cam = tiny
    frame = RenderSession(RenderConfig(width=32, height=24, spp=1, variant=variant)).render(snap, cam, rgb=False)
    assert frame.rgb is None and frame.variant == variant
    hit = frame.hits.mesh_index
    for k, mesh in enumerate(snap.meshes):
        assert (hit == k).any(), mesh.prim_path
        assert set(np.unique(frame.class_ids[hit == k])) == {mesh.class_id}
        assert set(np.unique(frame.instance_ids[hit == k])) == {mesh.instance_id}
    assert not frame.class_ids[hit < 0].any() and not frame.instance_ids[hit < 0].any()
    assert frame.class_ids.dtype == np.uint8 and frame.instance_ids.dtype == np.uint16


def test_tiny_render_rgb_is_lit_and_seeded(tiny, variant):
    snap, cam = tiny
    # The path tracer itself (tests/backends/mitsuba/test_denoised_render.py covers denoising).
    config = RenderConfig(width=32, height=24, spp=4, seed=3, denoise=False, variant=variant)
    a = RenderSession(config).render(snap, cam)
    b = RenderSession(config).render(snap, cam)
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
    # Another seed draws other samples.
    c = RenderSession(RenderConfig(width=32, height=24, spp=4, seed=4, denoise=False, variant=variant)).render(snap, cam)
    assert not np.allclose(a.rgb[ground], c.rgb[ground], rtol=0, atol=1e-6)


def test_the_raw_ray_bound_traces_one_ray_per_pixel(tiny, variant):
    from synthua_usd.backends.mitsuba.render import intersect_pixel_centres

    snap, cam = tiny
    session = RenderSession(RenderConfig(width=16, height=12, spp=1, variant=variant))
    assert session.mitsuba_scene is None
    session.render(snap, cam, rgb=False)
    assert intersect_pixel_centres(session.mi, session.mitsuba_scene, cam, 16, 12) == 16 * 12
