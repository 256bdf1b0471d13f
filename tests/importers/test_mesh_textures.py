"""The mesh importer keeps textures: OBJ/MTL ``map_Kd`` and glTF's PBR textures become images beside the twin
layer, UsdUVTexture networks in it and ``primvars:st`` on its meshes, and render where they should."""

from __future__ import annotations

import dataclasses

import numpy as np
import OpenImageIO as oiio
import pytest
import trimesh
from PIL import Image
from texture_checks import mitsuba_albedo, reference_albedo, srgb_decoded

from synthua_usd.backends.mitsuba import variants
from synthua_usd.importers.mesh import import_mesh
from synthua_usd.model.class_assignment import AssignmentRules
from synthua_usd.pipeline.twin_import import write_import
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.stage_io import open_stage

#: 8 wide, 6 tall, every texel different.
TEXELS = np.random.default_rng(11).integers(0, 256, (6, 8, 3), dtype=np.uint8)

OBJ = """mtllib wall.mtl
o Building_Wall
v 0 0 0
v 2 0 0
v 2 0 1
v 0 0 1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl brick
f 1/1 2/2 3/3 4/4
"""
MTL = "newmtl brick\nKd 1 1 1\nmap_Kd brick.png\n"


@pytest.fixture
def rules(class_map):
    return AssignmentRules.from_document({"rules": [{"field": "object", "pattern": "(?i)wall|box", "class": "building"}]},
                                         class_map)


def test_obj_mtl_texture_is_kept_written_and_rendered(tmp_path, rules, class_map):
    (tmp_path / "wall.obj").write_text(OBJ)
    (tmp_path / "wall.mtl").write_text(MTL)
    Image.fromarray(TEXELS).save(tmp_path / "brick.png")
    model = import_mesh(tmp_path / "wall.obj", rules)
    material = model.materials["brick"]
    assert material.base_color_texture.path == "textures/brick_base_color.png"
    assert np.array_equal(model.images["textures/brick_base_color.png"], TEXELS)
    (part,) = model.objects[0].parts
    assert part.uvs is not None and len(part.uvs) == len(part.points)

    out = tmp_path / "twin"
    written, _ = write_import(model, out, class_map, model.report)
    image = out / "textures" / "brick_base_color.png"
    assert image in written and image.is_file()
    assert np.array_equal(oiio.ImageBuf(str(image)).get_pixels(oiio.UINT8), TEXELS)

    stage = open_stage(out / "scenario.usda")
    snap = read_snapshot(stage, 1.0, class_map)
    read = snap.materials["/World/Looks/brick"]
    assert read.base_color_texture.path == str(image.resolve()) and read.base_color_texture.color_space == "sRGB"
    mesh, ground = snap.meshes  # the wall, and the generated ground (no texture coordinates)
    assert ground.prim_path.startswith("/World/Twin/Ground") and ground.uvs is None
    # The OBJ's st at its corners, the texture upright on the wall.
    corner = {tuple(np.round(p, 6)): tuple(uv) for p, uv in zip(mesh.points, mesh.uvs)}
    assert corner[(0.0, 0.0, 0.0)] == (0.0, 0.0) and corner[(2.0, 0.0, 1.0)] == (1.0, 1.0)
    mi = variants.activate("scalar_rgb")
    cam = read_camera(stage, "/World/Cameras/Overview", 1.0)
    wall = dataclasses.replace(snap, meshes=(mesh,))
    expected, hit_ref = reference_albedo(wall, cam, srgb_decoded(TEXELS), 48, 32)
    got, hit = mitsuba_albedo(mi, wall, cam, 48, 32)
    both = hit & hit_ref
    assert both.sum() > 50
    assert np.abs(got[both] - expected[both]).max() < 2e-3


def test_glb_pbr_textures_become_usd_textures(tmp_path, rules, class_map):
    box = trimesh.creation.box()
    uv = np.random.default_rng(1).random((len(box.vertices), 2))
    base = Image.fromarray(np.random.default_rng(2).integers(0, 256, (6, 8, 4), dtype=np.uint8), "RGBA")
    orm = Image.fromarray(np.random.default_rng(3).integers(0, 256, (4, 4, 3), dtype=np.uint8))
    normal = Image.fromarray(np.full((4, 4, 3), (128, 128, 255), np.uint8))
    box.visual = trimesh.visual.TextureVisuals(uv=uv, material=trimesh.visual.material.PBRMaterial(
        name="paint", baseColorTexture=base, baseColorFactor=[255, 128, 255, 255], metallicFactor=0.2,
        roughnessFactor=0.7, metallicRoughnessTexture=orm, normalTexture=normal, alphaMode="MASK", alphaCutoff=0.4))
    scene = trimesh.Scene()
    scene.add_geometry(box, node_name="Box", geom_name="box_mesh")
    scene.export(tmp_path / "box.glb")

    model = import_mesh(tmp_path / "box.glb", rules)
    out = tmp_path / "twin"
    write_import(model, out, class_map, model.report)
    assert sorted(p.name for p in (out / "textures").iterdir()) == ["paint_base_color.png", "paint_metallic_roughness.png",
                                                                     "paint_normal.png"]
    snap = read_snapshot(open_stage(out / "scenario.usda"), 1.0, class_map)
    m = snap.materials["/World/Looks/paint"]
    assert m.base_color_texture.scale == pytest.approx((1.0, 128 / 255, 1.0, 1.0))
    assert (m.roughness_texture.channel, m.roughness_texture.scale[0]) == ("g", pytest.approx(0.7))
    assert (m.metallic_texture.channel, m.metallic_texture.scale[0]) == ("b", pytest.approx(0.2))
    assert m.roughness_texture.color_space == m.metallic_texture.color_space == m.normal_texture.color_space == "raw"
    assert m.normal_texture.scale == (2.0, 2.0, 2.0, 1.0) and m.normal_texture.bias == (-1.0, -1.0, -1.0, 0.0)
    assert (m.opacity_texture.channel, m.opacity_threshold) == ("a", pytest.approx(0.4))
    mesh, _ = snap.meshes  # the box and the generated ground
    assert mesh.uvs is not None and mesh.triangles.shape == (12, 3)
    # glTF's v runs down the image; trimesh flips it on load, so the st that reach USD are the ones given.
    assert sorted(map(tuple, np.round(mesh.uvs, 5))) == sorted(map(tuple, np.round(uv.astype(np.float32), 5)))


def test_a_mesh_without_textures_writes_no_texture_folder(tmp_path, rules, class_map):
    trimesh.creation.box().export(tmp_path / "box.glb")
    model = import_mesh(tmp_path / "box.glb", rules)
    assert model.images == {} and model.report["textures"] == []
    write_import(model, tmp_path / "twin", class_map, model.report)
    assert not (tmp_path / "twin" / "textures").exists()


@pytest.mark.parametrize("content, reason", [(None, "not found"), (b"not an image", "Not a PNG file")])
def test_a_texture_the_mtl_names_but_cannot_be_read_is_named_with_the_reason(tmp_path, rules, caplog, content,
                                                                            reason):
    """trimesh drops such an image silently (a debug note): the import names the material, the file and why."""
    (tmp_path / "wall.obj").write_text(OBJ)
    (tmp_path / "wall.mtl").write_text(MTL)
    if content is not None:
        (tmp_path / "brick.png").write_bytes(content)
    with caplog.at_level("WARNING"):
        model = import_mesh(tmp_path / "wall.obj", rules)
    assert not model.materials["brick"].textures
    assert f"wall.obj: material 'brick': texture 'brick.png' cannot be read: {reason}; the material renders" in caplog.text


def test_trimesh_notes_of_images_it_could_not_load_are_collected():
    import logging

    from synthua_usd.importers.mesh_materials import ImageFailures

    with ImageFailures() as failures:
        try:
            raise OSError("cannot identify image file")
        except OSError:
            logging.getLogger("trimesh.exchange.gltf").debug("failed to load image!", exc_info=True)
    assert failures.reasons == ["OSError: cannot identify image file"]
    assert not logging.getLogger("trimesh").handlers or all(not isinstance(h, ImageFailures)
                                                           for h in logging.getLogger("trimesh").handlers)
