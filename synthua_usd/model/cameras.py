"""Pinhole cameras: physical lens values, the image they form, intrinsics and pixel-centre rays.

Frames and conventions
----------------------
* ``camera_to_world`` is a (4, 4) float64 matrix in the column-vector convention (``p_world = M @ p_cam``),
  world units metres. The camera looks down its local -Z axis with +Y up and +X right (USD/OpenGL).
* Pixel (0, 0) is the top-left pixel; pixel centres are at integer + 0.5; image y grows downward.
* Intrinsics ``K`` follow OpenCV: x right, y down, z forward; ``cx = W/2``, ``cy = H/2`` (no lens shift).
* Lens values are in millimetres here. USD authors them in tenths of a scene unit; the USD reader converts.
* An optional Brown–Conrady ``distortion`` (:mod:`synthua_usd.model.distortion`, OpenCV's convention) acts on
  normalised image coordinates: ``K`` stays the ideal pinhole's, and a pixel centre's ray goes through the
  undistorted point that the lens maps onto it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from synthua_usd.core.errors import InputError
from synthua_usd.model.distortion import BrownConrady

#: USD's default ``aspectRatioConformPolicy``: when the image and aperture aspects differ, the aperture
#: grows along one axis so that the whole authored aperture stays visible.
CONFORM_EXPAND = "expandAperture"


@dataclass(frozen=True, eq=False)
class PinholeCamera:
    """A perspective camera at one time code.

    Attributes
    ----------
    path : str
        Prim path of the camera in its stage.
    focal_length_mm, horizontal_aperture_mm, vertical_aperture_mm : float
        Physical lens and filmback, millimetres.
    clip_near_m, clip_far_m : float
        Clipping range, metres.
    camera_to_world : (4, 4) float64
        Rigid transform, column-vector convention, metres.
    distortion : BrownConrady or None
        Lens distortion; None (and all-zero coefficients, which are stored as None) is the ideal pinhole.
    exposure_ev : float
        Exposure compensation in stops (USD's ``exposure``: 1 doubles the image's intensities), applied on top
        of the metered exposure.
    """

    path: str
    focal_length_mm: float
    horizontal_aperture_mm: float
    vertical_aperture_mm: float
    clip_near_m: float
    clip_far_m: float
    camera_to_world: np.ndarray = field(repr=False)
    distortion: BrownConrady | None = None
    exposure_ev: float = 0.0

    def __post_init__(self) -> None:
        for name in ("focal_length_mm", "horizontal_aperture_mm", "vertical_aperture_mm"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise InputError(f"camera {self.path}: {name} should be > 0, but was {value}")
        if not (0 < self.clip_near_m < self.clip_far_m):
            raise InputError(f"camera {self.path}: clipping range should satisfy 0 < near < far, "
                             f"but was ({self.clip_near_m}, {self.clip_far_m})")
        m = np.asarray(self.camera_to_world, np.float64)
        if m.shape != (4, 4) or not np.all(np.isfinite(m)):
            raise InputError(f"camera {self.path}: camera_to_world should be a finite 4x4 matrix")
        object.__setattr__(self, "camera_to_world", m)
        if not (math.isfinite(self.exposure_ev) and abs(self.exposure_ev) <= 20):
            raise InputError(f"camera {self.path}: exposure should be a finite number of stops within ±20, "
                             f"but was {self.exposure_ev}")
        if self.distortion is not None and self.distortion.is_zero:
            object.__setattr__(self, "distortion", None)  # zero distortion is the pinhole, exactly

    # --- image formation -------------------------------------------------------------------------

    def conformed_aperture_mm(self, width: int, height: int) -> tuple[float, float]:
        """(horizontal, vertical) aperture in mm after USD's ``expandAperture`` conform to a W×H image."""
        _check_size(width, height)
        h, v = self.horizontal_aperture_mm, self.vertical_aperture_mm
        image_aspect = width / height
        if image_aspect > h / v:
            return v * image_aspect, v
        return h, h / image_aspect

    def fov_deg(self, width: int, height: int) -> tuple[float, float]:
        """(horizontal, vertical) full field of view in degrees for a W×H image."""
        h, v = self.conformed_aperture_mm(width, height)
        return (math.degrees(2 * math.atan(h / (2 * self.focal_length_mm))),
                math.degrees(2 * math.atan(v / (2 * self.focal_length_mm))))

    def intrinsics(self, width: int, height: int) -> np.ndarray:
        """(3, 3) float64 OpenCV intrinsic matrix K in pixels for a W×H image (square pixels)."""
        h, _ = self.conformed_aperture_mm(width, height)
        f_px = self.focal_length_mm * width / h
        return np.array([[f_px, 0.0, width / 2.0], [0.0, f_px, height / 2.0], [0.0, 0.0, 1.0]])

    # --- pose --------------------------------------------------------------------------------------

    @property
    def origin(self) -> np.ndarray:
        """(3,) float64 camera centre, world metres."""
        return self.camera_to_world[:3, 3].copy()

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Unit (right, up, forward) vectors in world space; forward is the local -Z axis."""
        r = self.camera_to_world[:3, :3]
        right, up, back = (r[:, i] / np.linalg.norm(r[:, i]) for i in range(3))
        return right, up, -back

    def world_to_camera_opencv(self) -> np.ndarray:
        """(4, 4) float64 extrinsic matrix [R|t] mapping world points to OpenCV camera coordinates."""
        right, up, forward = self.axes()
        rot = np.stack([right, -up, forward])  # rows: x right, y down, z forward
        out = np.eye(4)
        out[:3, :3] = rot
        out[:3, 3] = -rot @ self.origin
        return out

    def pixel_center_rays(self, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """Rays through every pixel centre, row-major from the top-left pixel.

        Returns ``origins`` (H*W, 3) float64 and unit ``directions`` (H*W, 3) float64, world space.
        Computed from the lens values alone, independently of any renderer. With ``distortion``, each pixel
        centre's distorted normalised coordinates are inverted (:meth:`BrownConrady.undistort`) first.
        """
        px, py = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
        return self.pixel_rays(px.ravel(), py.ravel(), width, height)

    def pixel_rays(self, px: np.ndarray, py: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """Rays through image points ``px``, ``py`` (n,) (pixel units from the top-left corner, so pixel centres
        are at +0.5) of a W×H image: ``origins`` and unit ``directions`` (n, 3) float64, world space. With
        ``distortion``, the points' distorted normalised coordinates are inverted first."""
        k = self.intrinsics(width, height)
        gx = (np.asarray(px, np.float64) - k[0, 2]) / k[0, 0]
        gy = (np.asarray(py, np.float64) - k[1, 2]) / k[1, 1]
        if self.distortion is not None:
            gx, gy = self.distortion.undistort(gx, gy, where=f"camera {self.path}")
        right, up, forward = self.axes()
        gx, gy = (v.ravel() for v in np.broadcast_arrays(gx, gy))
        d = np.empty((len(gx), 3))
        for axis in range(3):   # column by column (numpy is slow along a row of 3), the same values as row-wise
            d[:, axis] = gx * right[axis] - gy * up[axis] + forward[axis]
        d /= np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])[:, None]
        return np.broadcast_to(self.origin, d.shape).copy(), d


    def project(self, points: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates (n, 2) float64 (pixel centres at +0.5, distortion applied) and OpenCV depth
        ``z`` (n,) float64 metres of world ``points`` (n, 3); points with z <= 0 are behind the camera and
        get NaN coordinates."""
        ext = self.world_to_camera_opencv()
        pc = np.asarray(points, np.float64) @ ext[:3, :3].T + ext[:3, 3]
        z = pc[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            x, y = np.where(z > 0, pc[:, 0] / z, np.nan), np.where(z > 0, pc[:, 1] / z, np.nan)
        if self.distortion is not None:
            x, y = self.distortion.distort(x, y)
        k = self.intrinsics(width, height)
        return np.column_stack([k[0, 0] * x + k[0, 2], k[1, 1] * y + k[1, 2]]), z

    def check_distortion(self, width: int, height: int) -> None:
        """Refuse a distortion that cannot be inverted over a W×H image (its pixel centres and corners)."""
        if self.distortion is None:
            return
        k = self.intrinsics(width, height)
        half_w, half_h = width / 2.0 / k[0, 0], height / 2.0 / k[1, 1]
        self.distortion.check_field(half_w, half_h, where=f"camera {self.path}")


def _check_size(width: int, height: int) -> None:
    if not (isinstance(width, int) and isinstance(height, int) and width > 0 and height > 0):
        raise InputError(f"image size should be positive integers, but was {width}x{height}")


@dataclass(frozen=True)
class CameraSpec:
    """One camera to author: placed at ``eye`` looking at ``target`` (world metres, Z up) with a physical
    lens (mm); ``name`` becomes the prim name under ``/World/Cameras``."""

    name: str
    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    focal_length_mm: float
    horizontal_aperture_mm: float
    vertical_aperture_mm: float
    doc: str
    clip_near_m: float = 0.05
    clip_far_m: float = 1000.0
    #: The kind of rig it stands for (a name of :data:`synthua_usd.composition.rigs.RIG_TYPES`), or None.
    rig_type: str | None = None
