"""Rendering a translated scene: path-traced RGB, and exact labels from one ray through each pixel centre.

Two passes, never one: an AOV rendered with a sampler jitters inside the pixel and averages ids over
samples, so edges would not match any pixel-centre reference. Labels come from rays we generate at
((x + 0.5) / W, (y + 0.5) / H) and ``scene.ray_intersect_preliminary``; every label pixel is an exact id.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from synthua_usd.backends.exposure import Exposure
from synthua_usd.backends.mitsuba.translate import pass_sample_counts
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.conditions import Condition
from synthua_usd.model.render_config import RenderConfig, sampler_seed
from synthua_usd.model.scene import SceneSnapshot



@dataclass(frozen=True, eq=False)
class LabelHits:
    """First hits of the pixel-centre rays. Arrays are (H, W).

    ``mesh_index`` int32 indexes the snapshot's meshes (-1 where the ray escapes); ``distance_m`` float32 is
    the distance from the camera centre to the hit along the ray, metres (0 on a miss); ``z_m`` float32 is
    depth along the camera's optical axis.
    """

    mesh_index: np.ndarray = field(repr=False)
    distance_m: np.ndarray = field(repr=False)
    z_m: np.ndarray = field(repr=False)


@dataclass(frozen=True, eq=False)
class RenderedFrame:
    """All buffers of one frame. ``rgb`` (H, W, 3) float32 scene-linear Rec.709; ``class_ids`` (H, W) uint8;
    ``instance_ids`` (H, W) uint16; depths as in :class:`LabelHits`. ``exposure`` is chosen from ``rgb``
    (None without RGB); ``condition`` is the condition rendered (None: the stage's UsdLux lights); ``denoised``
    says how ``rgb`` was denoised (the denoiser and the firefly pixels scaled down; None: not denoised)."""

    rgb: np.ndarray = field(repr=False)
    class_ids: np.ndarray = field(repr=False)
    instance_ids: np.ndarray = field(repr=False)
    hits: LabelHits = field(repr=False)
    variant: str
    seconds: dict
    exposure: Exposure | None = None
    condition: Condition | None = None
    denoised: dict | None = None


@dataclass(frozen=True, eq=False)
class RgbPass:
    """The RGB pass of one frame, all (H, W, 3) float32: ``rgb`` scene-linear Rec.709 radiance; with guides (see
    :func:`render_rgb`), ``albedo`` (diffuse reflectance of the first hit, 0 on a miss) and ``normal`` (world-space
    shading normal of the first hit, 0 on a miss), averaged over the same film positions as ``rgb``; None
    without."""

    rgb: np.ndarray = field(repr=False)
    albedo: np.ndarray | None = field(default=None, repr=False)
    normal: np.ndarray | None = field(default=None, repr=False)


def render_rgb(mi, scene, config: RenderConfig, show_progress: bool = False, sensor=None,
               seed: int | None = None, guides=None) -> RgbPass:
    """The RGB pass: the mean of passes of at most 16 samples each (so that a progress bar can move; counts by
    :func:`synthua_usd.backends.mitsuba.translate.pass_sample_counts`); ``sensor`` (e.g. a
    :func:`synthua_usd.backends.mitsuba.lens.distorted_sensor`) replaces the scene's own; ``seed`` replaces
    ``config.seed``. ``guides`` (a loaded :func:`synthua_usd.backends.mitsuba.translate.guide_integrator_dict`)
    adds albedo and normal at the colour's film positions: a guides-only integrator is rendered after the colour
    with the same seed and sample count (JIT variants); one wrapped around the path tracer renders both."""
    seed = config.seed if seed is None else seed
    counts = pass_sample_counts(config.spp)
    total = np.zeros((config.height, config.width, 3 if guides is None else 9), np.float64)
    with tqdm(total=config.spp, unit="spp", desc="rgb", disable=not show_progress, leave=False) as bar:
        for k, spp in enumerate(counts):
            pass_seed = sampler_seed(seed, k)
            which = 0 if sensor is None else sensor  # the scene's own sensor, or the given one
            aux = None if guides is None else np.asarray(mi.render(scene, spp=spp, seed=pass_seed, sensor=which,
                                                                   integrator=guides), np.float64)
            if aux is not None and aux.shape[2] >= 9:  # wrapped around the path tracer: R, G, B, then the guides
                total += aux[..., :9] * spp
            else:
                image = mi.render(scene, spp=spp, seed=pass_seed, sensor=which)
                total[..., :3] += np.asarray(image, np.float64)[..., :3] * spp
                if aux is not None:  # albedo (3), then shading normal (3)
                    total[..., 3:] += aux[..., :6] * spp
            bar.update(spp)
    mean = (total / config.spp).astype(np.float32)
    if guides is None:
        return RgbPass(mean)
    return RgbPass(*(np.ascontiguousarray(mean[..., i:i + 3]) for i in (0, 3, 6)))


def trace_pixel_centres(mi, scene, shape_ids: tuple[str, ...], camera: PinholeCamera, width: int, height: int,
                        camera_rays: bool = False) -> LabelHits:
    """One primary ray through each pixel centre; first hit per pixel. ``shape_ids`` are the Mitsuba ids of the
    snapshot's meshes, in order.

    An ideal pinhole asks the scene's sensor for its rays at ((x + 0.5) / W, (y + 0.5) / H). A camera with lens
    distortion (or any camera, with ``camera_rays``: then the scene's sensor need not point at it) gets rays
    computed from the plain-data camera (:meth:`PinholeCamera.pixel_center_rays`, the Brown–Conrady model
    inverted per pixel centre), started on the near clipping plane as Mitsuba's perspective sensor starts its
    own, and traced the same way."""
    keys = {key: i for i, key in enumerate(shape_ids)}
    rays = pixel_centre_rays(mi, scene, camera, width, height, camera_rays)
    if mi.variant().startswith("scalar"):
        mesh_index, distance, z = _trace_scalar(mi, scene, keys, rays, width * height, camera)
    else:
        mesh_index, distance, z = _trace_jit(mi, scene, keys, rays, camera)
    shape = (height, width)
    return LabelHits(mesh_index.reshape(shape), distance.reshape(shape), z.reshape(shape))


def intersect_pixel_centres(mi, scene, camera: PinholeCamera, width: int, height: int) -> int:
    """The raw primary-ray bound of the label pass: the same pixel-centre rays (:func:`pixel_centre_rays`) and
    ``scene.ray_intersect_preliminary``, evaluated (JIT variants: one kernel, waited for), with nothing read
    back, mapped or converted. Returns the number of rays traced (W * H). For benchmarks: the label pass can
    only approach this time."""
    rays = pixel_centre_rays(mi, scene, camera, width, height)
    if mi.variant().startswith("scalar"):
        count = 0
        for ray in rays:
            scene.ray_intersect_preliminary(ray)
            count += 1
        return count
    import drjit as dr

    pi = scene.ray_intersect_preliminary(rays, coherent=True)
    dr.eval(pi.t, pi.shape, pi.prim_index)
    dr.sync_thread()
    return dr.width(pi.t)


def pixel_centre_rays(mi, scene, camera: PinholeCamera, width: int, height: int, camera_rays: bool = False):
    """The rays :func:`trace_pixel_centres` traces, row-major from the top-left pixel: from the scene's sensor for
    an ideal pinhole, else (or with ``camera_rays``) from the plain-data camera. One ``mi.Ray3f`` of H*W lanes on
    JIT variants; an iterator of H*W scalar rays on scalar ones."""
    if camera.distortion is None and not camera_rays:
        sensor = scene.sensors()[0]
        if mi.variant().startswith("scalar"):
            return _sensor_rays_scalar(mi, sensor, width, height)
        return _sensor_rays_jit(mi, sensor, width, height)
    return _camera_rays(mi, camera, width, height, mi.variant().startswith("scalar"))


def _sensor_rays_jit(mi, sensor, width, height):
    import drjit as dr

    idx = dr.arange(mi.UInt32, width * height)
    x = mi.Float(idx % width)
    y = mi.Float(idx // width)
    pos = mi.Point2f((x + 0.5) / width, (y + 0.5) / height)
    ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    return ray


def _sensor_rays_scalar(mi, sensor, width, height):
    aperture = mi.Point2f(0.5, 0.5)
    for k in range(width * height):
        y, x = divmod(k, width)
        ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f((x + 0.5) / width, (y + 0.5) / height), aperture)
        yield ray


def _camera_rays(mi, camera: PinholeCamera, width: int, height: int, scalar: bool):
    """Rays through the pixel centres of ``camera`` (distortion included) from its near clipping plane to its
    far one, like Mitsuba's perspective sensor: origin ``c + d near / (d . forward)``, maxt ``(far - near) /
    (d . forward)``."""
    centre, dirs = camera.pixel_center_rays(width, height)
    _, _, forward = camera.axes()
    cos = dirs @ forward
    origins = centre + dirs * (camera.clip_near_m / cos)[:, None]
    maxt = (camera.clip_far_m - camera.clip_near_m) / cos
    if scalar:
        return (mi.Ray3f(mi.Point3f(*map(float, o)), mi.Vector3f(*map(float, d)), float(t), 0.0, [])
                for o, d, t in zip(origins, dirs, maxt))
    o = mi.Point3f(*(mi.Float(np.ascontiguousarray(origins[:, i], np.float32)) for i in range(3)))
    d = mi.Vector3f(*(mi.Float(np.ascontiguousarray(dirs[:, i], np.float32)) for i in range(3)))
    return mi.Ray3f(o, d, mi.Float(maxt.astype(np.float32)), mi.Float(0.0), [])


def _trace_jit(mi, scene, keys, ray, camera: PinholeCamera):
    """(mesh index (n,) int32, distance (n,) float32, z (n,) float32), computed in one Dr.Jit kernel with the
    intersection: only these three arrays are read back (reading the rays back and finishing in NumPy cost
    3-4x the ray cast at 1280x960)."""
    import drjit as dr

    pi = scene.ray_intersect_preliminary(ray, coherent=True)
    # pi.shape holds registry ids, not indices: map them through shapes_dr() beside shapes(), by a table
    # indexed by registry id (-1: not one of the snapshot's meshes).
    registry = dr.reinterpret_array(mi.UInt32, pi.shape)
    valid = pi.is_valid()
    if keys:
        shape_registry = np.asarray(dr.reinterpret_array(mi.UInt32, scene.shapes_dr()), np.int64)
        table = np.full(int(shape_registry.max()) + 1, -1, np.int32)
        table[shape_registry] = [keys[s.id()] for s in scene.shapes()]
        valid &= registry < len(table)
        index = dr.select(valid, dr.gather(mi.Int32, mi.Int32(table), registry, valid), -1)
    else:  # nothing to hit
        index = dr.full(mi.Int32, -1, dr.width(pi.t))
    # Mitsuba starts each camera ray on the near clipping plane, so hit distances count from there: add the
    # way from the camera centre to the ray's origin.
    _, _, forward = camera.axes()
    centre = mi.Point3f(*(float(x) for x in camera.origin))
    hit = index >= 0
    distance = dr.select(hit, pi.t + dr.norm(ray.o - centre), 0.0)
    z = distance * dr.dot(ray.d, mi.Vector3f(*(float(x) for x in forward)))
    dr.eval(index, distance, z)
    return np.asarray(index, np.int32), np.asarray(distance, np.float32), np.asarray(z, np.float32)


def _trace_scalar(mi, scene, keys, rays, n, camera: PinholeCamera):
    mesh_index = np.full(n, -1, np.int32)
    distance = np.zeros(n, np.float64)
    dirs = np.zeros((n, 3), np.float64)
    origins = np.zeros((n, 3), np.float64)
    for k, ray in enumerate(rays):
        dirs[k] = (ray.d[0], ray.d[1], ray.d[2])
        origins[k] = (ray.o[0], ray.o[1], ray.o[2])
        pi = scene.ray_intersect_preliminary(ray)
        if pi.is_valid():
            mesh_index[k] = keys[pi.shape.id()]
            distance[k] = pi.t
    # distances count from the near clipping plane, where Mitsuba starts camera rays: add the way to it
    distance = np.where(mesh_index >= 0, distance + np.linalg.norm(origins - camera.origin, axis=1), 0.0)
    _, _, forward = camera.axes()
    return mesh_index, distance.astype(np.float32), (distance * (dirs @ forward)).astype(np.float32)


def label_maps(hits: LabelHits, snapshot: SceneSnapshot) -> tuple[np.ndarray, np.ndarray]:
    """(class_ids uint8, instance_ids uint16), both (H, W), from mesh hits; 0 where nothing is hit."""
    # The 0 of "nothing hit" is the tables' last entry, which index -1 takes: no (H, W) temporary of index + 1
    # (a fresh 10 MB array at 1280x960 costs more in page faults than the lookup itself).
    class_of = np.array([m.class_id for m in snapshot.meshes] + [0], np.uint8)
    inst_of = np.array([m.instance_id for m in snapshot.meshes] + [0], np.uint16)
    return np.take(class_of, hits.mesh_index), np.take(inst_of, hits.mesh_index)
