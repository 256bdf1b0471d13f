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

Two things keep it cheap without changing a mask. Each instance is one Mitsuba mesh (the triangle soup of its
gprims, :meth:`SceneSnapshot.world_triangles`): the masks only ask which instance a hit belongs to, and a
triangle's hit distance does not depend on the mesh it is in. And each scene traces only the pixels whose
centre can see one of its instances (:func:`candidate_pixels`: the instances' world boxes projected by the
pinhole camera, widened by ``MARGIN_PX``; every pixel for a camera with lens distortion); the rays of the
other pixels cannot meet any of the scene's triangles, and every ray's hits are its own.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Iterable

import numpy as np

from synthua_usd.backends.mitsuba.render import pixel_centre_rays
from synthua_usd.backends.mitsuba.translate import _mesh, sensor_dict, sensor_to_world
from synthua_usd.core.errors import InputError
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.scene import SceneSnapshot

log = logging.getLogger(__name__)

#: Hits per ray after which tracing stops (see the module docstring for what the pixel then keeps).
MAX_LAYERS = 1024
#: The step past a hit, metres per metre of the hit's largest coordinate (2^-18: 16 float32 ulps).
STEP_PER_M = 2.0 ** -18
#: World boxes closer than this (metres) touch; well above the step past a hit (about a millimetre at the
#: few hundred metres of a district).
TOUCH_M = 0.05
#: Pixels added on each side of an instance's projected box before its pixels are traced: the label pass's rays
#: come from Mitsuba's float32 sensor, the projection from the plain-data camera in float64 (they agree to well
#: under a pixel, see tests/backends/mitsuba/test_labels_embree.py).
MARGIN_PX = 2


@dataclass(eq=False)
class AmodalScene:
    """Mitsuba scenes of the meshes of ``instance_ids`` in ``snapshot`` (one mesh per instance) and a perspective
    sensor.

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
    #: (snapshot, its :func:`_boxes` of ``instance_ids``): the last boxes computed, asked for again by
    #: :meth:`holds` and :meth:`trace`.
    _boxes_cache: tuple = field(default=(None, None), repr=False)

    @classmethod
    def build(cls, mi, snapshot: SceneSnapshot, camera: PinholeCamera, config: RenderConfig,
              instance_ids: Iterable[int]) -> "AmodalScene":
        """Load the meshes of ``instance_ids`` (ids of ``snapshot.instances``; an unknown id raises
        :class:`InputError`), split into scenes of instances apart (:func:`apart_sets`); the first scene
        has a sensor for ``camera`` at ``config``'s size."""
        ids = checked_ids(snapshot, instance_ids)
        indices = _mesh_indices(snapshot, ids)
        boxes = _boxes(snapshot, ids)
        apart = apart_sets(snapshot, ids, boxes)
        meshes_of = _meshes_of(snapshot, indices)
        bsdf = mi.load_dict({"type": "diffuse"})  # never shaded: one BSDF for every mesh
        scenes = []
        for k, members in enumerate(apart or (frozenset(),)):
            scene = {"type": "scene"}
            if k == 0:
                scene["sensor"] = sensor_dict(mi, camera, config, spp=1)
            for inst in sorted(members):
                points, triangles, _ = snapshot.world_triangles([snapshot.meshes[i] for i in meshes_of[inst]])
                scene[instance_shape_id(inst)] = _mesh(mi, instance_shape_id(inst), points, triangles, bsdf)
            # optimize=False keeps one shape per instance: Mitsuba would merge them all.
            scenes.append(mi.load_dict(scene, optimize=False))
        return cls(mi, ids, snapshot, indices, apart, tuple(scenes), tuple(mi.traverse(s) for s in scenes),
                   _boxes_cache=(snapshot, boxes))

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
        boxes = self._boxes(snapshot)
        return not any(_touching([boxes[i] for i in members if i in boxes]).any() for members in self.apart)

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
        for inst, indices in _meshes_of(snapshot, self.mesh_indices).items():
            if all(self.snapshot.meshes[i].points is snapshot.meshes[i].points for i in indices):
                continue
            points = np.concatenate([snapshot.meshes[i].points for i in indices])
            k = scene_of[inst]
            params, name = self.params[k], f"{instance_shape_id(inst)}.vertex_positions"
            params[name] = type(params[name])(np.ascontiguousarray(points, np.float32).ravel())
            changed.add(k)
            moved += sum(self.snapshot.meshes[i].points is not snapshot.meshes[i].points for i in indices)
        for k in changed:
            self.params[k].update()
        self.snapshot = snapshot
        return moved

    def _boxes(self, snapshot: SceneSnapshot) -> dict[int, np.ndarray]:
        """:func:`_boxes` of the scene's instances in ``snapshot``, kept for the last snapshot asked."""
        if self._boxes_cache[0] is not snapshot:
            self._boxes_cache = (snapshot, _boxes(snapshot, self.instance_ids))
        return self._boxes_cache[1]

    def trace(self, camera: PinholeCamera, width: int, height: int) -> dict[int, np.ndarray]:
        """Every requested instance id → (k,) int64 sorted flat pixel indices (``y * width + x``) whose
        pixel-centre ray meets one of its meshes at any depth; empty for an instance never met. The sensor
        must be at ``camera`` (:meth:`build` or :meth:`update`)."""
        mi = self.mi
        order = np.array(sorted(self.instance_ids), np.int64)
        slot_of = {int(v): k for k, v in enumerate(order)}
        boxes = self._boxes(self.snapshot)
        rays = pixel_centre_rays(mi, self.scenes[0], camera, width, height)
        scalar = mi.variant().startswith("scalar")
        if scalar:
            rays = list(rays)
        else:  # computed once for every scene's gather, not once per scene
            import drjit as dr

            dr.eval(rays)
        pixels, slots, capped, layers = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)], 0, 0
        for members, scene in zip(self.apart, self.scenes):
            shape_slot = {instance_shape_id(inst): slot_of[inst] for inst in members}
            candidates = candidate_pixels(camera, [boxes[i] for i in sorted(members) if i in boxes], width, height)
            if scalar:
                found = _all_hits_scalar(mi, scene, rays, shape_slot, candidates)
            else:
                found = _all_hits_jit(mi, scene, rays, shape_slot, candidates)
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


def instance_shape_id(instance_id: int) -> str:
    """The Mitsuba id of an instance's mesh in an amodal scene."""
    return f"instance_{instance_id:05d}"


def checked_ids(snapshot: SceneSnapshot, instance_ids: Iterable[int]) -> frozenset[int]:
    """``instance_ids`` as a frozenset of ints, each an id of ``snapshot.instances``."""
    ids = frozenset(int(i) for i in instance_ids)
    unknown = sorted(ids - {inst.id for inst in snapshot.instances})
    if unknown:
        raise InputError(f"amodal masks: instance id(s) {unknown[:10]} not in the snapshot at time code "
                         f"{snapshot.time_code}; expected ids of its {len(snapshot.instances)} instances")
    return ids


def apart_sets(snapshot: SceneSnapshot, ids: frozenset[int],
               boxes: dict[int, np.ndarray] | None = None) -> tuple[frozenset[int], ...]:
    """``ids`` split so that no two instances in one set have touching world boxes (within ``TOUCH_M``):
    greedy colouring of the touch graph, instances in ascending id order. Instances with surfaces on top of
    each other (a mural on a wall, two row houses sharing a wall, a rider on a seat) then never share a
    scene, where a ray stepping past one surface could step over the other. ``boxes``: :func:`_boxes` of
    ``ids``, when already computed."""
    boxes = _boxes(snapshot, ids) if boxes is None else boxes
    order = sorted(boxes)
    touch = _touching([boxes[i] for i in order])
    sets: list[list[int]] = []
    for k in range(len(order)):
        for members in sets:
            if not touch[k, members].any():
                members.append(k)
                break
        else:
            sets.append([k])
    return tuple(frozenset(order[k] for k in members) for members in sets)


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


def _touching(boxes: list[np.ndarray]) -> np.ndarray:
    """(n, n) bool: which of the ``boxes`` ((2, 3) each) touch (within ``TOUCH_M``); the diagonal is False."""
    if not boxes:
        return np.zeros((0, 0), bool)
    b = np.stack(boxes)
    lo, hi = b[:, 0], b[:, 1]
    touch = np.all((lo[:, None] <= hi[None] + TOUCH_M) & (lo[None] <= hi[:, None] + TOUCH_M), axis=2)
    np.fill_diagonal(touch, False)
    return touch


def _mesh_indices(snapshot: SceneSnapshot, ids: frozenset[int]) -> tuple[int, ...]:
    return tuple(i for i, m in enumerate(snapshot.meshes) if m.instance_id in ids)


def _meshes_of(snapshot: SceneSnapshot, indices: Iterable[int]) -> dict[int, list[int]]:
    """Instance id → the snapshot's mesh indices among ``indices`` that belong to it, ascending."""
    out: dict[int, list[int]] = {}
    for i in indices:
        out.setdefault(snapshot.meshes[i].instance_id, []).append(i)
    return out


#: The 12 edges of a box as pairs of corner numbers (bit k of a corner number picks max over min on axis k).
_BOX_EDGES = tuple((a, a | (1 << k)) for a in range(8) for k in range(3) if not a & (1 << k))


def candidate_pixels(camera: PinholeCamera, boxes: list[np.ndarray], width: int, height: int) -> np.ndarray | None:
    """(k,) int64 ascending flat pixel indices whose pixel-centre rays can meet something inside one of the
    world ``boxes`` ((2, 3) float64 each), or None for every pixel (a camera with lens distortion).

    A pinhole camera sees a box inside the convex hull of its projected corners, once the box is cut to the
    part at least half the near clipping distance in front of the camera (the rays start on the near plane, so
    nothing closer is hit): the pixels of that hull's bounding rectangle, ``MARGIN_PX`` wider on each side."""
    if camera.distortion is not None:
        return None
    mask = np.zeros((height, width), bool)
    ext = camera.world_to_camera_opencv()
    k = camera.intrinsics(width, height)
    near = 0.5 * camera.clip_near_m
    bits = (np.arange(8)[:, None] >> np.arange(3)) & 1
    for box in boxes:
        corners = np.where(bits, box[1], box[0]) @ ext[:3, :3].T + ext[:3, 3]  # camera space, z forward
        z = corners[:, 2]
        front = [corners[z >= near]]
        for a, b in _BOX_EDGES:
            if (z[a] - near) * (z[b] - near) < 0:  # the edge crosses the plane z = near
                front.append(corners[a] + (corners[b] - corners[a]) * ((near - z[a]) / (z[b] - z[a])))
        seen = np.vstack(front)
        if not len(seen):
            continue
        x = k[0, 0] * seen[:, 0] / seen[:, 2] + k[0, 2]  # pixel x, pixel centres at i + 0.5
        y = k[1, 1] * seen[:, 1] / seen[:, 2] + k[1, 2]
        x0, x1 = max(int(np.floor(x.min())) - MARGIN_PX, 0), min(int(np.ceil(x.max())) + MARGIN_PX, width)
        y0, y1 = max(int(np.floor(y.min())) - MARGIN_PX, 0), min(int(np.ceil(y.max())) + MARGIN_PX, height)
        if x0 < x1 and y0 < y1:
            mask[y0:y1, x0:x1] = True
    return np.flatnonzero(mask)


def _step_m(reach_m: np.ndarray) -> np.ndarray:
    """Metres to step past a hit whose largest coordinate is at most ``reach_m`` metres."""
    return STEP_PER_M * (1.0 + reach_m)


def _all_hits_jit(mi, scene, ray, shape_slot: dict[str, int], candidates: np.ndarray | None):
    """(pixels, slots, capped, layers): one (pixel, instance slot) pair per hit of the H*W rays of ``ray`` whose
    pixels are ``candidates`` (None: all), how many rays were stopped at MAX_LAYERS, and the most hits along one
    ray. Each layer traces only the rays that hit in the layer before."""
    import drjit as dr

    if candidates is not None:
        if not len(candidates):
            return np.zeros(0, np.int64), np.zeros(0, np.int64), 0, 0
        index = mi.UInt32(candidates.astype(np.uint32))
        ray = mi.Ray3f(dr.gather(mi.Point3f, ray.o, index), dr.gather(mi.Vector3f, ray.d, index),
                       dr.gather(mi.Float, ray.maxt, index), mi.Float(0.0), [])
    registry = np.asarray(dr.reinterpret_array(mi.UInt32, scene.shapes_dr()), np.int64)
    slot_by_registry = np.full(int(registry.max()) + 2, -1, np.int64)
    for reg, shape in zip(registry, scene.shapes()):
        slot_by_registry[reg] = shape_slot[shape.id()]
    origin = np.stack([np.asarray(ray.o[i], np.float64) for i in range(3)], axis=1)
    reach = np.max(np.abs(origin), axis=1)  # |hit|_inf <= reach + distance travelled (|d|_inf <= 1)
    d32 = np.stack([np.asarray(ray.d[i], np.float32) for i in range(3)], axis=1)
    direction = d32.astype(np.float64)
    maxt = np.asarray(ray.maxt, np.float64)
    pixel_of = np.arange(len(maxt), dtype=np.int64) if candidates is None else candidates.astype(np.int64)
    active = np.arange(len(maxt), dtype=np.int64)  # rays still traced
    travelled = np.zeros(len(maxt))  # metres from each first origin to the current one
    pixels, slots = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    for layer in range(MAX_LAYERS):
        pi = scene.ray_intersect_preliminary(ray, coherent=layer == 0)
        # One kernel for both outputs: read one at a time, each would trace the rays again.
        shape = dr.reinterpret_array(mi.UInt32, pi.shape)
        dr.eval(pi.t, shape)
        t = np.asarray(pi.t, np.float64)
        valid = t != np.inf  # PreliminaryIntersection.is_valid()
        if not valid.any():
            return pixel_of[np.concatenate(pixels)], np.concatenate(slots), 0, layer
        reg = np.asarray(shape, np.int64)[valid]
        slot = slot_by_registry[np.clip(reg, 0, len(slot_by_registry) - 1)]
        active, t = active[valid], t[valid]
        pixels.append(active[slot >= 0])
        slots.append(slot[slot >= 0])
        travelled[active] += t
        travelled[active] += _step_m(reach[active] + travelled[active])
        active = active[travelled[active] < maxt[active]]
        if not len(active):
            return pixel_of[np.concatenate(pixels)], np.concatenate(slots), 0, layer + 1
        o = origin[active] + direction[active] * travelled[active, None]
        ray = mi.Ray3f(mi.Point3f(*(mi.Float(np.ascontiguousarray(o[:, i], np.float32)) for i in range(3))),
                       mi.Vector3f(*(mi.Float(np.ascontiguousarray(d32[active, i])) for i in range(3))),
                       mi.Float((maxt[active] - travelled[active]).astype(np.float32)), mi.Float(0.0), [])
    return pixel_of[np.concatenate(pixels)], np.concatenate(slots), len(active), MAX_LAYERS


def _all_hits_scalar(mi, scene, rays, shape_slot: dict[str, int], candidates: np.ndarray | None):
    """As :func:`_all_hits_jit`, one scalar ray at a time (``rays`` a list of all H*W)."""
    pixels, slots, capped, most = [], [], 0, 0
    for pixel in range(len(rays)) if candidates is None else candidates.tolist():
        ray = rays[pixel]
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
