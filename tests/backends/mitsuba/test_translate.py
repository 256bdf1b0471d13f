"""Translation of a snapshot into a Mitsuba scene description, without rendering, on every variant."""

import math

import numpy as np
import pytest
from pxr import UsdGeom

from synthua_usd.backends.mitsuba import variants
from synthua_usd.backends.mitsuba.surfaces import principled_dict
from synthua_usd.backends.mitsuba.translate import DOME_WEIGHT_SHARE, translate
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.scene import Material
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.semantics import renderable_gprims


def loaded_shapes(mi, translation) -> dict:
    """The loaded scene's shapes by Mitsuba id (``optimize=False``, as the render session loads it)."""
    scene = translation.load(mi)
    return {s.id(): s for s in scene.shapes()}


def test_translation_without_rendering(tiny, variant):
    snap, cam = tiny
    mi = variants.activate(variant)
    tr = translate(mi, snap, cam, RenderConfig(width=64, height=48, spp=4))
    sensor = tr.scene["sensor"]
    assert sensor["fov_axis"] == "x"
    assert sensor["fov"] == pytest.approx(math.degrees(2 * math.atan(36 / 2 / 20)))  # 20 mm on 36 mm film
    assert (sensor["film"]["width"], sensor["film"]["height"]) == (64, 48)
    assert sensor["sampler"]["sample_count"] == 4
    # the only light: its weight does not matter to Mitsuba's choice, it is the dome's illuminance share
    assert tr.scene["light_000"] == {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]},
                                     "sampling_weight": pytest.approx(math.pi * DOME_WEIGHT_SHARE)}
    # One shape per snapshot mesh, in the snapshot's order: labels look up prim paths and classes by it.
    assert [m.prim_path for m in snap.meshes] == ["/World/Ground", "/World/Box"]
    assert [m.class_id for m in snap.meshes] == [1, 18]
    assert len(tr.shape_ids) == len(set(tr.shape_ids)) == len(snap.meshes)


def test_shape_ids_are_aligned_with_the_snapshot_meshes(tiny, variant):
    snap, cam = tiny
    mi = variants.activate(variant)
    tr = translate(mi, snap, cam, RenderConfig(width=8, height=6, spp=1))
    shapes = loaded_shapes(mi, tr)
    for key, mesh in zip(tr.shape_ids, snap.meshes, strict=True):
        shape = shapes[key]
        assert (shape.vertex_count(), shape.face_count()) == (len(mesh.points), len(mesh.triangles)), mesh.prim_path
        positions = np.asarray(mi.traverse(shape)["vertex_positions"], np.float32).reshape(-1, 3)
        assert np.array_equal(positions, mesh.points.astype(np.float32)), mesh.prim_path


def test_loading_keeps_one_shape_per_gprim(demo_stage, class_map, variant):
    mi = variants.activate(variant)
    snap = read_snapshot(demo_stage, 1.0, class_map)
    cam = read_camera(demo_stage, "/World/Cameras/CCTV", 1.0)
    tr = translate(mi, snap, cam, RenderConfig(width=8, height=6, spp=1))
    shapes = loaded_shapes(mi, tr)
    gprims = len(renderable_gprims(demo_stage))
    assert len(shapes) == len(snap.meshes) == gprims
    assert set(shapes) == set(tr.shape_ids)


def test_preview_surface_to_principled():
    material = Material("m", (0.2, 0.3, 0.4), roughness=1.5, metallic=0.25)
    d, values = principled_dict(material)
    assert d == {"type": "principled", "base_color": {"type": "rgb", "value": [0.2, 0.3, 0.4]},
                 "roughness": 1.0, "metallic": 0.25} and values == {}


def test_materials_of_one_kind_are_one_bsdf_reading_the_shapes_rows(class_map):
    """With shape tables (JIT variants) a material's constants are columns of the tables, the same for every
    material of one kind: the BSDF dicts of two colours are equal and the values are the constants."""
    from conftest import activate_variant
    from synthua_usd.backends.mitsuba.shape_tables import ShapeTables

    mi = activate_variant("llvm_ad_rgb")
    tables = ShapeTables(mi)
    a, values_a = principled_dict(Material("a", (0.2, 0.3, 0.4), roughness=1.5, metallic=0.25), tables=tables)
    b, values_b = principled_dict(Material("b", (0.9, 0.1, 0.0), roughness=0.2), tables=tables)
    assert a == b and a["base_color"] is tables.value("base_color", 3)
    assert values_a == {"base_color": [0.2, 0.3, 0.4], "roughness": 1.0, "metallic": 0.25}
    assert values_b == {"base_color": [0.9, 0.1, 0.0], "roughness": 0.2, "metallic": 0.0}
    coated, values_c = principled_dict(Material("c", clearcoat=0.5, clearcoat_roughness=0.25), tables=tables)
    assert coated != a and values_c["clearcoat"] == 0.5 and values_c["clearcoat_gloss"] == 0.75


def test_sun_and_sky_are_sampled_by_the_illuminance_they_bring(class_map, variant):
    """Without a condition each UsdLux light's emitter-sampling weight is the illuminance it brings to an up-facing
    surface (the dome's scaled by DOME_WEIGHT_SHARE), computed here from the stage's authored values; with a
    condition the stage's own sun and sky are left out and nothing is weighted here."""
    from conftest import DATA
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(DATA / "valid" / "tiny_lit_scene.usda")
    snap = read_snapshot(stage, 1.0, class_map)
    mi = variants.activate(variant)
    tr = translate(mi, snap, read_camera(stage, "/World/Cam", 1.0), RenderConfig(width=8, height=6, spp=1))
    emitters = {d["type"]: d for k, d in tr.scene.items() if k.startswith("light_")}
    # authored: DistantLight intensity 3 rotated (35, 0, -30) from -Z; DomeLight intensity 0.6; both white
    # (the reader's colours are checked elsewhere: take them from the snapshot)
    sun, sky = (next(l for l in snap.lights if l.kind == kind) for kind in ("distant", "dome"))
    cos_sun = math.cos(math.radians(35))  # rotateXYZ (35, 0, -30) tilts -Z by 35 degrees from the nadir
    assert emitters["directional"]["sampling_weight"] == pytest.approx(3 * np.mean(sun.color) * cos_sun, rel=1e-5)
    assert emitters["constant"]["sampling_weight"] == pytest.approx(
        math.pi * 0.6 * np.mean(sky.color) * DOME_WEIGHT_SHARE, rel=1e-5)
    assert emitters["directional"]["sampling_weight"] > 4 * emitters["constant"]["sampling_weight"]


def test_authored_normals_shade_smoothly_and_move_with_the_points(tmp_path, class_map):
    """At every pixel-centre hit on a sphere with authored normals, Mitsuba's shading normal is the snapshot's
    normals interpolated barycentrically at the Embree hit (within 1 degree), not the facet's; without normals it is
    the facet's own. After a render session updates the moved sphere (its holder turned), the shading normals are
    the new snapshot's, not normals Mitsuba computed itself."""
    import trimesh

    from normal_scenes import sphere_stage
    from synthua_usd.backends.mitsuba import variants
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.cameras import PinholeCamera
    from synthua_usd.model import meshes as geo
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.usd.reader import StageReader

    mi = variants.activate("llvm_ad_rgb")
    W = H = 48
    camera = PinholeCamera(path="/Cam", focal_length_mm=50.0, horizontal_aperture_mm=36.0, vertical_aperture_mm=36.0,
                           clip_near_m=0.1, clip_far_m=100.0,
                           camera_to_world=geo.look_at((0.0, -6.0, 1.5), (0.0, 0.0, 0.0)))

    def shading_normals(scene, snapshot):
        origins, dirs = (a.astype(np.float32) for a in camera.pixel_center_rays(W, H))
        si = scene.ray_intersect(mi.Ray3f(mi.Point3f(*origins.T), mi.Vector3f(*dirs.T)))
        got = np.array(si.sh_frame.n).T
        item = snapshot.meshes[0]
        mesh = trimesh.Trimesh(item.points, item.triangles, process=False, validate=False)
        tri, ray, where = mesh.ray.intersects_id(camera.pixel_center_rays(W, H)[0], camera.pixel_center_rays(W, H)[1],
                                                 multiple_hits=False, return_locations=True)
        return got[ray], item, tri, where

    def angle(a, b):
        b = b / np.linalg.norm(b, axis=1, keepdims=True)
        return np.degrees(np.arccos(np.clip((a * b).sum(axis=1), -1, 1)))

    for kind in ("vertex", None):
        stage = sphere_stage(tmp_path / f"{kind}.usda", kind)
        snapshot = StageReader(stage, class_map).snapshot(1.0)
        scene = mi.load_dict(translate(mi, snapshot, camera, RenderConfig(width=W, height=H)).scene, optimize=False)
        got, item, tri, where = shading_normals(scene, snapshot)
        assert len(got) > 300
        if kind is None:
            assert item.normals is None
            expected = trimesh.Trimesh(item.points, item.triangles, process=False).face_normals[tri]
        else:
            bary = trimesh.triangles.points_to_barycentric(item.points[item.triangles[tri]], where)
            expected = np.einsum("kc,kcd->kd", bary, item.normals[item.triangles[tri]].astype(np.float64))
            facets = trimesh.Trimesh(item.points, item.triangles, process=False).face_normals[tri]
            assert np.median(angle(got, facets)) > 2.0  # smooth shading differs from the facets
        assert angle(got, expected).max() < 1.0, kind

    stage = sphere_stage(tmp_path / "moving.usda", "vertex")
    reader = StageReader(stage, class_map)
    session = RenderSession(RenderConfig(width=W, height=H, spp=1, variant="llvm_ad_rgb"))
    session.render(reader.snapshot(1.0), camera, rgb=False)
    UsdGeom.Xformable(stage.GetPrimAtPath("/World/Holder")).GetOrderedXformOps()[0].Set(75.0)
    moved = reader.snapshot(1.0)
    loads = session.loads
    session.render(moved, camera, rgb=False)
    assert session.loads == loads  # updated in place
    got, item, tri, where = shading_normals(session.mitsuba_scene, moved)
    bary = trimesh.triangles.points_to_barycentric(item.points[item.triangles[tri]], where)
    expected = np.einsum("kc,kcd->kd", bary, item.normals[item.triangles[tri]].astype(np.float64))
    assert angle(got, expected).max() < 1.0
