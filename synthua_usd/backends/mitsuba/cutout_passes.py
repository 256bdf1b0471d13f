"""The passes of a cut-out that a :class:`~synthua_usd.backends.mitsuba.session.RenderSession`'s loaded scene
gives beyond its labels: the group's colour with its coverage (RGBA), and the shadow it casts on a ground plane.

The scene is the studio's (:mod:`synthua_usd.usd.studio`): the group under a condition's environment and sun, no
ground. :func:`render_rgba` path-traces it with the directly seen environment hidden, so a pixel's alpha is the
share of its samples that hit the group and its colour is premultiplied by it (no sky or ground mixed into the
group's edges); the environment still lights the group, the lower half of its map as a ground plain.

:func:`ground_shadow` measures what a horizontal ground plane at height 0 under the group would lose: for every
pixel whose centre ray meets the plane, one ray towards the sun (a delta light: its shadow is sharp) and
:data:`SKY_DIRECTIONS` rays over the upper hemisphere (cosine-weighted, the same for every pixel) test whether the
group blocks them; the shadow factor is ``(E_sun * V_sun + sum_j L_j V_j * E_sky / sum_j L_j) / (E_sun + E_sky)``
with the sun's irradiance on the plane, the sky's irradiance and radiance ``L_j`` in each direction (luminance), as
the condition's environment gives them. What it leaves out: light the group reflects onto the ground, and the sky
below a direction's horizon.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd.backends.mitsuba.translate import sensor_dict
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.photometry import luminance
from synthua_usd.model.render_config import RenderConfig

#: Directions over the upper hemisphere the sky's occlusion is measured in (each pixel turns them by its own angle).
SKY_DIRECTIONS = 64
#: Sky directions traced in one call (rays: ground pixels x this).
SKY_BATCH = 16
#: The shadow layer is smoothed by a Gaussian of this many pixels (the sky's sampling noise; a sharp sun edge
#: keeps about a pixel of softness, as a real sun's penumbra a few metres away).
SMOOTHING_PX = 0.8
#: The group is denoised in its box widened by this many pixels, not the whole frame (where nothing else is):
#: OIDN's cost follows the pixels it sees; a wider view moves a few of the group's pixels by one or two 8-bit levels.
DENOISE_MARGIN_PX = 64


def render_rgba(session, camera: PinholeCamera, spp: int, seed: int, denoise: bool = True) -> np.ndarray:
    """(H, W, 4) float32 linear premultiplied RGBA of the session's loaded scene seen by ``camera`` (the session's
    size, max depth and variant; ``spp`` samples, box filter), the environment seen directly hidden; RGB denoised
    (Intel OIDN with albedo and normal guides of the same samples) when ``denoise``."""
    mi = session.mi
    config = RenderConfig(width=session.config.width, height=session.config.height, spp=spp,
                          max_depth=session.config.max_depth, denoise=denoise, variant=session.variant)
    sensor_spec = sensor_dict(mi, camera, config, spp)
    sensor_spec["film"] = {**sensor_spec["film"], "pixel_format": "rgba"}
    sensor = mi.load_dict(sensor_spec)
    integrator = mi.load_dict({"type": "path", "max_depth": config.max_depth, "hide_emitters": True})
    scene = session.mitsuba_scene
    rgba = np.asarray(mi.render(scene, sensor=sensor, integrator=integrator, spp=spp, seed=seed), np.float32)
    rgba = np.ascontiguousarray(rgba[..., :4])
    if denoise:
        from synthua_usd.backends.mitsuba.translate import guide_integrator_dict

        guides = np.asarray(mi.render(scene, sensor=sensor, integrator=mi.load_dict(guide_integrator_dict()),
                                      spp=spp, seed=seed), np.float32)
        rgb, _ = session.denoiser().denoise_pass(rgba[..., :3], np.ascontiguousarray(guides[..., :3]),
                                                 np.ascontiguousarray(guides[..., 3:6]), margin=DENOISE_MARGIN_PX)
        # the denoiser may leave a faint glow where nothing was hit: premultiplied colour is 0 there
        rgba[..., :3] = np.where(rgba[..., 3:4] > 0, np.maximum(rgb, 0.0), 0.0)
    return rgba


def _hemisphere(count: int) -> np.ndarray:
    """(count, 3) cosine-weighted unit directions over the +Z hemisphere, stratified (a Fibonacci spiral of the
    unit disc lifted onto the hemisphere)."""
    k = np.arange(count) + 0.5
    r = np.sqrt(k / count)
    phi = k * np.pi * (3.0 - np.sqrt(5.0))
    x, y = r * np.cos(phi), r * np.sin(phi)
    return np.stack([x, y, np.sqrt(np.maximum(0.0, 1.0 - x * x - y * y))], axis=1)


@dataclass(frozen=True)
class GroundLight:
    """The light on a horizontal ground plane under the session's condition: the sun's unit direction (towards it;
    None at night or below the horizon) and its irradiance on the plane ``sun_lux``, the sky's directions (n, 3)
    (cosine-weighted over the upper hemisphere), their radiance luminance (n,) and the sky's irradiance on the plane
    ``sky_lux`` (renderer units)."""

    sun: np.ndarray | None
    sun_lux: float
    sky: np.ndarray
    sky_radiance: np.ndarray
    sky_lux: float

    def grey_card(self, albedo: float = 0.18) -> np.ndarray:
        """(1, 1, 3) linear RGB of a grey card of ``albedo`` lying on the plane: what a photographer meters."""
        return np.full((1, 1, 3), albedo * (self.sun_lux + self.sky_lux) / np.pi, np.float32)


def ground_light(session) -> GroundLight:
    """The :class:`GroundLight` of the session's loaded scene and condition."""
    import drjit as dr

    mi = session.mi
    lighting = session.lighting
    sun, sun_lux = None, 0.0
    if lighting is not None and lighting.sun_direction is not None and lighting.sun_direction[2] > 0:
        sun = np.asarray(lighting.sun_direction, float)
        sun_lux = float(luminance(lighting.sun_irradiance)) * float(sun[2])
    sky = _hemisphere(SKY_DIRECTIONS)
    radiance = np.ones(len(sky))
    environment = session.mitsuba_scene.environment()
    if environment is not None:
        si = dr.zeros(mi.SurfaceInteraction3f, len(sky))
        si.wi = mi.Vector3f(*(-sky.T).astype(np.float32))
        values = np.asarray(environment.eval(si), np.float64)
        radiance = np.maximum(luminance(values.reshape(len(sky), 3)), 0.0)
    # a cosine-weighted estimate of the sky's irradiance: pi x the mean radiance of the directions
    return GroundLight(sun, sun_lux, sky, radiance, float(np.pi * radiance.mean()))


def _meets_box(origins: np.ndarray, direction: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """Whether each ray ``origins`` (n, 3) + t ``direction`` (t >= 0) meets the box ``bounds`` (2, 3: lowest and
    highest corner) widened by a millimetre (the slab test)."""
    lo, hi = bounds[0] - 1e-3, bounds[1] + 1e-3
    d = np.where(np.abs(direction) < 1e-12, 1e-12, direction)
    near, far = np.zeros(len(origins)), np.full(len(origins), np.inf)
    for axis in range(3):       # axis by axis on columns: a reduction over a row of 3 is slow in numpy
        t0, t1 = (lo[axis] - origins[:, axis]) / d[axis], (hi[axis] - origins[:, axis]) / d[axis]
        np.maximum(near, np.minimum(t0, t1), out=near)
        np.minimum(far, np.maximum(t0, t1), out=far)
    return far >= near


def _window(camera: PinholeCamera, frame_w: int, frame_h: int, pad: int, light: GroundLight,
            near: tuple[float, float, float], bounds: np.ndarray) -> tuple[int, int, int, int]:
    """The pixels (x0, y0, x1, y1) of the grid of the frame and ``pad`` around it outside which the ground keeps
    all its light: the image of the box ``bounds``'s shadow on the ground (its corners moved along the sun) and of
    the square about ``near`` (the sky's occlusion); the whole grid where one of those points is behind the camera
    or the sun is at the horizon."""
    w, h = frame_w + 2 * pad, frame_h + 2 * pad
    cx, cy, r = near
    points = [np.array([[cx + sx * r, cy + sy * r, 0.0] for sx in (-1, 1) for sy in (-1, 1)])]
    if light.sun is not None:
        if light.sun[2] <= 1e-6:
            return 0, 0, w, h
        corners = np.array([[x, y, z] for x in bounds[:, 0] for y in bounds[:, 1] for z in bounds[:, 2]])
        points.append(corners - corners[:, 2:3] / light.sun[2] * light.sun)
    uv, depth = camera.project(np.vstack(points), frame_w, frame_h)
    if not (depth > 1e-9).all():
        return 0, 0, w, h
    # two pixels wider (a pixel whose centre lies just outside is still shadowed in part), from a multiple of 4 (the
    # corner of the sky's block of a pixel inside is inside)
    x0, y0 = ((int(np.floor(v)) + pad - 2) // 4 * 4 for v in uv.min(axis=0))
    x1, y1 = (int(np.ceil(v)) + pad + 2 for v in uv.max(axis=0))
    x0, y0, x1, y1 = min(max(x0, 0), w), min(max(y0, 0), h), min(max(x1, 0), w), min(max(y1, 0), h)
    return x0, y0, max(x0, x1), max(y0, y1)


def ground_shadow(session, camera: PinholeCamera, light: GroundLight, near: tuple[float, float, float],
                  pad: int = 0, bounds: np.ndarray | None = None) -> np.ndarray:
    """(H + 2 pad, W + 2 pad) float32 shadow factor of the ground plane z = 0 seen by ``camera`` over the frame
    and ``pad`` pixels (a multiple of 4) around it, the ground a long shadow reaches beyond the frame (1:
    unshadowed; pixels whose ray misses the plane are 1), under ``light`` (:func:`ground_light`): see the module's
    docstring. The sky's
    occlusion is measured within ``near`` (x, y, radius: metres) of the group, where it is not negligible; the
    sun's shadow everywhere. Where ``bounds`` (2, 3), a box holding every mesh of the scene, is given, only the
    pixels where the box's shadow or the sky's occlusion can fall are traced (:func:`_window`), and of them only
    the rays towards the sun that meet the box: the others keep all their light, as a trace of them would find."""
    if pad % 4:
        raise ValueError(f"pad {pad}: expected a multiple of 4 (the sky's blocks beyond the frame)")
    mi = session.mi
    scene = session.mitsuba_scene
    frame_w, frame_h = session.config.width, session.config.height
    w, h = frame_w + 2 * pad, frame_h + 2 * pad
    x0, y0, x1, y1 = (0, 0, w, h) if bounds is None else _window(camera, frame_w, frame_h, pad, light, near, bounds)
    gx, gy = np.meshgrid(np.arange(x0, x1), np.arange(y0, y1))
    origins, directions = camera.pixel_rays(gx.ravel() - pad + 0.5, gy.ravel() - pad + 0.5, frame_w, frame_h)
    factor = np.ones(w * h, np.float32)
    down = directions[:, 2] < -1e-6
    t = np.where(down, -origins[:, 2] / np.where(down, directions[:, 2], -1.0), -1.0)
    on_ground = np.flatnonzero(down & (t > 0))
    total = light.sun_lux + light.sky_lux
    if not len(on_ground) or total <= 0:
        return factor.reshape(h, w)
    points = origins[on_ground] + directions[on_ground] * t[on_ground, None]
    hit = (gy.ravel() * w + gx.ravel())[on_ground]         # the pixels' indices in the whole grid

    def visible(origins: list, directions: list) -> np.ndarray:
        """Whether rays from ``origins`` (3 columns of n, float64) along ``directions`` (3 of n) meet nothing;
        column by column, each one contiguous float32 (what Dr.Jit takes without a copy)."""
        rays = mi.Ray3f(mi.Point3f(*((o + d * 1e-4).astype(np.float32) for o, d in zip(origins, directions))),
                        mi.Vector3f(*(np.asarray(d, np.float32) for d in directions)))
        return ~np.asarray(scene.ray_test(rays), bool)

    lit = np.zeros(len(points))
    if light.sun is not None:
        # a ray that misses the box holding every mesh sees the sun: only the others are traced
        sun_seen = np.ones(len(points), bool)
        near_box = np.flatnonzero(_meets_box(points, light.sun, bounds)) if bounds is not None else slice(None)
        ends = points[near_box]
        sun_seen[near_box] = visible([ends[:, k] for k in range(3)],
                                     [np.full(len(ends), light.sun[k]) for k in range(3)])
        lit += light.sun_lux * sun_seen
    # the sky's directions turned about the vertical by an angle of each pixel's own (a fixed hash of its index):
    # the same turn everywhere would draw the group's occlusion as streaks; here it is fine noise, then smoothed
    turn = (hit * 0.6180339887498949) % 1.0 * 2 * np.pi
    cos, sin = np.cos(turn)[:, None], np.sin(turn)[:, None]
    sky = light.sky
    weights = light.sky_radiance / max(light.sky_radiance.sum(), 1e-12)
    close = np.hypot(points[:, 0] - near[0], points[:, 1] - near[1]) <= near[2]
    lit[~close] += light.sky_lux
    # the sky's occlusion varies slowly: traced at one pixel of each block of 2 x 2 (beyond the frame, of 4 x 4:
    # the ground nearest the camera is many pixels there), each pixel taking its block's value
    rows, cols = np.divmod(hit, w)
    inside = (rows >= pad) & (rows < pad + frame_h) & (cols >= pad) & (cols < pad + frame_w)
    size = np.where(inside, 2, 4)
    corner = (rows // size * size) * w + cols // size * size        # a 4 x 4 block's corner is a 2 x 2 block's
    traced = close & (hit == corner)
    inner, cos, sin = points[traced], cos[traced], sin[traced]
    sky_seen = np.zeros(len(points))
    for start in range(0, len(sky), SKY_BATCH):
        part = sky[start:start + SKY_BATCH]
        dirs = [(cos * part[:, 0] - sin * part[:, 1]).ravel(), (sin * part[:, 0] + cos * part[:, 1]).ravel(),
                np.tile(part[:, 2], len(inner))]           # pixel-major: each pixel's len(part) directions
        seen = visible([np.repeat(inner[:, k], len(part)) for k in range(3)], dirs).reshape(len(inner), len(part))
        sky_seen[traced] += (seen * weights[start:start + SKY_BATCH]).sum(axis=1)
    # a pixel of a block whose traced corner missed the plane (or lay too far) keeps the whole sky
    share = np.ones(w * h)
    share[hit[traced]] = sky_seen[traced]
    lit[close] += light.sky_lux * share[corner[close]]
    factor[hit] = np.clip(lit / total, 0.0, 1.0)
    from scipy.ndimage import gaussian_filter

    return gaussian_filter(factor.reshape(h, w), SMOOTHING_PX, mode="nearest").astype(np.float32)
