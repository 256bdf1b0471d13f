"""Amodal (unoccluded) masks: the pixels whose pixel-centre ray meets an instance at any depth.

The label pass keeps the first hit of each pixel-centre ray; an amodal mask needs every hit. An
:class:`AmodalScene` is a second Mitsuba scene (a few, see below) holding only the meshes of the instances
asked for (so nothing else can stand in front of them) and a sensor set up exactly as the label pass's, so
that its rays are the label pass's rays bit for bit (:func:`render.pixel_centre_rays`; a distorted camera's
rays come from the plain-data camera, as in the label pass). Each ray is traced, then started again just past its hit, until
it escapes or reaches the far clipping plane ("all hits along each pixel ray"); every (pixel, instance) pair
met on the way goes into the masks.

Continuing past a hit moves the ray's origin along its own, unchanged direction to the hit plus
``STEP_PER_M * (1 + |origin|_inf + distance)`` metres (a bound on 16 float32 ulps of the hit's largest
coordinate: enough that the surface just hit is not found again at t = 0, though a grazing ray may meet it
again, which only repeats a pair). The origin is accumulated in float64 from the first origin and rounded
to float32 each layer, so it drifts at most half an ulp off the original ray.

A surface of *another* instance closer than that step behind a hit could be stepped over, and real scenes
are full of them (a mural on a wall, a door in it, row houses sharing a wall: coplanar faces): so the
instances are split into several scenes, none holding two instances whose world boxes touch
(:func:`apart_sets`), and every ray is traced through each. What can still be stepped over is another
surface of the same instance, which does not change its mask.

A ray still hitting after ``MAX_LAYERS`` hits is stopped there: its pixel keeps the instances found so
far, and the number of such rays is logged as a warning and kept in :attr:`AmodalScene.capped_rays`.

Because the first hit in each scene is that of the label pass's ray against a subset of the label pass's
meshes, with no two touching instances together, every visible pixel of a requested instance
(``instance_ids == i`` of :meth:`RenderSession.render`) is in its amodal set.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Iterable

import numpy as np

from synthua_usd.backends.mitsuba.render import pixel_centre_rays
from synthua_usd.backends.mitsuba.translate import _mesh, sensor_dict, sensor_to_world, shape_id
from synthua_usd.cameras import PinholeCamera
from synthua_usd.errors import InputError
from synthua_usd.render_config import RenderConfig
from synthua_usd.scene import SceneSnapshot

log = logging.getLogger(__name__)

#: Hits per ray after which tracing stops (see the module docstring for what the pixel then keeps).
MAX_LAYERS = 1024
#: The step past a hit, metres per metre of the hit's largest coordinate (2^-18: 16 float32 ulps).
STEP_PER_M = 2.0 ** -18
#: World boxes closer than this (metres) touch; well above the step past a hit (about a millimetre at the
#: few hundred metres of a district).
TOUCH_M = 0.05


@dataclass(eq=False)
class AmodalScene:
    """A Mitsuba scene of the meshes of ``instance_ids`` in ``snapshot`` and a perspective sensor.

    ``mesh_indices`` (ascending) index the snapshot's meshes that belong to the instances; ``capped_rays`` is
    how many rays the last :meth:`trace` stopped at ``MAX_LAYERS`` and ``layers`` the most hits it traced along
    one ray."""

    mi: object = field(repr=False)
    instance_ids: frozenset[int]
    snapshot: SceneSnapshot = field(repr=False)
    mesh_indices: tuple[int, ...]
    #: Instance ids per scene: instances whose boxes touch are never in one scene.
    apart: tuple[frozenset[int], ...]
    scenes: tuple = field(repr=False)
    params: tuple = field(repr=False)
    capped_rays: int = 0
    layers: int = 0

    @classmethod
    def build(cls, mi, snapshot: SceneSnapshot, camera: PinholeCamera, config: RenderConfig,
              instance_ids: Iterable[int]) -> "AmodalScene":
        """Load the meshes of ``instance_ids`` (ids of ``snapshot.instances``; an unknown id raises
        :class:`InputError`), split into scenes of instances apart (:func:`apart_sets`); the first scene
        has a sensor for ``camera`` at ``config``'s size."""
        ids = checked_ids(snapshot, instance_ids)
        indices = _mesh_indices(snapshot, ids)
        apart = apart_sets(snapshot, ids)
        bsdf = mi.load_dict({"type": "diffuse"})  # never shaded: one BSDF for every mesh
        scenes = []
        for k, members in enumerate(apart or (frozenset(),)):
            scene = {"type": "scene"}
            if k == 0:
                scene["sensor"] = sensor_dict(mi, camera, config, spp=1)
            for i in indices:
                item = snapshot.meshes[i]
                if item.instance_id in members:
                    scene[shape_id(i)] = _mesh(mi, shape_id(i), item.points, item.triangles, bsdf)
            # optimize=False keeps one shape per gprim, as in the label pass's scene.
            scenes.append(mi.load_dict(scene, optimize=False))
        return cls(mi, ids, snapshot, indices, apart, tuple(scenes), tuple(mi.traverse(s) for s in scenes))

    def holds(self, snapshot: SceneSnapshot, instance_ids: Iterable[int]) -> bool:
        """Whether :meth:`update` can bring this scene to ``snapshot``: the same instances, their meshes the
        same gprims with the same triangles (only vertex positions may differ), and instances that share a
        scene still apart."""
        ids = frozenset(int(i) for i in instance_ids)
        if ids != self.instance_ids or snapshot is self.snapshot:
            return ids == self.instance_ids
        indices = _mesh_indices(snapshot, ids)
        if indices != self.mesh_indices:
            return False
        for i in indices:
            a, b = self.snapshot.meshes[i], snapshot.meshes[i]
            if a is not b and (a.prim_path != b.prim_path or a.points.shape != b.points.shape
                               or not (a.triangles is b.triangles or np.array_equal(a.triangles, b.triangles))):
                return False
        boxes = _boxes(snapshot, ids)
        return all(not _touch(boxes[a], boxes[b]) for members in self.apart for a in members for b in members if a < b)

    def update(self, snapshot: SceneSnapshot, camera: PinholeCamera, config: RenderConfig) -> int:
        """Point the sensor at ``camera`` and move the meshes that moved in ``snapshot`` (which :meth:`holds`);
        returns how many meshes moved."""
        first = self.params[0]
        first["sensor.to_world"] = sensor_to_world(self.mi, camera)
        first["sensor.x_fov"] = camera.fov_deg(config.width, config.height)[0]
        first["sensor.near_clip"] = camera.clip_near_m
        first["sensor.far_clip"] = camera.clip_far_m
        moved, changed = 0, {0}
        scene_of = {inst: k for k, members in enumerate(self.apart) for inst in members}
        for i in self.mesh_indices:
            old, new = self.snapshot.meshes[i], snapshot.meshes[i]
            if old is new or old.points is new.points:
                continue
            k = scene_of[new.instance_id]
            params, name = self.params[k], f"{shape_id(i)}.vertex_positions"
            params[name] = type(params[name])(np.ascontiguousarray(new.points, np.float32).ravel())
            changed.add(k)
            moved += 1
        for k in changed:
            self.params[k].update()
        self.snapshot = snapshot
        return moved

    def trace(self, camera: PinholeCamera, width: int, height: int) -> dict[int, np.ndarray]:
        """Every requested instance id → (k,) int64 sorted flat pixel indices (``y * width + x``) whose
        pixel-centre ray meets one of its meshes at any depth; empty for an instance never met. The sensor
        must be at ``camera`` (:meth:`build` or :meth:`update`)."""
        mi = self.mi
        instance_of = {shape_id(i): self.snapshot.meshes[i].instance_id for i in self.mesh_indices}
        order = np.array(sorted(self.instance_ids), np.int64)
        slot_of = {int(v): k for k, v in enumerate(order)}
        rays = pixel_centre_rays(mi, self.scenes[0], camera, width, height)
        scalar = mi.variant().startswith("scalar")
        if scalar:
            rays = list(rays)
        pixels, slots, capped, layers = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)], 0, 0
        for members, scene in zip(self.apart, self.scenes):
            if scalar:
                shape_slot = {key: slot_of[inst] for key, inst in instance_of.items() if inst in members}
                found = _all_hits_scalar(mi, scene, rays, shape_slot)
            else:
                found = _all_hits_jit(mi, scene, rays, instance_of, slot_of)
            pixels.append(found[0])
            slots.append(found[1])
            capped, layers = capped + found[2], max(layers, found[3])
        pixels, slots = np.concatenate(pixels), np.concatenate(slots)
        self.capped_rays, self.layers = capped, layers
        if capped:
            log.warning("amodal: %d of %d pixel rays still hit after %d layers; their pixels keep the instances "
                        "met so far", capped, width * height, MAX_LAYERS)
        n = width * height
        codes = np.sort(slots * n + pixels)  # by instance slot, then pixel (a sort: np.unique hashes, slower)
        codes = codes[np.concatenate([[True], codes[1:] != codes[:-1]])] if len(codes) else codes
        bounds = np.searchsorted(codes, np.arange(len(order) + 1) * n)
        return {int(inst): codes[bounds[k]:bounds[k + 1]] - k * n for k, inst in enumerate(order)}


def checked_ids(snapshot: SceneSnapshot, instance_ids: Iterable[int]) -> frozenset[int]:
    """``instance_ids`` as a frozenset of ints, each an id of ``snapshot.instances``."""
    ids = frozenset(int(i) for i in instance_ids)
    unknown = sorted(ids - {inst.id for inst in snapshot.instances})
    if unknown:
        raise InputError(f"amodal masks: instance id(s) {unknown[:10]} not in the snapshot at time code "
                         f"{snapshot.time_code}; expected ids of its {len(snapshot.instances)} instances")
    return ids


def apart_sets(snapshot: SceneSnapshot, ids: frozenset[int]) -> tuple[frozenset[int], ...]:
    """``ids`` split so that no two instances in one set have touching world boxes (within ``TOUCH_M``):
    greedy colouring of the touch graph, instances in ascending id order. Instances with surfaces on top of
    each other (a mural on a wall, two row houses sharing a wall, a rider on a seat) then never share a
    scene, where a ray stepping past one surface could step over the other."""
    boxes = _boxes(snapshot, ids)
    sets: list[set[int]] = []
    for inst in sorted(boxes):
        for members in sets:
            if not any(_touch(boxes[inst], boxes[other]) for other in members):
                members.add(inst)
                break
        else:
            sets.append({inst})
    return tuple(frozenset(m) for m in sets)


def _boxes(snapshot: SceneSnapshot, ids: frozenset[int]) -> dict[int, np.ndarray]:
    """Instance id → (2, 3) float64 world box (min, max) of its meshes' points; instances without meshes are
    left out."""
    boxes: dict[int, np.ndarray] = {}
    for m in snapshot.meshes:
        if m.instance_id in ids and len(m.points):
            box = np.stack([m.points.min(axis=0), m.points.max(axis=0)])
            old = boxes.get(m.instance_id)
            boxes[m.instance_id] = box if old is None else np.stack([np.minimum(old[0], box[0]),
                                                                     np.maximum(old[1], box[1])])
    return boxes


def _touch(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.all(a[0] <= b[1] + TOUCH_M) and np.all(b[0] <= a[1] + TOUCH_M))


def _mesh_indices(snapshot: SceneSnapshot, ids: frozenset[int]) -> tuple[int, ...]:
    return tuple(i for i, m in enumerate(snapshot.meshes) if m.instance_id in ids)


def _step_m(reach_m: np.ndarray) -> np.ndarray:
    """Metres to step past a hit whose largest coordinate is at most ``reach_m`` metres."""
    return STEP_PER_M * (1.0 + reach_m)


def _all_hits_jit(mi, scene, ray, instance_of: dict[str, int], slot_of: dict[int, int]):
    """(pixels, slots, capped, layers): one (pixel, instance slot) pair per hit of the H*W rays of ``ray``, how
    many rays were stopped at MAX_LAYERS, and the most hits along one ray. Each layer traces only the rays that
    hit in the layer before."""
    import drjit as dr

    registry = np.asarray(dr.reinterpret_array(mi.UInt32, scene.shapes_dr()), np.int64)
    slot_by_registry = np.full(int(registry.max()) + 2, -1, np.int64)
    for reg, shape in zip(registry, scene.shapes()):
        slot_by_registry[reg] = slot_of[instance_of[shape.id()]]
    origin = np.stack([np.asarray(ray.o[i], np.float64) for i in range(3)], axis=1)
    reach = np.max(np.abs(origin), axis=1)  # |hit|_inf <= reach + distance travelled (|d|_inf <= 1)
    d32 = np.stack([np.asarray(ray.d[i], np.float32) for i in range(3)], axis=1)
    direction = d32.astype(np.float64)
    maxt = np.asarray(ray.maxt, np.float64)
    active = np.arange(len(maxt), dtype=np.int64)  # pixels of the rays still traced
    travelled = np.zeros(len(maxt))  # metres from each first origin to the current one
    pixels, slots = [], []
    for layer in range(MAX_LAYERS):
        pi = scene.ray_intersect_preliminary(ray, coherent=layer == 0)
        valid = np.asarray(pi.is_valid(), bool)
        if not valid.any():
            return np.concatenate(pixels or [[]]).astype(np.int64), np.concatenate(slots or [[]]).astype(np.int64), 0, layer
        reg = np.asarray(dr.reinterpret_array(mi.UInt32, pi.shape), np.int64)[valid]
        slot = slot_by_registry[np.clip(reg, 0, len(slot_by_registry) - 1)]
        active, t = active[valid], np.asarray(pi.t, np.float64)[valid]
        pixels.append(active[slot >= 0])
        slots.append(slot[slot >= 0])
        travelled[active] += t
        travelled[active] += _step_m(reach[active] + travelled[active])
        active = active[travelled[active] < maxt[active]]
        if not len(active):
            return np.concatenate(pixels), np.concatenate(slots), 0, layer + 1
        o = origin[active] + direction[active] * travelled[active, None]
        ray = mi.Ray3f(mi.Point3f(*(mi.Float(np.ascontiguousarray(o[:, i], np.float32)) for i in range(3))),
                       mi.Vector3f(*(mi.Float(np.ascontiguousarray(d32[active, i])) for i in range(3))),
                       mi.Float((maxt[active] - travelled[active]).astype(np.float32)), mi.Float(0.0), [])
    return np.concatenate(pixels), np.concatenate(slots), len(active), MAX_LAYERS


def _all_hits_scalar(mi, scene, rays, shape_slot: dict[str, int]):
    """As :func:`_all_hits_jit`, one scalar ray at a time."""
    pixels, slots, capped, most = [], [], 0, 0
    for pixel, ray in enumerate(rays):
        origin = np.array([ray.o[0], ray.o[1], ray.o[2]], np.float64)
        direction = mi.Vector3f(ray.d)
        d = np.array([ray.d[0], ray.d[1], ray.d[2]], np.float64)
        maxt, travelled, reach = float(ray.maxt), 0.0, float(np.max(np.abs(origin)))
        for layer in range(MAX_LAYERS):
            pi = scene.ray_intersect_preliminary(ray)
            if not pi.is_valid():
                break
            most = max(most, layer + 1)
            pixels.append(pixel)
            slots.append(shape_slot[pi.shape.id()])
            travelled += float(pi.t)
            travelled += _step_m(reach + travelled)
            if travelled >= maxt:
                break
            o = origin + d * travelled
            ray = mi.Ray3f(mi.Point3f(*map(float, o)), direction, maxt - travelled, 0.0, [])
        else:
            capped += 1
    return np.array(pixels, np.int64), np.array(slots, np.int64), capped, most
