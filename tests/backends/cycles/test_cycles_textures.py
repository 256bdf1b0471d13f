"""Textures cross to Cycles: the interchange carries texture coordinates and texture parameters, and Cycles
renders a textured quad's texels where the independent lookup of tests/texture_checks.py puts them, with the
tangent-space convention Mitsuba uses (skipped, with the reason, where no interpreter with bpy is installed)."""

from __future__ import annotations

import numpy as np
import pytest
from pxr import Gf, Sdf, UsdGeom, UsdShade
from texture_checks import TEXELS, add_texture, lit_from, reference_albedo, srgb_decoded, textured_quads, write_png

from synthua_usd.backends.cycles.interchange import read_interchange, write_interchange
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.stage_io import open_stage


@pytest.fixture
def quads(tmp_path):
    """tests/data/valid/textured_quads.usda in tmp_path with TEXELS as its texture."""
    return textured_quads(tmp_path)


def test_textured_and_untextured_meshes_of_one_material_cross_as_two_soups(quads, class_map, tmp_path):
    stage = open_stage(quads)
    # a third quad of the same material without texture coordinates: it renders the constants, in Mitsuba too
    bare = UsdGeom.Mesh.Define(stage, "/World/Bare")
    bare.CreatePointsAttr([(-1, 1.2, 0), (1, 1.2, 0), (1, 2, 0), (-1, 2, 0)])
    bare.CreateFaceVertexCountsAttr([4])
    bare.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    UsdShade.MaterialBindingAPI.Apply(bare.GetPrim()).Bind(
        UsdShade.Material(stage.GetPrimAtPath("/World/Looks/Quadrants")))
    add_texture(stage, "Bumps", "./textures/quadrants.png", "rgb", "normal", Sdf.ValueTypeNames.Normal3f,
                sourceColorSpace=(Sdf.ValueTypeNames.Token, "raw"), wrapS=(Sdf.ValueTypeNames.Token, "mirror"),
                scale=(Sdf.ValueTypeNames.Float4, Gf.Vec4f(2, 2, 2, 1)),
                bias=(Sdf.ValueTypeNames.Float4, Gf.Vec4f(-1, -1, -1, 0)))
    snap = read_snapshot(stage, 1.0, class_map)
    cam = read_camera(stage, "/World/Cam", 1.0)
    write_interchange(snap, cam, 32, 24, tmp_path / "scene")
    doc, soups = read_interchange(tmp_path / "scene")
    assert [(m["key"], m["textured"]) for m in doc["materials"]] == [(doc["materials"][0]["key"], False),
                                                                   (doc["materials"][0]["key"], True)]
    (plain, (bare_points, _, no_uvs)), (textured, (points, triangles, uvs)) = zip(doc["materials"], soups)
    assert no_uvs is None and plain["textures"] == {} and len(bare_points) == 4 and plain["meshes"] == 1
    meshes = [m for m in snap.meshes if m.uvs is not None]
    assert [m.prim_path for m in meshes] == ["/World/Left", "/World/Right"] and textured["meshes"] == 2
    expected_points, expected_triangles, _ = snap.world_triangles(meshes)
    assert np.allclose(points, expected_points, atol=1e-6) and np.array_equal(triangles, expected_triangles)
    # every triangle corner keeps the st its mesh gave it
    assert np.allclose(uvs[triangles], np.concatenate([m.uvs[m.triangles] for m in meshes]))
    source = snap.materials[textured["key"]]
    assert set(textured["textures"]) == {"base_color", "normal"}
    normal, colour = textured["textures"]["normal"], textured["textures"]["base_color"]
    assert normal["path"] == colour["path"] == str(quads.parent / "textures" / "quadrants.png")
    assert (normal["color_space"], normal["wrap_s"], normal["scale"], normal["bias"]) == \
        ("raw", "mirror", [2, 2, 2, 1], [-1, -1, -1, 0])
    assert (colour["channel"], colour["color_space"], colour["wrap_s"], colour["scale"], colour["bias"]) == \
        ("rgb", source.base_color_texture.color_space, "repeat", [1, 1, 1, 1], [0, 0, 0, 0])
    assert textured["not_exported"] == plain["not_exported"] == []


def _cycles(snap, cam, folder, width, height, samples):
    from synthua_usd.backends.cycles.runner import CyclesJob, CyclesUnavailable, find_cycles_python, render_jobs

    try:
        python = find_cycles_python()
    except CyclesUnavailable as exc:
        pytest.skip(f"{exc} (the Cycles comparison needs it; the rest of synthua does not)")
    write_interchange(snap, cam, width, height, folder / "scene")
    result = render_jobs(python, folder / "scene", [CyclesJob("a", samples)], folder / "out", threads=2,
                         max_bounces=2, timeout_s=300)
    return result.images["a"]


#: A UsdUVTexture tint as the district's materials author them; red's scale clips the brighter texels at 1.
TINT = ((1.6, 1.0, 0.5, 1.0), (0.0, 0.1, 0.0, 0.0))


@pytest.mark.slow
@pytest.mark.parametrize("space, tinted", [("sRGB", False), ("raw", False), ("sRGB", True)])
def test_cycles_renders_the_texels_where_the_independent_lookup_puts_them(quads, class_map, tmp_path, space,
                                                                          tinted):
    W, H = 256, 192  # about 13 pixels a texel: Cycles' pixel filter blurs texel edges little
    stage = open_stage(quads)
    image_prim = stage.GetPrimAtPath("/World/Looks/Quadrants/Image")
    image_prim.GetAttribute("inputs:sourceColorSpace").Set(space)
    if tinted:
        for name, value in zip(("scale", "bias"), TINT):
            image_prim.CreateAttribute(f"inputs:{name}", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(*value))
    snap = read_snapshot(stage, 1.0, class_map)
    cam = read_camera(stage, "/World/Cam", 1.0)
    image = _cycles(snap, cam, tmp_path, W, H, 32).reshape(-1, 3)

    def lookup(texels, decode, tint):
        # Cycles filters an 8-bit sRGB image before decoding it (Mitsuba decodes first): bilinear then decode;
        # then UsdUVTexture's scale and bias, clipped to [0, 1] as Mitsuba's translation clips
        values, hit = reference_albedo(snap, cam, texels / 255.0, W, H)
        values = srgb_decoded(np.clip(values, 0.0, 1.0) * 255.0) if decode else values
        if tint:
            values = np.clip(values * np.array(TINT[0][:3]) + np.array(TINT[1][:3]), 0.0, 1.0)
        return values, hit

    def fit(texels, decode, tint=tinted):
        # under a uniform white sky a diffuse quad returns its albedo; the BSDF's specular layer adds a little
        expected, hit = lookup(texels, decode, tint)
        a, b = np.polyfit(expected[hit].ravel(), image[hit].ravel(), 1)
        return a, np.median(np.abs(image[hit] - (a * expected[hit] + b)))

    a, error = fit(TEXELS, space == "sRGB")
    assert 0.85 < a < 1.1 and error < 0.012
    # the same texels upside down, mirrored, decoded by the other colour space, or without their tint fit far worse
    wrong = [(TEXELS[::-1], space == "sRGB"), (TEXELS[:, ::-1], space == "sRGB"), (TEXELS, space != "sRGB")]
    for texels, decode in wrong:
        assert fit(texels, decode)[1] > 3 * error
    if tinted:
        assert fit(TEXELS, space == "sRGB", tint=False)[1] > 3 * error
        # where the tinted red would exceed 1.2 it is clipped to 1 (its fit to the white sky: about a + b)
        raw, hit = lookup(TEXELS, space == "sRGB", False)
        over = hit & (raw[:, 0] * TINT[0][0] + TINT[1][0] > 1.2)
        assert over.sum() > 100 and np.median(image[over, 0]) < 1.05 * a


@pytest.mark.slow
@pytest.mark.parametrize("axis", ["x", "y"])
def test_a_normal_map_tilts_the_cycles_shading_as_mitsubas(tmp_path, class_map, axis):
    # As tests/backends/mitsuba/test_textures.py::test_a_normal_map_tilts_the_shading: s runs along +X and t
    # along +Y; a tangent-space normal's red tilts it towards +s, its green towards +t.
    W, H = 64, 48
    means = {}
    for tilt in (0.0, 0.6, -0.6):
        folder = tmp_path / f"tilt{tilt}"  # a stage of its own: one layer opened twice is the same stage
        folder.mkdir()
        textured_quads(folder, np.full((2, 2, 3), 200, np.uint8))
        n = np.array([tilt, 0.0, 1.0] if axis == "x" else [0.0, tilt, 1.0])
        n /= np.linalg.norm(n)
        write_png(folder / "textures" / "normal.png", np.tile(np.round((n * 0.5 + 0.5) * 255), (2, 2, 1)))
        stage = open_stage(folder / "quads.usda")
        lit_from(stage, axis)
        add_texture(stage, "Normals", "./textures/normal.png", "rgb", "normal", Sdf.ValueTypeNames.Normal3f,
                    sourceColorSpace=(Sdf.ValueTypeNames.Token, "raw"),
                    scale=(Sdf.ValueTypeNames.Float4, Gf.Vec4f(2, 2, 2, 1)),
                    bias=(Sdf.ValueTypeNames.Float4, Gf.Vec4f(-1, -1, -1, 0)))
        snap = read_snapshot(stage, 1.0, class_map)
        cam = read_camera(stage, "/World/Cam", 1.0)
        image = _cycles(snap, cam, folder, W, H, 16)
        means[tilt] = image[14:34, 8:28].mean()  # inside the Left quad (x -2.1..-0.1 m, y -1..1 m)
    # Lambert: cos(60°) = 0.5 flat; a normal tilted ±31° towards the sun faces it at 29° or 91°.
    assert means[0.6] > 1.3 * means[0.0] and means[-0.6] < 0.5 * means[0.0]
