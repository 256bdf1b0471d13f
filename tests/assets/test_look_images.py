"""The images people wear (synthua_usd/assets/look_images.py): the shipped files hold exactly what the code makes,
fabrics tile, normal maps are unit and face out, the face image is plain skin at its edge with dark irises and
light whites where its eyes are, a sneaker's sole is its bottom band, and two_colour gives the asked colours."""

from __future__ import annotations

import numpy as np
import pytest

from synthua_usd.assets.garments import EYE_HALF_SPACING_M, FACE_SPAN_M, SHOE_TILE_M
from synthua_usd.assets.look_images import (FABRICS, FACE_OFFSET, SHOES, image_path, look_images, two_colour)
from synthua_usd.core.images import read_image


@pytest.fixture(scope="module")
def made():
    return look_images()


def test_the_shipped_images_are_what_the_code_makes(made):
    """tools/build_look_images.py wrote them; a change of the generators without a rebuild fails here."""
    assert len(made) == 2 * len(FABRICS) + 2 * len(SHOES) + 1
    for stem, pixels in made.items():
        shipped, _ = read_image(image_path(stem))
        assert shipped.shape == pixels.shape and np.array_equal(shipped, pixels), stem


@pytest.mark.parametrize("kind", FABRICS)
def test_fabrics_tile_and_their_normals_face_out(made, kind):
    """Across the wrap-around (last column to first, last row to first) the mask and normals step no more
    than between neighbours inside; normals decode to unit vectors with z > 0.5 (folds tilt, never fold over)."""
    for stem in (f"fabric_{kind}", f"fabric_{kind}_normal"):
        a = made[stem].astype(float)
        for axis in (0, 1):
            inside = np.abs(np.diff(a, axis=axis)).mean()
            across = np.abs(np.take(a, 0, axis=axis) - np.take(a, -1, axis=axis)).mean()
            assert across < 2.0 * inside + 1.0, (stem, axis, across, inside)
    n = made[f"fabric_{kind}_normal"].astype(float) / 255.0 * 2.0 - 1.0
    assert np.allclose(np.linalg.norm(n, axis=2), 1.0, atol=0.02) and n[..., 2].min() > 0.5


def test_the_face_image(made):
    """Stored (m + FACE_OFFSET) / (1 + FACE_OFFSET): its edge is m = 0 (skin, 85 of 255), each eye's centre m = 1
    (pupil), its whites below 0 (lighter than skin) beside the iris, at the positions the mapping puts a body's
    eyes (garments.EYE_HALF_SPACING_M from the middle)."""
    face = made["face"].astype(float) / 255.0 * (1 + FACE_OFFSET) - FACE_OFFSET
    size = face.shape[0]
    edge = np.concatenate([face[0], face[-1], face[:, 0], face[:, -1]])
    assert np.abs(edge).max() < 1 / 255 * (1 + FACE_OFFSET)
    row = size // 2  # t = 0.5: the eyes' height
    for side in (1, -1):
        col = int((0.5 + side * EYE_HALF_SPACING_M / FACE_SPAN_M) * size)
        assert face[row - 1:row + 1, col - 1:col + 1].min() > 0.9  # the pupil
        white = int((0.5 + side * (EYE_HALF_SPACING_M + 0.009) / FACE_SPAN_M) * size)
        assert face[row, white].max() < -0.3


@pytest.mark.parametrize("kind, sole_m", [("sneaker", 0.03), ("shoe", 0.015)])
def test_a_shoes_sole_is_its_bottom_band(made, kind, sole_m):
    mask = made[f"shoe_{kind}"][..., 0].astype(float) / 255.0
    size = mask.shape[0]
    height = (size - 0.5 - np.arange(size)) / size * SHOE_TILE_M  # row 0 is the top
    assert mask[height < sole_m - 0.002].mean() > 0.95
    assert mask[height > sole_m + 0.02].mean() < 0.15


def test_two_colour_turns_a_mask_into_its_two_colours():
    c1, c2 = (0.2, 0.3, 0.4), (0.9, 0.1, 0.0)
    scale, bias = two_colour(c1, c2)
    for m, expected in ((0.0, c1), (1.0, c2)):
        assert np.allclose(m * np.array(scale[:3]) + bias[:3], expected)
    scale, bias = two_colour(c1, c2, FACE_OFFSET)
    stored = (np.array([0.0, 1.0, -0.5]) + FACE_OFFSET) / (1 + FACE_OFFSET)  # m = 0, 1 and -0.5
    got = stored[:, None] * np.array(scale[:3]) + bias[:3]
    assert np.allclose(got[0], c1) and np.allclose(got[1], c2)
    assert np.allclose(got[2], np.array(c1) - 0.5 * (np.array(c2) - np.array(c1)))
