"""The district's procedural textures: deterministic, small, tinted to their palette colours, and mapped
without moving a triangle (so the label maps are the untextured district's)."""

import numpy as np
import OpenImageIO as oiio
import pytest

from conftest import DISTRICT
from synthua_usd.demo.district import build_district
from synthua_usd.demo.district_textures import TEXTURED
from synthua_usd.demo.textures import SIZE, decode_srgb8, district_images
from synthua_usd.materials import PALETTE


@pytest.fixture(scope="module")
def pair():
    return build_district(0), build_district(0, textures=False)


def test_images_are_seeded_tileable_variation():
    a, b, other = district_images(0, 64), district_images(0, 64), district_images(1, 64)
    assert sorted(a) == ["asphalt", "plaster", "stone", "wood"]
    for name in a:
        assert a[name].shape == (64, 64, 3) and a[name].dtype == np.uint8
        assert np.array_equal(a[name], b[name]) and not np.array_equal(a[name], other[name])
        linear = decode_srgb8(a[name])
        assert 0.02 < linear.std() and linear.max() < 1.0  # variation, never clipped white
        # Tileable: the step across the wrap-around edge is no larger than steps inside the image.
        inside = np.abs(np.diff(linear, axis=1)).mean()
        assert np.abs(linear[:, 0] - linear[:, -1]).mean() < 2.0 * inside


def test_textured_materials_keep_their_palette_colour_as_mean(pair):
    textured, _ = pair
    images = {f"textures/{name}.png": pixels for name, pixels in district_images(0).items()}
    assert set(textured.images) == {f"textures/{image}.png" for image, _, _ in TEXTURED.values()}
    for key, (image, _, _) in TEXTURED.items():
        if key not in textured.materials:
            continue
        m = textured.materials[key]
        assert m.base_color == PALETTE[key].base_color  # the fallback stays the flat colour
        mean = decode_srgb8(images[m.base_color_texture.path]).mean(axis=(0, 1)) * np.array(m.base_color_texture.scale[:3])
        assert mean == pytest.approx(PALETTE[key].base_color, rel=1e-9)
        assert m.base_color_texture.color_space == "sRGB"


def test_texturing_moves_no_triangle(pair):
    textured, flat = pair
    for a, b in zip(textured.objects, flat.objects, strict=True):
        for pa, pb in zip(a.parts, b.parts, strict=True):
            assert np.array_equal(pa.points[pa.triangles], pb.points[pb.triangles]), f"{a.path}/{pa.name}"
            assert (pa.uvs is not None) == (pa.material in TEXTURED)


def test_committed_images_are_small():
    files = sorted((DISTRICT / "textures").glob("*.png"))
    assert [f.stem for f in files] == ["asphalt", "plaster", "stone", "wood"]
    assert sum(f.stat().st_size for f in files) < 1_500_000
    for f in files:
        spec = oiio.ImageInput.open(str(f)).spec()
        assert (spec.width, spec.height, spec.nchannels) == (SIZE, SIZE, 3)
