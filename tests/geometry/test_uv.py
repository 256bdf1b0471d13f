"""Texture-coordinate projections and seam splitting on plain arrays."""

import numpy as np
import pytest

from synthua_usd.geometry.uv import box_uvs, planar_uvs
from synthua_usd.model.meshes import split_corners
from synthua_usd.model import meshes as geo


def test_box_projection_keeps_every_triangle_and_shares_points_within_a_face():
    points, tris = geo.box((0, 0, 0), (2, 1, 3))
    new_points, new_tris, uvs = box_uvs(points, tris, tile_m=0.5)
    assert np.array_equal(new_points[new_tris], points[tris])
    # Split at the box's edges where the faces' projections disagree (at most 6 faces x 4 corners), never
    # inside a face: a corner whose coordinates agree across an edge stays one point.
    assert 8 < len(new_points) <= 24
    corners = new_points[new_tris]
    normals = np.round(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), 6)
    for normal in np.unique(normals, axis=0):  # a face's two triangles share its diagonal's two points
        a, b = new_tris[np.all(normals == normal, axis=1)]
        assert len(set(a.tolist()) & set(b.tolist())) == 2, normal
    assert uvs.shape == (len(new_points), 2) and uvs.dtype == np.float32


@pytest.mark.parametrize("heading_deg", [0.0, 30.0, 135.0])
def test_walls_get_the_image_upright_and_unmirrored_at_any_heading(heading_deg):
    a = np.radians(heading_deg)
    right = np.array([np.cos(a), np.sin(a), 0.0])  # seen from the front, this way is right
    quad = np.array([[0, 0, 0], right * 2, right * 2 + [0, 0, 1], [0, 0, 1]], float)
    tris = np.array([[0, 1, 2], [0, 2, 3]])  # counter-clockwise seen from the front
    pts, new_tris, uvs = box_uvs(quad, tris, tile_m=1.0)
    st = {tuple(np.round(p, 6)): tuple(np.round(uv, 5)) for p, uv in zip(pts, uvs)}
    s0, t0 = st[tuple(np.round(quad[0], 6))]
    s1, _ = st[tuple(np.round(quad[1], 6))]
    _, t3 = st[tuple(np.round(quad[3], 6))]
    assert s1 - s0 == pytest.approx(2.0, abs=1e-4) and t3 - t0 == pytest.approx(1.0, abs=1e-4)
    assert len(pts) == 4


def test_planar_uvs_are_x_y_in_repeats():
    assert planar_uvs(np.array([[3.0, -1.5, 7.0]]), 1.5).tolist() == [[2.0, -1.0]]


def test_split_corners_splits_only_at_seams():
    points = np.arange(12, dtype=float).reshape(4, 3)
    tris = np.array([[0, 1, 2], [0, 2, 3]])
    same = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]], np.float32)
    p, t, uv = split_corners(points, tris, same)
    assert np.array_equal(p, points) and np.array_equal(t, tris)
    seam = same.copy()
    seam[1, 1] = (-1, 1)  # point 2 seen from the second triangle
    p, t, uv = split_corners(points, tris, seam)
    assert len(p) == 5 and np.array_equal(p[t], points[tris]) and np.array_equal(uv[t], seam)
