"""Texture coordinates on bank bodies (synthua_usd/assets/garments.py), checked on every body of the bank: the face
image's eyes and mouth land on each body's own eyes (found by casting rays at its keypoints, not by the mapping),
fabric is mapped in metres without stretch and without a seam inside a triangle, and nothing but the head reaches
the face image."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from synthua_usd.assets.bodies import BONES, load_bank
from synthua_usd.assets.garments import AWAY, EYE_HALF_SPACING_M, FABRIC_TILE_M, FACE_SPAN_M, corner_uvs


@pytest.fixture(scope="module")
def bank():
    return load_bank()


def _st_at(bank, body: int, origins: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """(k, 2) st interpolated at the first hits of rays on the rest body (Embree, barycentric)."""
    points, tris = bank.points[body], bank.triangles
    mesh = trimesh.Trimesh(points, tris, process=False, validate=False)
    tri, ray, where = mesh.ray.intersects_id(origins, directions, multiple_hits=False, return_locations=True)
    assert len(ray) == len(origins)
    order = np.argsort(ray)
    tri, where = tri[order], where[order]
    bary = trimesh.triangles.points_to_barycentric(points[tris[tri]], where)
    return np.einsum("kc,kcd->kd", bary, corner_uvs(bank, body)[tri].astype(np.float64))


@pytest.mark.parametrize("body", range(0, 72, 3))
def test_the_face_images_eyes_lie_on_the_bodys_eyes(bank, body):
    """A ray from in front through each eye keypoint hits the face where the face image has that eye: s at
    +-EYE_HALF_SPACING_M from the middle (over FACE_SPAN_M), t at the middle, within 4 mm of face."""
    eyes = bank.keypoints[body][[1, 2]]
    origins = eyes + [0.5, 0.0, 0.0]
    st = _st_at(bank, body, origins, np.tile([-1.0, 0.0, 0.0], (2, 1)))
    expected = np.array([[0.5 + EYE_HALF_SPACING_M / FACE_SPAN_M, 0.5], [0.5 - EYE_HALF_SPACING_M / FACE_SPAN_M, 0.5]])
    assert np.abs(st - expected).max() * FACE_SPAN_M < 0.004, (st, expected)


def test_only_the_head_reaches_the_face_image(bank):
    """Every corner of a triangle not dominated by the head has s beyond the face image (clamped: plain skin)."""
    head = BONES.index("head")
    for body in range(len(bank)):
        st = corner_uvs(bank, body)
        assert (st[bank.face_bone != head, :, 0] > 1.5).all()
        assert (st[bank.face_bone != head, :, 0] > AWAY - 5).all()


@pytest.mark.parametrize("body", [3, 30, 60])
def test_fabric_is_mapped_in_metres_without_stretch_or_seams_inside_triangles(bank, body):
    """On the garment bones, a triangle's area in st (times FABRIC_TILE_M squared) is its area in metres (the
    median ratio within 15 %, nine in ten within a factor of 2), and hardly a triangle spans more than half a
    repeat in s: the back seam is unwrapped per triangle (unwrapped, a seam triangle spans a whole
    circumference, 2-3 repeats); what remains are a few collar triangles round the torso's axis (0.6 % of the
    garment triangles at most over the bank)."""
    garment = np.isin(np.array(BONES)[bank.face_bone], ["torso", "upperleg.L", "upperleg.R", "lowerleg.L",
                                                        "lowerleg.R", "upperarm.L", "upperarm.R", "lowerarm.L",
                                                        "lowerarm.R"])
    st = corner_uvs(bank, body)[garment].astype(np.float64) * FABRIC_TILE_M
    p = bank.points[body][bank.triangles[garment]]
    metres = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    e1, e2 = st[:, 1] - st[:, 0], st[:, 2] - st[:, 0]
    mapped = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    ratio = mapped / np.maximum(metres, 1e-12)
    assert abs(np.median(ratio) - 1.0) < 0.15
    assert np.mean((ratio > 0.5) & (ratio < 2.0)) > 0.9
    assert np.mean(np.ptp(st[..., 0], axis=1) / FABRIC_TILE_M > 0.5) < 0.01
