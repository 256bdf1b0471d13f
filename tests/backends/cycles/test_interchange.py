"""The Cycles interchange: what :func:`write_interchange` writes is what the Cycles script reads, and Cycles
renders it (skipped, with the reason, where no interpreter with bpy is installed)."""

import dataclasses
import json

import numpy as np
import pytest

from conftest import DATA
from synthua_usd.backends.cycles.interchange import GEOMETRY, SCENE, read_interchange, write_interchange


@pytest.fixture(scope="module")
def lit(class_map):
    """(snapshot, camera) of tests/data/valid/tiny_lit_scene.usda: ground, box, sun and sky."""
    from synthua_usd.usd.cameras import camera_paths, read_camera
    from synthua_usd.usd.reader import read_snapshot
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(DATA / "valid" / "tiny_lit_scene.usda")
    return read_snapshot(stage, 1.0, class_map), read_camera(stage, camera_paths(stage)[0], 1.0)


def test_round_trip_keeps_triangles_materials_lights_and_camera(lit, tmp_path):
    snap, cam = lit
    write_interchange(snap, cam, 64, 48, tmp_path)
    assert (tmp_path / GEOMETRY).is_file() and (tmp_path / SCENE).is_file()
    doc, soups = read_interchange(tmp_path)
    assert sum(len(t) for _, t, _ in soups) == snap.triangle_count()
    assert {m["key"] for m in doc["materials"]} == {m.material_key for m in snap.meshes}
    for material, (points, triangles, uvs) in zip(doc["materials"], soups):
        meshes = [m for m in snap.meshes if m.material_key == material["key"]]
        assert material["triangles"] == len(triangles) == sum(len(m.triangles) for m in meshes)
        assert points.dtype == np.float32 and triangles.dtype == np.int32 and triangles.max() < len(points)
        assert uvs is None and not material["textured"] and material["textures"] == {}  # no textures here
        source = snap.materials[material["key"]]
        assert material["base_color"] == pytest.approx(list(source.base_color))
        assert (material["roughness"], material["metallic"]) == pytest.approx((source.roughness, source.metallic))
        # the merged soup is the meshes' own world-space triangles, in order
        expected, _, _ = snap.world_triangles(meshes)
        assert np.allclose(points, expected, atol=1e-5)
    assert [(l["kind"], l["irradiance"], l["radiance"]) for l in doc["lights"]] == \
        [(l.kind, l.irradiance, l.radiance) for l in snap.lights]
    camera = doc["camera"]
    assert (camera["fov_x_deg"], camera["fov_y_deg"]) == pytest.approx(cam.fov_deg(64, 48))
    assert np.allclose(camera["camera_to_world"], cam.camera_to_world)
    assert (camera["clip_near_m"], camera["clip_far_m"]) == (cam.clip_near_m, cam.clip_far_m)
    assert (doc["width"], doc["height"]) == (64, 48)


def test_a_distorted_camera_is_refused(lit, tmp_path):
    from synthua_usd.model.distortion import BrownConrady

    snap, cam = lit
    distorted = dataclasses.replace(cam, distortion=BrownConrady(k1=0.1))
    with pytest.raises(ValueError, match="distortion"):
        write_interchange(snap, distorted, 64, 48, tmp_path)


def test_another_format_version_is_refused(lit, tmp_path):
    snap, cam = lit
    write_interchange(snap, cam, 16, 12, tmp_path)
    doc = json.loads((tmp_path / SCENE).read_text())
    (tmp_path / SCENE).write_text(json.dumps(dict(doc, format=99)))
    with pytest.raises(ValueError, match="format 99"):
        read_interchange(tmp_path)


def test_a_missing_cycles_interpreter_says_so_in_one_line(tmp_path):
    from synthua_usd.backends.cycles.runner import CyclesUnavailable, find_cycles_python

    with pytest.raises(CyclesUnavailable, match="Blender \\(bpy\\) is not installed") as info:
        find_cycles_python(tmp_path / "no-python")
    assert "\n" not in str(info.value) and "setup_cycles.sh" in str(info.value)


@pytest.mark.slow
def test_cycles_renders_the_exported_scene_like_mitsuba(lit, tmp_path):
    from synthua_usd.backends.cycles.runner import CyclesJob, CyclesUnavailable, find_cycles_python, render_jobs
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig

    try:
        python = find_cycles_python()
    except CyclesUnavailable as exc:
        pytest.skip(f"{exc} (the Cycles comparison needs it; the rest of synthua does not)")
    snap, cam = lit
    write_interchange(snap, cam, 32, 24, tmp_path / "scene")
    jobs = [CyclesJob("a", 64), CyclesJob("b", 4, denoise=True, adaptive=True)]
    result = render_jobs(python, tmp_path / "scene", jobs, tmp_path / "out", threads=2, max_bounces=2, timeout_s=300)
    assert set(result.images) == {"a", "b"} and all(s > 0 for s in result.seconds.values())
    image = result.images["a"]
    assert image.shape == (24, 32, 3) and image.dtype == np.float32 and np.isfinite(image).all()
    mitsuba = RenderSession(RenderConfig(width=32, height=24, spp=64, max_depth=4)).render(snap, cam).rgb
    # same scene, same units: the mean colours agree within the renderers' BSDF differences
    assert np.allclose(image.mean(axis=(0, 1)), mitsuba.mean(axis=(0, 1)), rtol=0.15)
