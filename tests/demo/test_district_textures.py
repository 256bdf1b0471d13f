"""The district's procedural textures: deterministic, small, tinted to their palette colours, and mapped
without moving a triangle (so the label maps are the untextured district's)."""

import numpy as np
import OpenImageIO as oiio
import pytest

from conftest import DISTRICT
from synthua_usd.demo.district import build_district
from synthua_usd.demo.district_textures import PAVED, TEXTURED, paving_images
from synthua_usd.demo.textures import SIZE, district_images, paving
from synthua_usd.model.srgb import decode_srgb8
from synthua_usd.model.materials import PALETTE


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
    images = {f"textures/{name}.png": pixels for name, pixels in {**district_images(0), **paving_images(0)}.items()}
    assert set(textured.images) == ({f"textures/{image}.png" for image, _, _ in TEXTURED.values()}
                                    | {f"textures/{image}_normal.png" for image in PAVED})
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
    assert [f.stem for f in files] == ["asphalt", "pavers", "pavers_normal", "plaster", "setts", "setts_normal",
                                       "stone", "wood"]
    assert sum(f.stat().st_size for f in files) < 2_200_000
    for f in files:
        spec = oiio.ImageInput.open(str(f)).spec()
        assert (spec.width, spec.height, spec.nchannels) == (SIZE, SIZE, 3)


def test_paving_lays_stones_in_running_bond_with_joints_and_rounded_edges():
    """Stones, joints and slopes where an independent count of the layout puts them: 4 stones of 0.5 m per row,
    4 rows of 0.5 m, every other row shifted by 0.25 m, 5 cm joints, edges rounded over 5 cm, 1 cm deep."""
    size, tile = 256, 2.0
    shades = np.array([[1.0, 1.0, 1.0], [10.0, 10.0, 10.0]])
    colour, normals = paving(np.random.default_rng(0), size, tile, 4, 4, 0.05, 0.05, 0.01, shades, np.zeros(3))
    x = (np.arange(size) + 0.5) / size * tile          # metres along s, per column
    y = (1.0 - (np.arange(size) + 0.5) / size) * tile  # metres along t, per row (row 0 at the top)
    row = np.floor(y / 0.5).astype(int)[:, None]
    xs = x[None, :] - 0.25 * (row % 2)
    edge = np.minimum(np.minimum(xs % 0.5, 0.5 - xs % 0.5), np.minimum(y % 0.5, 0.5 - y % 0.5)[:, None])
    joint = edge < 0.025
    assert np.all(colour[joint] == 0.0) and np.all(colour[~joint] > 0.0)  # joints take the joint tone (black)
    flat = edge > 0.025 + 0.05 + 0.01  # past the rounded edge: the stone's top faces straight up
    assert np.allclose(normals[flat], [0.0, 0.0, 1.0])
    assert np.allclose(normals[edge < 0.025 - 0.008], [0.0, 0.0, 1.0])  # the joint floor (a texel from the stone)
    assert np.allclose(np.linalg.norm(normals, axis=2), 1.0)
    # On the rounded edge the surface falls towards the joint: a stone's east edge tilts east (+s), its north
    # edge north (+t). Pixels 2-4 cm inside the joint's edge, nearer that edge than any other, say so.
    to_east, to_north = 0.5 - xs % 0.5, (0.5 - y % 0.5)[:, None] * np.ones_like(xs)
    others_e = np.minimum(np.minimum(xs % 0.5, to_north), (y % 0.5)[:, None])
    others_n = np.minimum(np.minimum(xs % 0.5, to_east), (y % 0.5)[:, None])
    east = (to_east > 0.045) & (to_east < 0.065) & (others_e > to_east + 0.01)
    north = (to_north > 0.045) & (to_north < 0.065) & (others_n > to_north + 0.01)
    assert east.sum() > 50 and north.sum() > 50
    assert np.all(normals[east][:, 0] > 0.05) and np.allclose(normals[east][:, 1], 0.0, atol=1e-9)
    assert np.all(normals[north][:, 1] > 0.05) and np.allclose(normals[north][:, 0], 0.0, atol=1e-9)
    # each stone is one shade (1 or 10) under the grain (tens of per cent): its pixels are all one or the other
    stone_of = row * 4 + np.floor(xs / 0.5).astype(int) % 4
    low = []
    for k in range(16):
        values = colour[(stone_of == k) & ~joint].mean(axis=1)
        assert values.max() < 3.0 or values.min() > 3.0, k
        low.append(values.max() < 3.0)
    assert 0 < sum(low) < 16


def test_paving_images_are_seeded_and_tileable():
    a, b, other = paving_images(0, 128), paving_images(0, 128), paving_images(1, 128)
    assert sorted(a) == sorted([*PAVED, *(f"{n}_normal" for n in PAVED)])
    for name in a:
        assert a[name].shape == (128, 128, 3) and a[name].dtype == np.uint8
        assert np.array_equal(a[name], b[name])
    assert not np.array_equal(a["setts"], other["setts"])
    for name in PAVED:  # the joints run across the wrap-around edges as inside: the same share of joint pixels
        n = a[f"{name}_normal"].astype(float) / 255 * 2 - 1
        assert np.allclose(np.linalg.norm(n, axis=2), 1.0, atol=0.02)
        assert np.all(n[..., 2] > 0.3)  # never steeper than the bevel allows
