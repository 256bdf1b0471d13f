"""Reading UsdPreviewSurface networks: textures followed through connections, and what falls back to the
constant (with a warning naming the prim)."""

from __future__ import annotations

import logging
import shutil

import numpy as np
import pytest
from pxr import Gf, Sdf, UsdGeom, UsdShade

from conftest import DATA
from texture_checks import TEXELS, write_png
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.stage_checks import validate_stage
from synthua_usd.usd.stage_io import open_stage

LOOKS = "/World/Looks/Quadrants"


@pytest.fixture
def quads(tmp_path):
    shutil.copy(DATA / "valid" / "textured_quads.usda", tmp_path / "quads.usda")
    (tmp_path / "textures").mkdir()
    write_png(tmp_path / "textures" / "quadrants.png", TEXELS)  # the reader opens its header
    return open_stage(tmp_path / "quads.usda")


def material(stage, class_map):
    return read_snapshot(stage, 1.0, class_map).materials[LOOKS]


def test_a_texture_is_read_with_its_settings(quads, class_map):
    image = UsdShade.Shader(quads.GetPrimAtPath(f"{LOOKS}/Image"))
    image.CreateInput("scale", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(0.5, 0.6, 0.7, 1.0))
    image.CreateInput("bias", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(0.1, 0.0, 0.0, 0.0))
    image.GetInput("wrapT").Set("mirror")
    tex = material(quads, class_map).base_color_texture
    assert tex.path == str((quads.GetRootLayer().realPath.rsplit("/", 1)[0] + "/textures/quadrants.png"))
    assert (tex.channel, tex.color_space, tex.wrap_s, tex.wrap_t) == ("rgb", "sRGB", "repeat", "mirror")
    assert tex.scale == pytest.approx((0.5, 0.6, 0.7, 1.0)) and tex.bias == pytest.approx((0.1, 0, 0, 0))


def test_the_primvar_name_comes_through_the_material_interface(quads, class_map):
    quads.GetPrimAtPath(LOOKS).GetAttribute("inputs:frame:stPrimvarName").Set("uvmap")
    for mesh in ("/World/Left", "/World/Right"):
        api = UsdGeom.PrimvarsAPI(quads.GetPrimAtPath(mesh))
        st = api.GetPrimvar("st")
        uv = api.CreatePrimvar("uvmap", Sdf.ValueTypeNames.TexCoord2fArray, st.GetInterpolation())
        uv.Set(st.Get())
        if st.IsIndexed():
            uv.SetIndices(st.GetIndices())
        st.GetAttr().Clear()
    snap = read_snapshot(quads, 1.0, class_map)
    assert snap.materials[LOOKS].uv_primvar == "uvmap"
    assert all(m.uvs is not None for m in snap.meshes)


def test_a_transform2d_between_falls_back_to_the_constant(quads, class_map, caplog):
    xf = UsdShade.Shader.Define(quads, f"{LOOKS}/Transform")
    xf.CreateIdAttr("UsdTransform2d")
    xf.CreateInput("in", Sdf.ValueTypeNames.Float2).ConnectToSource(
        UsdShade.Shader(quads.GetPrimAtPath(f"{LOOKS}/StReader")).ConnectableAPI(), "result")
    out = xf.CreateOutput("result", Sdf.ValueTypeNames.Float2)
    UsdShade.Shader(quads.GetPrimAtPath(f"{LOOKS}/Image")).GetInput("st").ConnectToSource(out)
    with caplog.at_level(logging.WARNING):
        m = material(quads, class_map)
    assert m.base_color_texture is None and m.base_color == pytest.approx((0.5, 0.5, 0.5))
    assert f"texture {LOOKS}/Image: st comes from 'UsdTransform2d' at {LOOKS}/Transform" in caplog.text
    assert all(mesh.uvs is None for mesh in read_snapshot(quads, 1.0, class_map).meshes)


def test_an_unknown_shader_falls_back_to_the_constant(quads, class_map, caplog):
    other = UsdShade.Shader.Define(quads, f"{LOOKS}/Checker")
    other.CreateIdAttr("ND_checkerboard_color3")
    out = other.CreateOutput("out", Sdf.ValueTypeNames.Color3f)
    UsdShade.Shader(quads.GetPrimAtPath(f"{LOOKS}/Surface")).GetInput("diffuseColor").ConnectToSource(out)
    with caplog.at_level(logging.WARNING):
        m = material(quads, class_map)
    assert m.base_color_texture is None
    assert f"is connected to 'ND_checkerboard_color3' at {LOOKS}/Checker, which synthua does not translate" in caplog.text


def test_an_interface_input_gives_its_value(quads, class_map):
    colour = quads.GetPrimAtPath(LOOKS)
    inp = UsdShade.Material(colour).CreateInput("tint", Sdf.ValueTypeNames.Color3f)
    inp.Set(Gf.Vec3f(0.1, 0.2, 0.3))
    UsdShade.Shader(quads.GetPrimAtPath(f"{LOOKS}/Surface")).GetInput("diffuseColor").ConnectToSource(inp)
    m = material(quads, class_map)
    assert m.base_color_texture is None and m.base_color == pytest.approx((0.1, 0.2, 0.3))


def test_mismatched_st_lengths_render_the_constants(quads, class_map, caplog):
    UsdGeom.PrimvarsAPI(quads.GetPrimAtPath("/World/Left")).GetPrimvar("st").Set([(0, 0), (1, 0)])
    with caplog.at_level(logging.WARNING):
        snap = read_snapshot(quads, 1.0, class_map)
    left = next(m for m in snap.meshes if m.prim_path == "/World/Left")
    assert left.uvs is None and len(left.triangles) == 2
    assert "/World/Left: primvars:st has 2 vertex values for 4 points" in caplog.text


def test_validation_reports_a_missing_texture_file(tmp_path, class_map):
    shutil.copy(DATA / "valid" / "textured_quads.usda", tmp_path / "quads.usda")
    findings = validate_stage(open_stage(tmp_path / "quads.usda"), class_map)
    assert [f.rule for f in findings] == ["usdUtilsValidators:MissingReferenceValidator"]
    assert "textures/quadrants.png" in findings[0].message


def test_written_materials_read_back_with_their_textures(tmp_path, class_map):
    from synthua_usd.composition.scenario import StageMetadata
    from synthua_usd.model.scene import Material, Texture
    from synthua_usd.usd.authoring import define_mesh, define_preview_material, new_layer

    stage = new_layer(StageMetadata(), "a textured material")
    spec = Material("M", (0.2, 0.3, 0.4), 0.6, base_color_texture=Texture("textures/a.png", scale=(0.5, 0.5, 0.5, 1)),
                    roughness_texture=Texture("textures/a.png", channel="g", color_space="raw"),
                    normal_texture=Texture("textures/n.png", color_space="raw", scale=(2, 2, 2, 1), bias=(-1, -1, -1, 0)),
                    opacity_texture=Texture("textures/a.png", channel="a"), opacity_threshold=0.5)
    looks = define_preview_material(stage, "/World/Looks/M", spec)
    define_mesh(stage, "/World/Quad", np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]], float), np.array([[0, 1, 2]]), looks,
                np.array([[0, 0], [1, 0], [1, 1]], np.float32))
    (tmp_path / "textures").mkdir()
    for name in ("a.png", "n.png"):
        write_png(tmp_path / "textures" / name, TEXELS)
    stage.GetRootLayer().Export(str(tmp_path / "m.usda"))
    read = read_snapshot(open_stage(tmp_path / "m.usda"), 1.0, class_map)
    got = read.materials["/World/Looks/M"]
    for field in ("base_color_texture", "roughness_texture", "normal_texture", "opacity_texture"):
        want, have = getattr(spec, field), getattr(got, field)
        assert have.path == str(tmp_path / want.path)
        assert (have.channel, have.color_space, have.scale, have.bias) == (want.channel, want.color_space, want.scale,
                                                                           want.bias), field
    assert got.opacity_threshold == 0.5 and got.base_color == pytest.approx((0.2, 0.3, 0.4))
    assert read.meshes[0].uvs.tolist() == [[0, 0], [1, 0], [1, 1]]


def test_a_texture_outside_the_scenario_folder_is_refused_unless_allowed(tmp_path, class_map):
    from synthua_usd.core.errors import StageError

    (tmp_path / "elsewhere").mkdir()
    write_png(tmp_path / "elsewhere" / "quadrants.png", TEXELS)
    (tmp_path / "scenario").mkdir()
    text = (DATA / "valid" / "textured_quads.usda").read_text().replace("@./textures/quadrants.png@",
                                                                         "@../elsewhere/quadrants.png@")
    (tmp_path / "scenario" / "quads.usda").write_text(text)
    with pytest.raises(StageError, match=r"/World/Looks/Quadrants/Image reads the texture .*elsewhere/quadrants.png, "
                                         r"outside the scenario's folder .*--allow-external-assets"):
        open_stage(tmp_path / "scenario" / "quads.usda")
    stage = open_stage(tmp_path / "scenario" / "quads.usda", allow_external_assets=True)
    assert material(stage, class_map).base_color_texture.path == str(tmp_path / "elsewhere" / "quadrants.png")


def test_a_display_color_primvar_reader_gives_each_gprim_its_colour(class_map, caplog):
    from pxr import Usd

    from conftest import third_party

    stage = Usd.Stage.Open(str(third_party("usd-wg-teapot", "Teapot.usd")))  # default: Utah, CeramicLimeGreen
    with caplog.at_level(logging.WARNING):
        snap = read_snapshot(stage, 1.0, class_map)
    assert "does not translate" not in caplog.text
    (mesh,) = snap.meshes
    m = snap.materials[mesh.material_key]
    assert m.key == "/Teapot/Materials/Ceramic[displayColor=(0.3250,0.8250,0.0000)]"
    assert m.base_color == pytest.approx((0.325, 0.825, 0.0)) and m.roughness == pytest.approx(0.125)
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        stage.GetPrimAtPath("/Teapot").GetVariantSet("shadingVariant").SetVariantSelection("CeramicBlue")
    blue = read_snapshot(stage, 1.0, class_map)
    assert blue.materials[blue.meshes[0].material_key].base_color == pytest.approx((0.013679987, 0.19873393, 0.912))


@pytest.mark.parametrize("value", [Gf.Vec4f(float("nan"), 1, 1, 1), Gf.Vec3f(1, 1, 1)])
def test_a_bad_scale_falls_back_to_the_constant(quads, class_map, caplog, value):
    image = UsdShade.Shader(quads.GetPrimAtPath(f"{LOOKS}/Image"))
    kind = Sdf.ValueTypeNames.Float4 if isinstance(value, Gf.Vec4f) else Sdf.ValueTypeNames.Float3
    image.CreateInput("scale", kind).Set(value)
    with caplog.at_level(logging.WARNING):
        m = material(quads, class_map)
    assert m.base_color_texture is None
    assert f"texture {LOOKS}/Image: scale is (" in caplog.text and "expected 4 finite numbers" in caplog.text
