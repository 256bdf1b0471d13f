"""Rendering a translated scene: path-traced RGB, and exact labels from one ray through each pixel centre.

Two passes, never one: an AOV rendered with a sampler jitters inside the pixel and averages ids over
samples, so edges would not match any pixel-centre reference. Labels come from rays we generate at
((x + 0.5) / W, (y + 0.5) / H) and ``scene.ray_intersect_preliminary``; every label pixel is an exact id.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from synthua_usd.backends.exposure import Exposure
from synthua_usd.cameras import PinholeCamera
from synthua_usd.conditions import Condition
from synthua_usd.render_config import RenderConfig
from synthua_usd.scene import SceneSnapshot

#: RGB is rendered in passes of at most this many samples per pixel so a progress bar can move.
SPP_PER_PASS = 16


@dataclass(frozen=True, eq=False)
class LabelHits:
    """First hits of the pixel-centre rays. Arrays are (H, W).

    ``mesh_index`` int64 indexes the snapshot's meshes (-1 where the ray escapes); ``distance_m`` float32 is
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
    (None without RGB); ``condition`` is the condition rendered (None: the stage's UsdLux lights)."""

    rgb: np.ndarray = field(repr=False)
    class_ids: np.ndarray = field(repr=False)
    instance_ids: np.ndarray = field(repr=False)
    hits: LabelHits = field(repr=False)
    variant: str
    seconds: dict
    exposure: Exposure | None = None
    condition: Condition | None = None


def render_rgb(mi, scene, config: RenderConfig, show_progress: bool = False) -> np.ndarray:
    """(H, W, 3) float32 linear RGB: the mean of passes of at most SPP_PER_PASS samples each."""
    passes = math.ceil(config.spp / SPP_PER_PASS)
    total = np.zeros((config.height, config.width, 3), np.float64)
    done = 0
    with tqdm(total=config.spp, unit="spp", desc="rgb", disable=not show_progress, leave=False) as bar:
        for k in range(passes):
            spp = min(SPP_PER_PASS, config.spp - done)
            image = mi.render(scene, spp=spp, seed=config.seed * 100_003 + k)
            total += np.asarray(image, np.float64)[..., :3] * spp
            done += spp
            bar.update(spp)
    return (total / config.spp).astype(np.float32)


def trace_pixel_centres(mi, scene, shape_ids: tuple[str, ...], camera: PinholeCamera, width: int, height: int) -> LabelHits:
    """One primary ray through each pixel centre of the scene's sensor; first hit per pixel. ``shape_ids``
    are the Mitsuba ids of the snapshot's meshes, in order."""
    keys = {key: i for i, key in enumerate(shape_ids)}
    sensor = scene.sensors()[0]
    if mi.variant().startswith("scalar"):
        mesh_index, distance, origins, dirs = _trace_scalar(mi, scene, sensor, keys, width, height)
    else:
        mesh_index, distance, origins, dirs = _trace_jit(mi, scene, sensor, keys, width, height)
    # Mitsuba starts each camera ray on the near clipping plane, so hit distances count from there: add the
    # way from the camera centre to the ray's origin.
    distance = np.where(mesh_index >= 0, distance + np.linalg.norm(origins - camera.origin, axis=1), 0.0)
    _, _, forward = camera.axes()
    z = (distance * (dirs @ forward)).astype(np.float32)
    shape = (height, width)
    return LabelHits(mesh_index.reshape(shape), distance.astype(np.float32).reshape(shape), z.reshape(shape))


def _trace_jit(mi, scene, sensor, keys, width, height):
    import drjit as dr

    idx = dr.arange(mi.UInt32, width * height)
    x = mi.Float(idx % width)
    y = mi.Float(idx // width)
    pos = mi.Point2f((x + 0.5) / width, (y + 0.5) / height)
    ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    pi = scene.ray_intersect_preliminary(ray, coherent=True)
    valid = np.asarray(pi.is_valid(), bool)
    registry = np.asarray(dr.reinterpret_array(mi.UInt32, pi.shape), np.int64)
    distance = np.where(valid, np.asarray(pi.t, np.float64), 0.0)
    dirs = np.stack([np.asarray(ray.d[i], np.float64) for i in range(3)], axis=1)
    origins = np.stack([np.asarray(ray.o[i], np.float64) for i in range(3)], axis=1)
    if not keys:  # nothing to hit
        return np.full(len(valid), -1, np.int64), np.zeros(len(valid)), origins, dirs
    # pi.shape holds registry ids, not indices: map them through shapes_dr() beside shapes().
    shape_registry = np.asarray(dr.reinterpret_array(mi.UInt32, scene.shapes_dr()), np.int64)
    shape_mesh = np.array([keys[s.id()] for s in scene.shapes()], np.int64)
    order = np.argsort(shape_registry)
    pos_in = np.searchsorted(shape_registry[order], registry)
    pos_in = np.clip(pos_in, 0, len(order) - 1)
    found = valid & (shape_registry[order][pos_in] == registry)
    mesh_index = np.where(found, shape_mesh[order][pos_in], -1)
    return mesh_index, np.where(found, distance, 0.0), origins, dirs


def _trace_scalar(mi, scene, sensor, keys, width, height):
    n = width * height
    mesh_index = np.full(n, -1, np.int64)
    distance = np.zeros(n, np.float64)
    dirs = np.zeros((n, 3), np.float64)
    origins = np.zeros((n, 3), np.float64)
    aperture = mi.Point2f(0.5, 0.5)
    for k in range(n):
        y, x = divmod(k, width)
        ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f((x + 0.5) / width, (y + 0.5) / height), aperture)
        dirs[k] = (ray.d[0], ray.d[1], ray.d[2])
        origins[k] = (ray.o[0], ray.o[1], ray.o[2])
        pi = scene.ray_intersect_preliminary(ray)
        if pi.is_valid():
            mesh_index[k] = keys[pi.shape.id()]
            distance[k] = pi.t
    return mesh_index, distance, origins, dirs


def label_maps(hits: LabelHits, snapshot: SceneSnapshot) -> tuple[np.ndarray, np.ndarray]:
    """(class_ids uint8, instance_ids uint16), both (H, W), from mesh hits; 0 where nothing is hit."""
    class_of = np.array([0] + [m.class_id for m in snapshot.meshes], np.uint8)
    inst_of = np.array([0] + [m.instance_id for m in snapshot.meshes], np.uint16)
    return class_of[hits.mesh_index + 1], inst_of[hits.mesh_index + 1]
