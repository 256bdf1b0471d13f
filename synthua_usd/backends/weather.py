"""Fog and rain in image space, on a rendered frame and its exact per-pixel depth. No renderer here.

Fog: Koschmieder's atmospheric scattering model on the distance d from the camera centre to the surface
seen through each pixel centre (the label pass's ``distance_m``; rays that escape have d = ∞):

    I = I₀ · e^(−βd) + A · (1 − e^(−βd)),   β = 3.912 / V  (V: meteorological visibility)

Chosen over a homogeneous medium with Mitsuba's volumetric path tracer because it is exact to the stated
model, noise-free and costs milliseconds, while a volume makes every frame several times slower and noisy
at dataset sample counts, needs a bounded medium (a box that the label rays would hit) and a scene
reload for every change of fog. What it leaves out: light scattered by the fog around lamps (no halos),
and a pixel straddling an edge takes the fog of the surface at its centre.

The fog also dims the sun on the way down: :func:`fog_lighting` attenuates the direct beam through a
layer ``fog_top_m`` deep and hands what it scatters to the diffuse sky, by the two-stream (Eddington)
approximation for a non-absorbing layer of optical depth τ = β·H with droplet asymmetry g = 0.85 (Liou, *An
Introduction to Atmospheric Radiation*, 2002, ch. 6): direct T = e^(−τ/μ₀), total T = 1 − (1−g)τ /
(4/3 + (1−g)τ). The airlight A is the radiance of a white Lambertian surface under that light, E/π.

Rain: streaks of the drops within 1–10 m of the camera (Garg & Nayar 2006, "Photorealistic rendering of
rain streaks"): drop sizes ≥ 1 mm from the Marshall–Palmer distribution N(D) = 8000·e^(−ΛD) m⁻³mm⁻¹,
Λ = 4.1·R^(−0.21) mm⁻¹ for rain rate R mm/h; terminal speed v = 9.65 − 10.3·e^(−0.6D) m/s (Atlas et al.
1973); each drop moves during a 1/50 s shutter and is drawn as a segment whose opacity per pixel is the
share of the pixel and of the exposure it covers; its radiance is the mean of the frame and of the sky
light A (a drop refracts light from a ~165° cone around it). Drops behind the surface a pixel sees are
hidden. Streaks are drawn from a seeded generator: the same seed, camera and time code give the same rain.

The sun's disk: the path tracer lights the scene with the sun as a directional (delta) light, which no
camera ray can hit, so :func:`sun_disk` draws the disk where it is seen: a uniform disk of angular radius
``SUN_HALF_ANGLE_DEG`` whose radiance is the sun's normal irradiance over its solid angle, on the pixels
whose centre ray escapes, weighted by the share of each pixel's area (8×8 points) that looks into it. Fog
then covers it like any other escaped pixel. Left out: limb darkening, and the sun seen in mirror-like
reflections.
"""

from __future__ import annotations

import math

import numpy as np

from synthua_usd.model.cameras import PinholeCamera

FOG_ASYMMETRY_G = 0.85
SHUTTER_S = 1.0 / 50.0
RAIN_RANGE_M = (1.0, 10.0)
RAIN_MIN_DROP_MM = 1.0
MARSHALL_PALMER_N0 = 8000.0  # m⁻³ mm⁻¹
#: Half the sun's apparent diameter (0.5358°, as Mitsuba's ``sunsky`` has it).
SUN_HALF_ANGLE_DEG = 0.5358 / 2.0
SUN_DISK_SUBSAMPLES = 8


def fog_lighting(condition, e_sun: np.ndarray, e_sky: np.ndarray) -> tuple[float, float, np.ndarray]:
    """(sun scale, sky scale, airlight A (3,) linear RGB radiance) for ``condition`` given the horizontal
    irradiance of its clear sun and clear sky, ``e_sun`` and ``e_sky`` (3,) renderer units."""
    beta = condition.fog_extinction_per_m
    if beta == 0.0 or condition.fog_top_m == 0.0 or not condition.sun_up:
        sun_scale, sky_scale = 1.0, 1.0
    else:
        tau = beta * condition.fog_top_m
        mu0 = math.sin(math.radians(condition.sun_elevation_deg))
        direct = math.exp(-tau / mu0)
        total = 1.0 - (1.0 - FOG_ASYMMETRY_G) * tau / (4.0 / 3.0 + (1.0 - FOG_ASYMMETRY_G) * tau)
        sun_y, sky_y = float(np.mean(e_sun)), float(np.mean(e_sky))
        sun_scale = direct
        sky_scale = total + max(total - direct, 0.0) * (sun_y / sky_y if sky_y > 0 else 0.0)
    airlight = (sun_scale * np.asarray(e_sun, float) + sky_scale * np.asarray(e_sky, float)) / math.pi
    return sun_scale, sky_scale, airlight


def sun_disk(rgb: np.ndarray, escaped: np.ndarray, camera: PinholeCamera, direction: np.ndarray,
             normal_irradiance: np.ndarray, half_angle_deg: float = SUN_HALF_ANGLE_DEG) -> np.ndarray:
    """``rgb`` (H, W, 3) float32 linear with the sun's disk added where ``escaped`` (H, W) bool: the sun in
    unit world ``direction`` (towards the sun), ``normal_irradiance`` (3,) linear RGB on a surface facing it
    (renderer units). Returns ``rgb`` itself when the disk is nowhere in the image."""
    h, w = escaped.shape
    d = np.asarray(direction, np.float64) / np.linalg.norm(direction)
    cos_max = math.cos(math.radians(half_angle_deg))
    centre, z = camera.project(camera.origin[None, :] + d[None, :], w, h)
    if not z[0] > 0 or not np.all(np.isfinite(centre)):
        return rgb
    # The disk's radius in pixels near the image axis, doubled (and 2 px more) to cover oblique views and lenses.
    k = camera.intrinsics(w, h)
    reach = 2.0 * max(k[0, 0], k[1, 1]) * math.tan(math.radians(half_angle_deg)) + 2.0
    x0, x1 = max(int(centre[0, 0] - reach), 0), min(int(centre[0, 0] + reach) + 1, w)
    y0, y1 = max(int(centre[0, 1] - reach), 0), min(int(centre[0, 1] + reach) + 1, h)
    if x0 >= x1 or y0 >= y1:
        return rgb
    n = SUN_DISK_SUBSAMPLES
    offsets = (np.arange(n) + 0.5) / n
    px = (np.arange(x0, x1)[:, None] + offsets[None, :]).ravel()
    py = (np.arange(y0, y1)[:, None] + offsets[None, :]).ravel()
    gx, gy = np.meshgrid(px, py)
    _, rays = camera.pixel_rays(gx.ravel(), gy.ravel(), w, h)
    inside = (rays @ d >= cos_max).reshape(y1 - y0, n, x1 - x0, n)
    share = inside.mean(axis=(1, 3))
    share = np.where(escaped[y0:y1, x0:x1], share, 0.0)
    if not share.any():
        return rgb
    solid_angle = 2.0 * math.pi * (1.0 - cos_max)
    radiance = np.asarray(normal_irradiance, np.float64) / solid_angle
    out = rgb.copy()
    out[y0:y1, x0:x1] += (share[..., None] * radiance).astype(np.float32)
    return out


def apply_fog(rgb: np.ndarray, distance_m: np.ndarray, hit: np.ndarray, beta_per_m: float,
              airlight: np.ndarray) -> np.ndarray:
    """Koschmieder fog. ``rgb`` (H, W, 3) float32 linear; ``distance_m`` (H, W) from the camera centre;
    ``hit`` (H, W) bool (False: the ray escaped, d = ∞). β = 0 returns ``rgb`` unchanged."""
    if beta_per_m == 0.0:
        return rgb
    transmittance = np.where(hit, np.exp(-beta_per_m * np.asarray(distance_m, np.float64)), 0.0)[..., None]
    out = rgb * transmittance + np.asarray(airlight, np.float64) * (1.0 - transmittance)
    return out.astype(np.float32)


def drop_density_per_m3(rate_mm_per_h: float, min_diameter_mm: float = RAIN_MIN_DROP_MM) -> tuple[float, float]:
    """(drops of diameter ≥ ``min_diameter_mm`` per m³, Λ in 1/mm) of Marshall–Palmer rain at
    ``rate_mm_per_h``."""
    lam = 4.1 * rate_mm_per_h ** -0.21
    return MARSHALL_PALMER_N0 / lam * math.exp(-lam * min_diameter_mm), lam


def terminal_speed_mps(diameter_mm: np.ndarray) -> np.ndarray:
    """Atlas et al. (1973) fall speed of raindrops, m/s, for diameters in mm."""
    return np.maximum(9.65 - 10.3 * np.exp(-0.6 * np.asarray(diameter_mm)), 0.0)


def rain_streaks(rgb: np.ndarray, z_depth_m: np.ndarray, camera: PinholeCamera, rate_mm_per_h: float,
                 sky_radiance: np.ndarray, rng: np.random.Generator, up_axis: str = "Z") -> np.ndarray:
    """``rgb`` (H, W, 3) float32 with rain streaks over it. ``z_depth_m`` (H, W) is depth along the optical
    axis (0 where nothing is hit); ``sky_radiance`` (3,) the light a drop also refracts from above."""
    if rate_mm_per_h <= 0.0:
        return rgb
    h, w = rgb.shape[:2]
    k = camera.intrinsics(w, h)
    f_px = k[0, 0]
    z0, z1 = RAIN_RANGE_M
    density, lam = drop_density_per_m3(rate_mm_per_h)
    # The frustum between z0 and z1: cross-section (w/f)·(h/f)·z², volume ∫ of it.
    volume = (z1 ** 3 - z0 ** 3) / 3.0 * (w / f_px) * (h / f_px)
    count = int(rng.poisson(density * volume))
    if count == 0:
        return rgb
    # Camera-space (OpenCV: x right, y down, z forward) positions uniform in the frustum volume.
    z = np.cbrt(z0 ** 3 + rng.random(count) * (z1 ** 3 - z0 ** 3))
    u = rng.random(count) * w
    v = rng.random(count) * h
    diameter_mm = RAIN_MIN_DROP_MM + rng.exponential(1.0 / lam, count)
    speed = terminal_speed_mps(diameter_mm)
    down_world = np.array([0.0, -1.0, 0.0]) if up_axis == "Y" else np.array([0.0, 0.0, -1.0])
    down_cam = camera.world_to_camera_opencv()[:3, :3] @ down_world
    p0 = np.stack([(u - k[0, 2]) * z / f_px, (v - k[1, 2]) * z / f_px, z], axis=1)
    p1 = p0 + (speed * SHUTTER_S)[:, None] * down_cam
    z_end = np.maximum(p1[:, 2], 0.05)
    u1, v1 = k[0, 0] * p1[:, 0] / z_end + k[0, 2], k[1, 1] * p1[:, 1] / z_end + k[1, 2]
    length = np.hypot(u1 - u, v1 - v)
    width = np.minimum(diameter_mm * 1e-3 * f_px / z, 1.0)
    alpha = width / np.maximum(length, 1.0)
    # Splat points at one-pixel spacing along each streak, bilinearly.
    steps = np.ceil(length).astype(np.int64) + 1
    owner = np.repeat(np.arange(count), steps)
    t = (np.arange(len(owner)) - np.repeat(np.cumsum(steps) - steps, steps)) / np.maximum(steps[owner] - 1, 1)
    su = u[owner] + t * (u1 - u)[owner] - 0.5
    sv = v[owner] + t * (v1 - v)[owner] - 0.5
    sz = z[owner] + t * (p1[:, 2] - z)[owner]
    total = np.zeros(h * w, np.float64)
    iu, iv = np.floor(su).astype(np.int64), np.floor(sv).astype(np.int64)
    fu, fv = su - iu, sv - iv
    depth = np.where(z_depth_m > 0, z_depth_m, np.inf).ravel()
    for du, dv, weight in ((0, 0, (1 - fu) * (1 - fv)), (1, 0, fu * (1 - fv)), (0, 1, (1 - fu) * fv), (1, 1, fu * fv)):
        x, y = iu + du, iv + dv
        inside = (x >= 0) & (x < w) & (y >= 0) & (y < h)
        index = y[inside] * w + x[inside]
        visible = sz[inside] < depth[index]
        np.add.at(total, index[visible], (alpha[owner] * weight)[inside][visible])
    cover = np.minimum(total, 1.0).reshape(h, w, 1)
    drop = 0.5 * (rgb.reshape(-1, 3).mean(axis=0) + np.asarray(sky_radiance, np.float64))
    return (rgb * (1.0 - cover) + drop * cover).astype(np.float32)
