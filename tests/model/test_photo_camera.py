"""The ground-plane camera of a photo, against a pinhole camera projecting points by its rotation (an independent
computation of the same geometry)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.model.photo_camera import PhotoCamera, focal_px_from_35mm, horizon_from_people


def _project(point_cam: np.ndarray, f: float, cx: float, cy: float) -> tuple[float, float]:
    """OpenCV projection of a camera-frame point (x right, y down, z forward)."""
    return cx + f * point_cam[0] / point_cam[2], cy + f * point_cam[1] / point_cam[2]


def _to_camera(point_world: np.ndarray, height_m: float, pitch_deg: float) -> np.ndarray:
    """A world point (x right, y up, z forward along the ground) in the frame of a camera ``height_m`` above the
    origin pitched by ``pitch_deg`` (negative: down)."""
    p = point_world - np.array([0.0, height_m, 0.0])
    t = math.radians(pitch_deg)
    # rotate the world so that the camera's axis (pitched) becomes +z, then flip y to point down
    y = p[1] * math.cos(t) - p[2] * math.sin(t)
    z = p[1] * math.sin(t) + p[2] * math.cos(t)
    return np.array([p[0], -y, z])


@pytest.mark.parametrize("distance_m, height_m, subject_m", [(3.0, 1.5, 1.3), (12.0, 1.1, 1.8), (40.0, 6.0, 1.7)])
def test_a_level_camera_places_ground_points_and_heights_as_a_pinhole_does(distance_m, height_m, subject_m):
    width, height, f = 640, 480, 500.0
    camera = PhotoCamera(width, height, height / 2.0, height_m, f)
    _, foot = _project(_to_camera(np.array([0.3, 0.0, distance_m]), height_m, 0.0), f, width / 2, height / 2)
    _, head = _project(_to_camera(np.array([0.3, subject_m, distance_m]), height_m, 0.0), f, width / 2, height / 2)
    assert camera.distance_m(foot) == pytest.approx(distance_m)
    assert camera.pixel_height(subject_m, foot) == pytest.approx(foot - head)
    assert camera.elevation_deg(foot) == pytest.approx(math.degrees(math.atan2(height_m, distance_m)))
    assert camera.anchor_row(subject_m, foot - head) == pytest.approx(foot)


@pytest.mark.parametrize("pitch_deg", [-20.0, -5.0, 0.0, 8.0])
def test_the_horizon_of_a_pitched_camera_is_where_a_far_ground_point_projects(pitch_deg):
    f = 400.0
    camera = PhotoCamera.from_pitch(320, 240, pitch_deg, 1.6, f)
    _, far = _project(_to_camera(np.array([0.0, 0.0, 1e9]), 1.6, pitch_deg), f, 160, 120)
    assert camera.horizon_row_px == pytest.approx(far, abs=1e-4)
    assert camera.pitch_deg == pytest.approx(pitch_deg)


def test_ground_depth_is_the_ground_distance_below_the_horizon_and_infinity_above():
    camera = PhotoCamera(8, 10, 3.2, 2.0, 100.0)
    depth = camera.ground_depth()
    assert depth.shape == (10, 8) and depth.dtype == np.float32
    assert (depth[:3] == 0).all()               # rows 0..2: centres 0.5..2.5 lie above the horizon at 3.2
    for row in range(3, 10):
        assert depth[row, 5] == pytest.approx(camera.distance_m(row + 0.5), rel=1e-6)


def test_intrinsics_and_35mm_focal_length():
    camera = PhotoCamera(640, 480, 100.0, 1.5, 520.0)
    assert camera.intrinsics().tolist() == [[520.0, 0.0, 320.0], [0.0, 520.0, 240.0], [0.0, 0.0, 1.0]]
    assert focal_px_from_35mm(28.0, 4000, 3000) == pytest.approx(28.0 / 36.0 * 4000)
    assert focal_px_from_35mm(28.0, 3000, 4000) == pytest.approx(28.0 / 36.0 * 4000)   # the long side, portrait too


@pytest.mark.parametrize("field, value", [("height_m", 0.0), ("focal_px", -1.0), ("horizon_row_px", float("nan"))])
def test_impossible_values_are_refused(field, value):
    values = {"horizon_row_px": 10.0, "height_m": 1.5, "focal_px": 300.0, field: value}
    with pytest.raises(InputError, match=f"camera model: {field}"):
        PhotoCamera(64, 48, **values)


def test_an_anchor_on_or_above_the_horizon_has_no_distance():
    with pytest.raises(ValueError, match="not below the horizon"):
        PhotoCamera(64, 48, 20.0, 1.5, 60.0).distance_m(20.0)


def test_a_photos_standing_people_put_the_horizon_where_the_pinhole_puts_it():
    """People 1.7 m tall standing at 3, 6 and 15 m, projected by the rotation-free pinhole above, give back the
    horizon of the level camera that saw them; boxes the photo's edges cut, or too small, place nothing."""
    width, height, f, camera_m = 640, 480, 500.0, 1.4
    boxes = []
    for distance in (3.0, 6.0, 15.0):
        _, foot = _project(_to_camera(np.array([0.0, 0.0, distance]), camera_m, 0.0), f, width / 2, 200.0)
        _, head = _project(_to_camera(np.array([0.0, 1.7, distance]), camera_m, 0.0), f, width / 2, 200.0)
        boxes.append(((100.0, head, 140.0, foot), 1.7))
    photo = (0.0, float(height))
    row, used = horizon_from_people(boxes, photo, camera_m)
    assert used == 3 and row == pytest.approx(200.0)         # a level camera's horizon is its principal row
    cut = [((0.0, 0.0, 50.0, 300.0), 1.7), ((0.0, 200.0, 50.0, 480.0), 1.7), ((0.0, 100.0, 10.0, 110.0), 1.7)]
    assert horizon_from_people(cut, photo, camera_m) is None   # top, bottom, 10 px
    assert horizon_from_people(boxes[:1] + cut, photo, camera_m) == (pytest.approx(200.0), 1)
    # a taller stated person (or a lower camera) puts the horizon lower: y_b - p H / h
    assert horizon_from_people([(boxes[0][0], 1.9)], photo, camera_m)[0] > 200.0


def test_seated_wheelchair_users_and_boxes_the_cut_crops_place_the_horizon_too():
    """A wheelchair user 1.35 m tall from the ground up, seated 4 m away, gives back the same horizon with their
    height; a box whose head the cut for the output crops (rows above the frame) counts in its whole extent while
    the photo holds it whole, and not where the photo's own edge cuts it."""
    f, camera_m, principal = 500.0, 1.0, 120.0
    _, foot = _project(_to_camera(np.array([0.0, 0.0, 4.0]), camera_m, 0.0), f, 320.0, principal)
    _, head = _project(_to_camera(np.array([0.0, 1.35, 4.0]), camera_m, 0.0), f, 320.0, principal)
    _, near_foot = _project(_to_camera(np.array([0.0, 0.0, 1.8]), camera_m, 0.0), f, 320.0, principal)
    _, near_head = _project(_to_camera(np.array([0.0, 1.7, 1.8]), camera_m, 0.0), f, 320.0, principal)
    assert near_head < 0.0 < near_foot < 480.0                 # the frame shows the standing person's legs only
    seated, standing = ((300.0, head, 360.0, foot), 1.35), ((100.0, near_head, 160.0, near_foot), 1.7)
    assert horizon_from_people([seated], (0.0, 480.0), camera_m) == (pytest.approx(principal), 1)
    photo = (-100.0, 540.0)                                     # the photo reaches 100 rows above the frame
    assert horizon_from_people([seated, standing], photo, camera_m) == (pytest.approx(principal), 2)
    assert horizon_from_people([standing], (0.0, 480.0), camera_m) is None
    assert horizon_from_people([standing], (near_head + 2.0, 540.0), camera_m) is None   # the photo's edge cuts it
