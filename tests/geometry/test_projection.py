"""Projected boxes and truncation by the frame, on cases computed by hand.

The camera sits at the world origin looking down -Z (+Y up): focal 50 mm on a 36 x 24 mm filmback at
360 x 240 pixels, so f = 500 px, cx = 180, cy = 120, and a world point (X, Y, -D) lands on pixel
(500 X / D + 180, -500 Y / D + 120).
"""

import numpy as np
import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.geometry.projection import frame_outline, projected_box, projected_boxes, truncation, truncations
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.distortion import BrownConrady

W, H = 360, 240
QUAD = np.array([[0, 1, 2], [0, 2, 3]])


def camera(distortion=None) -> PinholeCamera:
    return PinholeCamera("/Cam", 50.0, 36.0, 24.0, 0.05, 1000.0, np.eye(4), distortion)


def square(x0, x1, y0, y1, depth):
    """A world quad facing the camera at distance ``depth`` (metres)."""
    return np.array([[x0, y0, -depth], [x1, y0, -depth], [x1, y1, -depth], [x0, y1, -depth]], float)


def test_square_inside_is_not_truncated():
    pts = square(-1, 1, -1, 1, 10)  # 100 x 100 px around the centre
    assert np.allclose(projected_box(pts, QUAD, camera(), W, H), [130, 70, 230, 170])
    assert truncation(pts, QUAD, camera(), W, H) == 0.0


def test_square_half_outside_the_right_edge_is_half_truncated():
    pts = square(3.6 - 1, 3.6 + 1, -1, 1, 10)  # X = 3.6 m at 10 m is the right edge, u = 360
    assert np.allclose(projected_box(pts, QUAD, camera(), W, H), [310, 70, 410, 170])
    assert truncation(pts, QUAD, camera(), W, H) == pytest.approx(0.5)


def test_square_over_a_corner_is_three_quarters_truncated():
    pts = square(3.6 - 1, 3.6 + 1, 2.4 - 1, 2.4 + 1, 10)  # centred on the top-right corner (360, 0)
    assert truncation(pts, QUAD, camera(), W, H) == pytest.approx(0.75)


def test_geometry_behind_the_camera_is_clipped_at_the_near_plane():
    """A strip in the plane X = 1 from 10 m in front of the camera to 10 m behind it. Clipped at z = 0.05 m
    its box runs from u = 500 / 10 + 180 = 230 to u = 500 / 0.05 + 180 = 10180, and v = 120 -+ 500 * 0.1 / 0.05
    = [-880, 1120]; of that, [230, 360] x [0, 240] is in the frame. Projecting the vertex behind the camera
    without clipping would flip it to the left of the image instead."""
    pts = np.array([[1, -0.1, -10], [1, -0.1, 10], [1, 0.1, 10], [1, 0.1, -10]], float)
    box = projected_box(pts, QUAD, camera(), W, H)
    assert np.allclose(box, [230, -880, 10180, 1120])
    expected = 1 - (130 * 240) / ((10180 - 230) * 2000)
    assert truncation(pts, QUAD, camera(), W, H) == pytest.approx(expected)


def test_geometry_wholly_behind_the_camera_is_fully_truncated():
    pts = square(-1, 1, -1, 1, -5)
    assert projected_box(pts, QUAD, camera(), W, H) is None
    assert truncation(pts, QUAD, camera(), W, H) == 1.0


def test_square_wholly_outside_is_fully_truncated():
    pts = square(10, 12, -1, 1, 10)
    assert truncation(pts, QUAD, camera(), W, H) == 1.0


def test_unused_points_do_not_count():
    pts = np.vstack([square(-1, 1, -1, 1, 10), [[100.0, 0, -10]]])  # the last point is in no triangle
    assert truncation(pts, QUAD, camera(), W, H) == 0.0


def test_barrel_distortion_shows_more_than_the_pinhole_frame():
    """With k1 < 0 the frame's right edge (x_d = 0.36 normalised, on the axis row) images the undistorted
    x solving x (1 + k1 x^2) = 0.36: a thin box from the pinhole edge u = 360 to u = 370 is inside up to
    u = 500 x + 180."""
    k1 = -0.2
    cam = camera(BrownConrady(k1=k1))
    roots = np.roots([k1, 0.0, 1.0, -0.36])
    x = min(r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0)
    u_edge = 500 * x + 180
    assert 360 < u_edge < 370
    pts = square(3.6, 3.8, -0.002, 0.002, 10)  # u from 360 to 370, 0.2 px tall on the axis row
    assert truncation(pts, QUAD, cam, W, H) == pytest.approx(1 - (u_edge - 360) / 10, abs=1e-4)
    assert truncation(pts, QUAD, camera(), W, H) == pytest.approx(1.0)


def test_distorted_frame_outline_maps_back_onto_the_frame_border():
    cam = camera(BrownConrady(k1=-0.2, p1=0.001))
    outline = frame_outline(cam, W, H)
    xd, yd = cam.distortion.distort((outline[:, 0] - 180) / 500, (outline[:, 1] - 120) / 500)
    u, v = 500 * xd + 180, 500 * yd + 120
    on_border = np.minimum.reduce([np.abs(u), np.abs(u - W), np.abs(v), np.abs(v - H)])
    assert np.all(on_border < 1e-6)


@pytest.mark.parametrize("points, triangles", [(np.zeros((3, 2)), [[0, 1, 2]]),
                                               (np.zeros((3, 3)), [[0, 1, 3]]),
                                               (np.zeros((3, 3)), [[0.0, 1.0, 2.0]])])
def test_bad_input_is_refused(points, triangles):
    with pytest.raises(InputError, match="projection"):
        truncation(points, np.asarray(triangles), camera(), W, H)


def box_of_one_mesh(points, triangles, cam, width, height):
    """projected_box the straightforward way, one mesh at a time: project the used points in front of the
    near plane and the points where triangle edges cross it."""
    ext = cam.world_to_camera_opencv()
    pc = points @ ext[:3, :3].T + ext[:3, 3]
    front = pc[:, 2] >= cam.clip_near_m
    used = np.zeros(len(pc), bool)
    used[triangles.ravel()] = True
    found = [pc[used & front]]
    for a, b in ((0, 1), (1, 2), (2, 0)):
        pa, pb = pc[triangles[:, a]], pc[triangles[:, b]]
        cross = front[triangles[:, a]] != front[triangles[:, b]]
        t = (cam.clip_near_m - pa[cross, 2]) / (pb[cross, 2] - pa[cross, 2])
        found.append(pa[cross] + t[:, None] * (pb[cross] - pa[cross]))
    found = np.concatenate(found)
    if not len(found):
        return None
    k = cam.intrinsics(width, height)
    u = k[0, 0] * found[:, 0] / found[:, 2] + k[0, 2]
    v = k[1, 1] * found[:, 1] / found[:, 2] + k[1, 2]
    return np.array([u.min(), v.min(), u.max(), v.max()])


def test_boxes_of_many_meshes_at_once_equal_each_mesh_alone():
    """truncations works on all of an image's instances together (and multiplies large meshes in blocks):
    each box must be exactly the one of its mesh alone, also across the near plane, for empty meshes and
    unused points."""
    rng = np.random.default_rng(5)
    cam = PinholeCamera("/Cam", 35.0, 36.0, 24.0, 0.05, 1000.0,
                        np.array([[1, 0, 0, 0.3], [0, 0.8, -0.6, 1.5], [0, 0.6, 0.8, 2.0], [0, 0, 0, 1.0]]), None)
    parts = [(np.zeros((0, 3)), np.zeros((0, 3), np.int64))]
    for n in (3, 10, 40, 200, 20000):  # 20000 points: more than one block
        for spread in (0.5, 30.0):  # 30 m around the camera: meshes across the near plane and behind it
            points = rng.normal(0, spread, (n, 3)) + [0, 0, -8]
            triangles = rng.integers(0, max(1, n - 2), (max(1, n // 2), 3))  # the last points unused
            parts.append((points, triangles))
    parts.append((square(-1, 1, -1, 1, -5), QUAD))  # wholly behind
    boxes = projected_boxes(parts, cam, W, H)
    crossing = 0
    for (points, triangles), box in zip(parts, boxes):
        expected = box_of_one_mesh(points, triangles, cam, W, H) if len(triangles) else None
        assert (box is None and expected is None) or np.array_equal(box, expected)
        crossing += expected is not None and (expected[2] - expected[0]) > 10 * W
    assert boxes[0] is None and boxes[-1] is None and crossing >= 2
    assert truncations(parts, cam, W, H) == [truncation(p, t, cam, W, H) for p, t in parts]
