"""Textured materials rendered by Mitsuba, checked against an independent computation
(tests/texture_checks.py: Embree hits, the reader's uvs, a numpy texel lookup, colour-science's sRGB)."""

from __future__ import annotations

import logging
import shutil

import numpy as np
import OpenImageIO as oiio
import pytest
from conftest import DATA, third_party
from texture_checks import (TEXELS, add_texture, lit_from, mitsuba_albedo, reference_albedo, srgb_decoded,
                            textured_quads, write_png)
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade

from synthua_usd.backends.mitsuba import variants
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import StageReader, read_snapshot
from synthua_usd.usd.stage_io import open_stage

W, H = 64, 48


@pytest.fixture
def quads(tmp_path):
    """tests/data/valid/textured_quads.usda in tmp_path with TEXELS as its texture."""
    return textured_quads(tmp_path)


@pytest.mark.parametrize("space", ["sRGB", "raw", "auto"])
def test_texels_land_where_the_independent_lookup_puts_them(quads, class_map, variant, space):
    mi = variants.activate(variant)
    stage = open_stage(quads)
    stage.GetPrimAtPath("/World/Looks/Quadrants/Image").GetAttribute("inputs:sourceColorSpace").Set(space)
    snap = read_snapshot(stage, 1.0, class_map)
    cam = read_camera(stage, "/World/Cam", 1.0)
    decoded = TEXELS / 255.0 if space == "raw" else srgb_decoded(TEXELS)  # auto: an 8-bit RGB PNG is sRGB
    expected, hit_ref = reference_albedo(snap, cam, decoded, W, H)
    got, hit = mitsuba_albedo(mi, snap, cam, W, H)
    assert np.array_equal(hit, hit_ref)
    assert hit.sum() > 0.35 * W * H  # the quads cover 43 % of the view
    # Both quads: Left's st per point, Right's per face corner (indexed).
    assert np.abs(got[hit] - expected[hit]).max() < 2e-3


def test_face_varying_seams_split_points_but_keep_triangles(quads, class_map):
    stage = open_stage(quads)
    right = UsdGeom.Mesh(stage.GetPrimAtPath("/World/Right"))
    # The second triangle maps the image mirrored: its corners disagree with the first's at the shared edge.
    st = UsdGeom.PrimvarsAPI(right).GetPrimvar("st")
    st.Set([(0, 0), (1, 0), (1, 1), (0, 0), (-1, 1), (0, 1)])
    st.SetIndices([0, 1, 2, 3, 4, 5])
    snap = read_snapshot(stage, 1.0, class_map)
    mesh = next(m for m in snap.meshes if m.prim_path == "/World/Right")
    assert len(mesh.points) == 5  # point 2 is split (its two corners disagree); 0 and 1, 3 are not
    corners = mesh.points[mesh.triangles]
    assert np.allclose(corners, [[(0.1, -1, 0), (2.1, -1, 0), (2.1, 1, 0)], [(0.1, -1, 0), (2.1, 1, 0), (0.1, 1, 0)]])
    assert np.allclose(mesh.uvs[mesh.triangles], [[(0, 0), (1, 0), (1, 1)], [(0, 0), (-1, 1), (0, 1)]])


def test_labels_are_byte_identical_with_and_without_textures(quads, class_map):
    stage = open_stage(quads)
    right = UsdGeom.PrimvarsAPI(stage.GetPrimAtPath("/World/Right")).GetPrimvar("st")
    right.Set([(0, 0), (1, 0), (1, 1), (0, 0), (-1, 1), (0, 1)])  # a seam: Right's points are split
    right.SetIndices([0, 1, 2, 3, 4, 5])
    cam = read_camera(stage, "/World/Cam", 1.0)
    textured = read_snapshot(stage, 1.0, class_map)
    surface = UsdShade.Shader(stage.GetPrimAtPath("/World/Looks/Quadrants/Surface"))
    surface.GetInput("diffuseColor").DisconnectSource()
    flat = read_snapshot(stage, 1.0, class_map)
    assert all(m.uvs is None for m in flat.meshes) and all(m.uvs is not None for m in textured.meshes)
    config = RenderConfig(width=W, height=H, spp=1)
    a = RenderSession(config).render(textured, cam, rgb=False)
    b = RenderSession(config).render(flat, cam, rgb=False)
    assert a.class_ids.tobytes() == b.class_ids.tobytes()
    assert a.instance_ids.tobytes() == b.instance_ids.tobytes()
    assert a.hits.distance_m.tobytes() == b.hits.distance_m.tobytes()


def test_a_missing_texture_file_renders_the_constant_after_a_warning(tmp_path, class_map, caplog):
    shutil.copy(DATA / "valid" / "textured_quads.usda", tmp_path / "quads.usda")  # no texture written
    stage = open_stage(tmp_path / "quads.usda")
    with caplog.at_level(logging.WARNING):
        snap = read_snapshot(stage, 1.0, class_map)
    assert "texture file './textures/quadrants.png' of /World/Looks/Quadrants/Image was not found" in caplog.text
    material = snap.materials["/World/Looks/Quadrants"]
    assert material.base_color_texture is None and material.base_color == pytest.approx((0.5, 0.5, 0.5))
    mi = variants.activate("scalar_rgb")
    got, hit = mitsuba_albedo(mi, snap, read_camera(stage, "/World/Cam", 1.0), W, H)
    assert np.allclose(got[hit], 0.5)


def test_an_oversized_texture_is_refused_before_it_is_decoded(quads, class_map, monkeypatch):
    from synthua_usd.backends.mitsuba import surfaces
    from synthua_usd.core.errors import InputError

    monkeypatch.setattr(surfaces, "MAX_TEXELS", 40)
    snap = read_snapshot(open_stage(quads), 1.0, class_map)
    with pytest.raises(InputError, match=r"quadrants.png: texture image of 8x6 pixels, 3 channels; expected at most 40"):
        mitsuba_albedo(variants.activate("scalar_rgb"), snap, read_camera(open_stage(quads), "/World/Cam", 1.0), W, H)


def test_a_texture_that_is_no_image_renders_the_constant_after_a_warning(quads, class_map, run_cli):
    (quads.parent / "textures" / "quadrants.png").write_text("not an image")
    code, _, err = run_cli("render", quads, "--camera", "/World/Cam", "--width", 16, "--height", 12, "--spp", 1,
                           "--variant", "scalar_rgb", "--out", quads.parent / "out")
    assert code == 0
    assert "quadrants.png" in err and "cannot be read" in err and (quads.parent / "out").is_dir()


def test_wet_weathering_darkens_every_texel(quads, class_map):
    from synthua_usd.backends.mitsuba import surfaces, weather_scene

    mi = variants.activate("scalar_rgb")
    material = read_snapshot(open_stage(quads), 1.0, class_map).materials["/World/Looks/Quadrants"]
    images = surfaces.TextureImages(mi)
    node, values = weather_scene.surface_bsdf_dict(material, frozenset({"face_wet"}), images)
    assert node["type"] == "blendbsdf" and values == {}  # scalar variants: constants in the dict
    dry = np.asarray(mi.traverse(node["bsdf_0"]["base_color"])["data"])
    wet = np.asarray(mi.traverse(node["bsdf_1"]["base_color"])["data"])
    assert np.allclose(dry, srgb_decoded(TEXELS), atol=1e-6)
    assert np.allclose(wet, weather_scene.wet_albedo(dry), atol=1e-6)
    mi.load_dict(node)  # a valid Mitsuba BSDF


def test_a_session_moves_a_textured_mesh_and_keeps_its_uvs(quads, class_map):
    stage = open_stage(quads)
    stage.SetEndTimeCode(2)
    op = UsdGeom.Xformable(stage.GetPrimAtPath("/World/Right")).AddTranslateOp()
    op.Set(Gf.Vec3d(0, 0, 0), 1.0)
    op.Set(Gf.Vec3d(-0.5, 0.3, 0), 2.0)  # the textured face-varying quad slides under the camera
    cam = read_camera(stage, "/World/Cam", 1.0)
    config = RenderConfig(width=W, height=H, spp=4, pixel_filter="box", variant="scalar_rgb")
    reader = StageReader(stage, class_map)
    session = RenderSession(config)
    before = session.render(reader.snapshot(1.0), cam)
    moved = session.render(reader.snapshot(2.0), cam)
    assert "update" in moved.seconds and session.loads == 1
    assert not np.array_equal(before.instance_ids, moved.instance_ids)
    fresh = RenderSession(config).render(read_snapshot(stage, 2.0, class_map), cam)
    assert np.array_equal(moved.instance_ids, fresh.instance_ids)
    assert np.allclose(moved.rgb, fresh.rgb, atol=1e-6)


def _mean_rgb(stage, class_map, prim: str):
    snap = read_snapshot(stage, 1.0, class_map)
    cam = read_camera(stage, "/World/Cam", 1.0)
    frame = RenderSession(RenderConfig(width=W, height=H, spp=16, variant="scalar_rgb")).render(snap, cam)
    index = next(i for i, m in enumerate(snap.meshes) if m.prim_path == prim)
    return frame.rgb[frame.hits.mesh_index == index].mean(axis=0)


@pytest.mark.parametrize("axis, tilt, brighter", [("x", 0.6, True), ("x", -0.6, False), ("y", 0.6, True),
                                                   ("y", -0.6, False)])
def test_a_normal_map_tilts_the_shading(tmp_path, class_map, axis, tilt, brighter):
    # The quad's s runs along +X and t along +Y: a tangent-space normal's red tilts it towards +s, its green
    # towards +t (UsdPreviewSurface's and glTF's convention), whatever way Mitsuba's v runs.
    shutil.copy(DATA / "valid" / "textured_quads.usda", tmp_path / "quads.usda")
    write_png(tmp_path / "textures" / "quadrants.png", np.full((2, 2, 3), 200, np.uint8))
    n = np.array([tilt, 0.0, 1.0] if axis == "x" else [0.0, tilt, 1.0])
    n /= np.linalg.norm(n)
    write_png(tmp_path / "textures" / "normal.png", np.tile(np.round((n * 0.5 + 0.5) * 255), (2, 2, 1)))
    stage = open_stage(tmp_path / "quads.usda")
    lit_from(stage, axis)
    flat = _mean_rgb(stage, class_map, "/World/Left")
    add_texture(stage, "Normals", "./textures/normal.png", "rgb", "normal", Sdf.ValueTypeNames.Normal3f,
                 sourceColorSpace=(Sdf.ValueTypeNames.Token, "raw"),
                 scale=(Sdf.ValueTypeNames.Float4, Gf.Vec4f(2, 2, 2, 1)),
                 bias=(Sdf.ValueTypeNames.Float4, Gf.Vec4f(-1, -1, -1, 0)))
    tilted = _mean_rgb(stage, class_map, "/World/Left")
    # Lambert: cos(60°) = 0.5 flat; a normal tilted ±31° towards the sun faces it at 29° or 91°.
    assert (tilted.mean() > 1.3 * flat.mean()) if brighter else (tilted.mean() < 0.5 * flat.mean())


def test_an_opacity_texture_cuts_the_surface_away(tmp_path, class_map):
    shutil.copy(DATA / "valid" / "textured_quads.usda", tmp_path / "quads.usda")
    rgba = np.zeros((2, 8, 4), np.uint8)
    rgba[:, 4:, 3] = 255  # the image's right half opaque, its left half a hole
    write_png(tmp_path / "textures" / "quadrants.png", rgba)
    stage = open_stage(tmp_path / "quads.usda")
    clamp = (Sdf.ValueTypeNames.Token, "clamp")  # repeat would blend the opaque right edge into the left one
    add_texture(stage, "Alpha", "./textures/quadrants.png", "a", "opacity", Sdf.ValueTypeNames.Float, wrapS=clamp,
                 wrapT=clamp)
    stage.GetPrimAtPath("/World/Looks/Quadrants/Surface").CreateAttribute(
        "inputs:opacityThreshold", Sdf.ValueTypeNames.Float).Set(0.5)
    snap = read_snapshot(stage, 1.0, class_map)
    cam = read_camera(stage, "/World/Cam", 1.0)
    frame = RenderSession(RenderConfig(width=W, height=H, spp=4, variant="scalar_rgb")).render(snap, cam)
    left = frame.hits.mesh_index == 0
    xs = np.nonzero(left.any(axis=0))[0]
    hole = frame.rgb[:, xs[2]:xs[len(xs) // 2 - 2]][left[:, xs[2]:xs[len(xs) // 2 - 2]]]
    solid = frame.rgb[:, xs[len(xs) // 2 + 2]:xs[-2]][left[:, xs[len(xs) // 2 + 2]:xs[-2]]]
    assert hole.mean() == pytest.approx(1.0, abs=0.02)  # the sky seen through the hole
    assert solid.mean() < 0.05  # black, opaque
    assert left.sum() > 0.2 * W * H  # labels still see the whole quad: they come from geometry


def teapot_stage() -> Usd.Stage:
    """The usd-wg teapot with its textured 'Fancy' model, a sky and a camera, added in the session layer."""
    stage = Usd.Stage.Open(str(third_party("usd-wg-teapot", "Teapot.usd")))
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        stage.GetPrimAtPath("/Teapot").GetVariantSet("modelVariant").SetVariantSelection("Fancy")
        UsdLux.DomeLight.Define(stage, "/Sky").CreateIntensityAttr(1.0)
        cam = UsdGeom.Camera.Define(stage, "/Cam")
        cam.CreateFocalLengthAttr(0.5)
        cam.CreateHorizontalApertureAttr(0.36)
        cam.CreateVerticalApertureAttr(0.27)
        cam.CreateClippingRangeAttr(Gf.Vec2f(0.01, 100))
        UsdGeom.Xformable(cam).AddTranslateOp().Set(Gf.Vec3d(0.0, 0.12, 0.75))
    return stage


@pytest.fixture(scope="module")
def teapot():
    return teapot_stage()


def test_the_teapot_renders_its_texture_colours(teapot, class_map, variant):
    mi = variants.activate(variant)
    snap = read_snapshot(teapot, 1.0, class_map)
    cam = read_camera(teapot, "/Cam", 1.0)
    material = next(m for m in snap.materials.values() if m.base_color_texture is not None)
    assert material.base_color_texture.path.endswith("tea_set_01_diff_2k.jpg")
    assert (material.roughness_texture.channel, material.metallic_texture.channel) == ("g", "b")
    assert material.roughness_texture.color_space == "raw"
    image = oiio.ImageBuf(material.base_color_texture.path).get_pixels(oiio.UINT8)
    expected, hit_ref = reference_albedo(snap, cam, srgb_decoded(np.asarray(image, np.float64)), W, H)
    got, hit = mitsuba_albedo(mi, snap, cam, W, H)
    both = hit & hit_ref
    assert both.sum() > 0.2 * W * H
    assert np.std(got[both], axis=0).max() > 0.05  # patterned, not one flat colour
    # The texture's 2k texels are far smaller than a pixel: silhouettes and the mip-free lookups still agree.
    close = np.abs(got[both] - expected[both]).max(axis=1) < 2e-3
    assert close.mean() > 0.99


def test_teapot_labels_are_the_same_with_its_textures_split_seams(class_map):
    stage = teapot_stage()
    cam = read_camera(stage, "/Cam", 1.0)
    snap = read_snapshot(stage, 1.0, class_map)
    assert all(m.uvs is not None for m in snap.meshes)
    config = RenderConfig(width=W, height=H, spp=1)
    textured = RenderSession(config).render(snap, cam, rgb=False)
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        for prim in stage.Traverse():
            if prim.IsA(UsdGeom.Mesh):
                UsdShade.MaterialBindingAPI.Apply(prim).UnbindAllBindings()
    flat_snap = read_snapshot(stage, 1.0, class_map)
    flat = RenderSession(config).render(flat_snap, cam, rgb=False)
    # The texture seams split points: same triangles, more points.
    assert sum(len(m.points) for m in flat_snap.meshes) < sum(len(m.points) for m in snap.meshes)
    assert sum(len(m.triangles) for m in flat_snap.meshes) == sum(len(m.triangles) for m in snap.meshes)
    assert textured.instance_ids.tobytes() == flat.instance_ids.tobytes()
    assert textured.hits.mesh_index.tobytes() == flat.hits.mesh_index.tobytes()
    assert textured.hits.distance_m.tobytes() == flat.hits.distance_m.tobytes()


def _packaged(quads):
    """``quads`` packed into quads.usdz (OpenUSD's own packager), its loose texture removed."""
    from pxr import UsdUtils

    package = quads.parent / "quads.usdz"
    assert UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(quads)), str(package))
    shutil.rmtree(quads.parent / "textures")
    return package


def test_a_texture_inside_a_usdz_package_renders(quads, class_map, variant, caplog):
    """Ar resolves the packed texture to quads.usdz[...]: read from the package, not reported missing."""
    package = _packaged(quads)
    stage = open_stage(package)
    with caplog.at_level(logging.WARNING):
        snap = read_snapshot(stage, 1.0, class_map)
    assert "texture" not in caplog.text
    texture = snap.materials["/World/Looks/Quadrants"].base_color_texture
    assert texture is not None and texture.path.startswith(f"{package}[") and texture.path.endswith("quadrants.png]")
    cam = read_camera(stage, "/World/Cam", 1.0)
    expected, hit_ref = reference_albedo(snap, cam, srgb_decoded(TEXELS), W, H)
    got, hit = mitsuba_albedo(variants.activate(variant), snap, cam, W, H)
    assert np.array_equal(hit, hit_ref) and np.abs(got[hit] - expected[hit]).max() < 2e-3


def test_a_texture_that_cannot_be_read_is_named_with_the_reason(quads, class_map, caplog):
    (quads.parent / "textures" / "quadrants.png").write_text("not an image")
    with caplog.at_level(logging.WARNING):
        snap = read_snapshot(open_stage(quads), 1.0, class_map)
    assert snap.materials["/World/Looks/Quadrants"].base_color_texture is None
    (line,) = [r.getMessage() for r in caplog.records if "cannot be read" in r.getMessage()]
    assert "texture file './textures/quadrants.png' of /World/Looks/Quadrants/Image" in line
    assert str(quads.parent / "textures" / "quadrants.png") in line and "using the input's constant" in line
    assert "format" in line.lower() or "not" in line.lower()  # OpenImageIO's own reason follows the file
