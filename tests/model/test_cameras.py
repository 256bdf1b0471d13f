import math

import numpy as np
import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.meshes import look_at


def camera(**kw):
    args = dict(path="/cam", focal_length_mm=24.0, horizontal_aperture_mm=36.0, vertical_aperture_mm=24.0,
                clip_near_m=0.1, clip_far_m=100.0, camera_to_world=look_at((0, -10, 2), (0, 0, 2)))
    args.update(kw)
    return PinholeCamera(**args)


def test_fov_from_lens():
    cam = camera()
    hfov, vfov = cam.fov_deg(360, 240)  # same aspect as the filmback
    assert hfov == pytest.approx(math.degrees(2 * math.atan(18 / 24)))
    assert vfov == pytest.approx(math.degrees(2 * math.atan(12 / 24)))


def test_expand_aperture_conform():
    cam = camera()
    # 4:3 image on a 3:2 filmback: the vertical aperture grows, horizontal stays.
    assert cam.conformed_aperture_mm(400, 300) == pytest.approx((36.0, 27.0))
    # 2:1 image: the horizontal grows.
    assert cam.conformed_aperture_mm(480, 240) == pytest.approx((48.0, 24.0))


def test_intrinsics_square_pixels_centred():
    k = camera().intrinsics(640, 480)
    assert k[0, 0] == pytest.approx(24 * 640 / 36) and k[0, 0] == k[1, 1]
    assert (k[0, 2], k[1, 2]) == (320, 240)


def test_pixel_rays_reproject_to_their_pixels():
    cam = camera(camera_to_world=look_at((3, -7, 4), (0, 1, 0.5)))
    w, h = 64, 48
    origins, dirs = cam.pixel_center_rays(w, h)
    points = origins + 5.0 * dirs
    ext = cam.world_to_camera_opencv()
    pc = (ext[:3, :3] @ points.T).T + ext[:3, 3]
    uv = (cam.intrinsics(w, h) @ pc.T).T
    uv = uv[:, :2] / uv[:, 2:]
    ys, xs = np.mgrid[0:h, 0:w]
    assert np.allclose(uv[:, 0], xs.ravel() + 0.5) and np.allclose(uv[:, 1], ys.ravel() + 0.5)


def test_image_up_is_world_up():
    cam = camera()
    _, dirs = cam.pixel_center_rays(3, 3)
    assert dirs[1, 2] > dirs[4, 2] > dirs[7, 2]  # top row looks higher than the bottom row
    assert dirs[3, 0] < dirs[4, 0] < dirs[5, 0]  # left column looks further left (-X) for a +Y view


@pytest.mark.parametrize("field,value,text", [
    ("focal_length_mm", 0.0, "focal_length_mm should be > 0, but was 0.0"),
    ("vertical_aperture_mm", float("nan"), "vertical_aperture_mm should be > 0"),
    ("clip_near_m", 200.0, "clipping range should satisfy 0 < near < far"),
])
def test_bad_values_are_refused_with_the_value(field, value, text):
    with pytest.raises(InputError, match=text.replace("(", r"\(")):
        camera(**{field: value})


def test_distorted_pixel_rays_project_back_onto_their_pixel_centres():
    from synthua_usd.model.distortion import BrownConrady

    cam = camera(camera_to_world=look_at((3, -7, 4), (0, 1, 0.5)),
                 distortion=BrownConrady(k1=-0.25, k2=0.05, p1=0.001, p2=-0.002))
    w, h = 64, 48
    origins, dirs = cam.pixel_center_rays(w, h)
    uv, z = cam.project(origins + 5.0 * dirs, w, h)
    ys, xs = np.mgrid[0:h, 0:w]
    assert np.all(z > 0)
    assert np.abs(uv[:, 0] - (xs.ravel() + 0.5)).max() < 1e-8 and np.abs(uv[:, 1] - (ys.ravel() + 0.5)).max() < 1e-8
    # and the lens does bend them: the corner ray leaves the pinhole's corner by pixels, not rounding
    _, plain = camera(camera_to_world=cam.camera_to_world).pixel_center_rays(w, h)
    assert np.degrees(np.arccos(np.clip(dirs[0] @ plain[0], -1, 1))) > 2.0


def test_zero_distortion_is_the_pinhole():
    from synthua_usd.model.distortion import BrownConrady

    zero = camera(distortion=BrownConrady())
    assert zero.distortion is None
    assert zero.pixel_center_rays(8, 6)[1].tobytes() == camera().pixel_center_rays(8, 6)[1].tobytes()
