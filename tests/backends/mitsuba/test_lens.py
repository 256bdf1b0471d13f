"""Lens distortion in the renderer. Labels through the Brown–Conrady model agree with an independent
Embree cast of rays whose undistortion is computed here by another method (OpenCV's fixed-point scheme,
not the library's Newton); zero distortion renders the pinhole bit for bit; the RGB is distorted like the
labels."""

import dataclasses

import numpy as np
import pytest
from scipy import ndimage

from conftest import DATA
from reference_raycast import labels_of_rays
from synthua_usd.backends.mitsuba.lens import distorted_sensor, sensor_rays
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.distortion import BrownConrady
from synthua_usd.model.meshes import look_at
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.stage_io import open_stage

LENS = BrownConrady(k1=-0.3, k2=0.08, p1=0.002, p2=-0.001)
W, H = 160, 120
CAMERAS = ("CCTV", "PedestrianEye")


def fixed_point_undistort(lens: BrownConrady, xd, yd, iterations: int = 500):
    """OpenCV's undistortPoints scheme: x = (x_d - tangential(x)) / radial(x), iterated; written out here
    from the forward formula, sharing no code with the library's inverse."""
    x, y = xd.copy(), yd.copy()
    for _ in range(iterations):
        r2 = x * x + y * y
        radial = 1 + lens.k1 * r2 + lens.k2 * r2 ** 2 + lens.k3 * r2 ** 3
        x, y = ((xd - (2 * lens.p1 * x * y + lens.p2 * (r2 + 2 * x * x))) / radial,
                (yd - (lens.p1 * (r2 + 2 * y * y) + 2 * lens.p2 * x * y)) / radial)
    return x, y


def independent_rays(camera, lens, width, height):
    """Origins and directions (H*W, 3) of the pixel centres through ``lens``, from the camera's matrix and
    its lens values in millimetres (not from PinholeCamera's ray code)."""
    _, v_ap = camera.conformed_aperture_mm(width, height)
    f_px = camera.focal_length_mm * height / v_ap
    ys, xs = np.mgrid[0:height, 0:width]
    xd, yd = (xs + 0.5 - width / 2) / f_px, (ys + 0.5 - height / 2) / f_px
    x, y = fixed_point_undistort(lens, xd, yd)
    fx, fy = lens.distort(x, y)
    assert max(np.abs(fx - xd).max(), np.abs(fy - yd).max()) < 1e-12  # the reference itself converged
    m = camera.camera_to_world
    d = x.reshape(-1, 1) * m[:3, 0] - y.reshape(-1, 1) * m[:3, 1] - m[:3, 2]  # camera looks down -Z, +Y up
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.broadcast_to(m[:3, 3], d.shape).copy(), d


@pytest.fixture(scope="module")
def street(demo_stage, class_map):
    snap = read_snapshot(demo_stage, 24, class_map)
    return snap, {name: read_camera(demo_stage, f"/World/Cameras/{name}", 24) for name in CAMERAS}


@pytest.fixture(scope="module")
def session(variant):
    return RenderSession(RenderConfig(width=W, height=H, spp=1, variant=variant))


@pytest.mark.slow
@pytest.mark.parametrize("name", CAMERAS)
def test_distorted_labels_equal_an_independent_computation(street, session, name):
    snap, cameras = street
    pinhole = cameras[name]
    distorted = session.render(snap, dataclasses.replace(pinhole, distortion=LENS), rgb=False)
    ref_class, ref_inst = labels_of_rays(snap, *independent_rays(pinhole, LENS, W, H), W, H)
    assert np.array_equal(distorted.instance_ids, ref_inst) and np.array_equal(distorted.class_ids, ref_class)
    # Not vacuous: the lens moves a good share of the pixels to other objects.
    plain = session.render(snap, pinhole, rgb=False)
    assert np.mean(plain.instance_ids != distorted.instance_ids) > 0.05


def test_zero_distortion_is_bit_identical_to_the_pinhole(street, session):
    snap, cameras = street
    pinhole = cameras["CCTV"]
    plain = session.render(snap, pinhole, rgb=False)
    zero = session.render(snap, dataclasses.replace(pinhole, distortion=BrownConrady()), rgb=False)
    assert zero.instance_ids.tobytes() == plain.instance_ids.tobytes()
    assert zero.hits.z_m.tobytes() == plain.hits.z_m.tobytes() and zero.hits.distance_m.tobytes() == plain.hits.distance_m.tobytes()
    # The ray path a real lens takes, at a distortion too small to move a ray, hits what the sensor's rays hit
    # (depths agree to float32 rounding of the directions, under a millimetre here).
    near_zero = session.render(snap, dataclasses.replace(pinhole, distortion=BrownConrady(k1=1e-15)), rgb=False)
    assert np.array_equal(near_zero.instance_ids, plain.instance_ids)
    assert np.abs(near_zero.hits.z_m - plain.hits.z_m).max() < 2e-3
    # quick_labels (camera placement's pass) takes that path without pointing the sensor: same ids here
    assert np.array_equal(session.quick_labels(snap, cameras["PedestrianEye"]),
                          session.render(snap, cameras["PedestrianEye"], rgb=False).instance_ids)


def test_the_rgb_sensor_shoots_the_label_rays(variant, tiny):
    from conftest import activate_variant

    mi = activate_variant(variant)
    camera = dataclasses.replace(tiny[1], distortion=LENS)
    sensor = distorted_sensor(mi, camera, RenderConfig(width=32, height=24, spp=1, variant=variant))
    ys, xs = np.mgrid[0:24, 0:32]
    _, dirs = sensor_rays(mi, sensor, np.column_stack([(xs.ravel() + 0.5) / 32, (ys.ravel() + 0.5) / 24]))
    assert np.abs(dirs - camera.pixel_center_rays(32, 24)[1]).max() < 1e-6  # float32 Newton vs float64


def test_rgb_is_distorted_like_the_labels(variant, class_map):
    """Red box and blue ball seen close up with a wide lens, so the lens moves their edges by pixels: away
    from label edges (3x3 neighbourhoods with one id), red pixels are exactly the box's and blue ones the
    ball's in the distorted RGB, while the pinhole's RGB misses the distorted labels."""
    stage = open_stage(DATA / "valid" / "tiny_lit_scene.usda")
    snap = read_snapshot(stage, 1, class_map)
    pinhole = dataclasses.replace(read_camera(stage, "/World/Cam", 1), focal_length_mm=20.0,
                                  camera_to_world=look_at((0.1, -1.9, 1.0), (0.05, 0.2, 0.35)))
    session = RenderSession(RenderConfig(width=64, height=48, spp=16, variant=variant))
    distorted = session.render(snap, dataclasses.replace(pinhole, distortion=LENS))
    plain = session.render(snap, pinhole)
    ids = {i.prim_path: i.id for i in snap.instances}
    labels = distorted.instance_ids
    interior = ndimage.maximum_filter(labels, 3, mode="nearest") == ndimage.minimum_filter(labels, 3, mode="nearest")

    def wrong(rgb):
        red, blue = rgb[..., 0] > 2 * rgb[..., 1], rgb[..., 2] > 2 * rgb[..., 0]
        ok = (red == (labels == ids["/World/Box"])) & (blue == (labels == ids["/World/Ball"]))
        return int((~ok & interior).sum())

    assert interior.sum() > 2000 and wrong(distorted.rgb) == 0
    assert wrong(plain.rgb) > 30
