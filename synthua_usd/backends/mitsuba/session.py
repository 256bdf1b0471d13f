"""A render session: one Mitsuba scene loaded once, rendered from any camera at any time code.

The first :meth:`RenderSession.render` translates and loads the snapshot. Later calls compare the new
snapshot with the loaded one and change only what differs, through Mitsuba's ``traverse()`` parameters:
the sensor (pose, field of view, clipping) and the vertex positions of meshes that moved (a new
:class:`MeshItem` object where the reader re-read a time-varying gprim). Mitsuba then rebuilds its
acceleration structure; the scene, its BSDFs and static meshes stay. A snapshot with other meshes (a
gprim appeared or disappeared, a mesh changed its topology) or other lights is loaded afresh, and
``reloads`` counts it.

Conditions (:mod:`synthua_usd.model.conditions`): a session loaded with a condition swaps to another in place
(the environment map of sky and ground, the sun's direction and irradiance, lamps and emitter sampling
weights through ``traverse()``, day or night; fog, rain and exposure are image-space steps) unless they differ
in wetness or snow cover (those live in the BSDFs and mesh attributes the scene was built with): then the
session reloads, and counts it in ``reloads``. Labels come
from the same geometry under every condition.

This is what a dataset worker holds: one session, one scene load, every frame of its share.
"""

from __future__ import annotations

import time
import zlib
from typing import Iterable

import numpy as np

from synthua_usd.backends import weather
from synthua_usd.backends.denoise import Denoiser
from synthua_usd.backends.exposure import choose_exposure
from synthua_usd.backends.mitsuba import variants, weather_scene
from synthua_usd.backends.mitsuba.amodal import AmodalScene, checked_ids
from synthua_usd.backends.mitsuba.lens import distorted_sensor
from synthua_usd.backends.mitsuba.render import RenderedFrame, label_maps, render_rgb, trace_pixel_centres
from synthua_usd.backends.mitsuba.translate import Translation, guide_integrator_dict, sensor_to_world, translate
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.conditions import Condition
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.scene import SceneSnapshot


class RenderSession:
    """Renders RGB and exact labels of snapshots of one scene at a fixed image size and sample count.

    ``variant`` is picked (or checked) once, when the session is made.
    """

    def __init__(self, config: RenderConfig, count_compiles: bool = False) -> None:
        self.config = config
        #: Whether :meth:`render` reports the seconds Dr.Jit spent compiling kernels (``compile``, from its kernel
        #: history, which this turns on for the process): for benchmarks and profiles.
        self.count_compiles = count_compiles
        self.mi = variants.activate(config.variant)
        self.variant = self.mi.variant()
        if count_compiles and not self.variant.startswith("scalar"):
            import drjit as dr

            dr.set_flag(dr.JitFlag.KernelHistory, True)
        self.loads = 0
        self.reloads = 0
        #: Seconds the last load spent translating the snapshot (the rest of ``load``: Mitsuba building the scene).
        self.translate_seconds = 0.0
        self._scene = None
        self._params = None
        self._translation: Translation | None = None
        self._snapshot: SceneSnapshot | None = None
        self._condition: Condition | None = None
        self._lighting: weather_scene.Lighting | None = None
        self._meter: weather_scene.LightMeter | None = None
        self._amodal: AmodalScene | None = None
        # With denoise on: the aov integrator that adds the denoiser's guides and the OIDN device, made with the
        # first RGB frame (a session that only traces labels needs neither).
        self._guides = None
        self._denoiser: Denoiser | None = None

    @property
    def mitsuba_scene(self):
        """The loaded Mitsuba scene (None before the first render), e.g. to time raw ray casts against it."""
        return self._scene

    @property
    def lighting(self) -> weather_scene.Lighting | None:
        """What the loaded scene's condition set (the sun's direction and irradiance, ...); None without one."""
        return self._lighting if self._condition is not None else None

    def denoiser(self) -> Denoiser:
        """The session's denoiser (made once)."""
        if self._denoiser is None:
            self._denoiser = Denoiser()
        return self._denoiser

    def _load(self, snapshot: SceneSnapshot, camera: PinholeCamera, condition: Condition | None = None) -> None:
        t0 = time.perf_counter()
        self._translation = translate(self.mi, snapshot, camera, self.config, condition)
        self.translate_seconds = time.perf_counter() - t0
        # optimize=False: Mitsuba would otherwise merge meshes and lose the identity labels depend on.
        self._scene = self._translation.load(self.mi)
        self._params = self.mi.traverse(self._scene)
        self._snapshot = snapshot
        self._condition = None
        if condition is not None:
            self._set_condition(condition)
            self._params.update()
        self.loads += 1

    def _set_condition(self, condition: Condition) -> None:
        """Sky, lamps and sampling weights of the loaded scene to ``condition`` (parameters, no reload)."""
        if self._meter is None:
            self._meter = weather_scene.LightMeter(self.mi)
        self._lighting = weather_scene.apply_condition(self.mi, self._params, self._translation.shape_ids,
                                                       self._translation.lamps, condition, self._snapshot.up_axis,
                                                       self._meter)
        self._condition = condition

    def _same_layout(self, snapshot: SceneSnapshot, condition: Condition | None = None) -> bool:
        old = self._snapshot
        # the lights the scene was built with (with a condition, the environment's own sun and sky stand in for
        # it in viewers only: a view layer may turn them)
        # and the materials' values: BSDFs are built with the scene (a material recoloured means a reload)
        return (self._translation.condition_key == weather_scene.scene_key(condition)
                and len(old.meshes) == len(snapshot.meshes)
                and weather_scene.own_lights(old, condition) == weather_scene.own_lights(snapshot, condition)
                and (old.materials is snapshot.materials
                     or all(old.materials[k] == snapshot.materials.get(k) for k in {m.material_key for m in old.meshes}))
                # (the same meshes: every pair below is one object; label passes ask this for every view)
                and (old.meshes is snapshot.meshes
                     or all(a is b or (a.prim_path == b.prim_path and a.material_key == b.material_key
                                       and a.points.shape == b.points.shape
                                       and (a.normals is None) == (b.normals is None)
                                       and (a.triangles is b.triangles or np.array_equal(a.triangles, b.triangles)))
                            for a, b in zip(old.meshes, snapshot.meshes))))

    def _update(self, snapshot: SceneSnapshot, camera: PinholeCamera, condition: Condition | None = None) -> int:
        """Point the sensor at ``camera``, move what moved and switch to ``condition`` if it is another;
        returns how many meshes were updated."""
        mi, params = self.mi, self._params
        fov_x, _ = camera.fov_deg(self.config.width, self.config.height)
        params["sensor.to_world"] = sensor_to_world(mi, camera)
        params["sensor.x_fov"] = fov_x
        params["sensor.near_clip"] = camera.clip_near_m
        params["sensor.far_clip"] = camera.clip_far_m
        moved = 0
        for key, old, new in zip(self._translation.shape_ids, self._snapshot.meshes, snapshot.meshes):
            if old is new or old.points is new.points:
                continue
            name = f"{key}.vertex_positions"
            # The parameter's own array type: mi.Float is a plain float on scalar variants.
            params[name] = type(params[name])(np.ascontiguousarray(new.points, np.float32).ravel())
            if new.normals is not None:  # with the positions: alone they would make Mitsuba recompute its own
                normals = f"{key}.vertex_normals"
                params[normals] = type(params[normals])(np.ascontiguousarray(new.normals, np.float32).ravel())
            moved += 1
        self._snapshot = snapshot
        if condition is not None and condition != self._condition:
            self._set_condition(condition)
        params.update()
        return moved

    def quick_labels(self, snapshot: SceneSnapshot, camera: PinholeCamera) -> np.ndarray:
        """(H, W) uint16 instance ids of ``camera``'s pixel-centre rays computed from its lens values, without
        pointing the scene's sensor at it: the cheap pass for many throw-away views of one snapshot, such as
        scoring camera placements (a new snapshot is still loaded or updated first, and the session's
        condition is not kept: use a session of its own). Ids agree with :meth:`render`'s up to float32
        rounding of the ray directions; dataset labels come from :meth:`render`."""
        if self._scene is None or not self._same_layout(snapshot):
            self._load(snapshot, camera)
            self.reloads += self.loads > 1
        elif snapshot is not self._snapshot:
            self._update(snapshot, camera)
        hits = trace_pixel_centres(self.mi, self._scene, self._translation.shape_ids, camera, self.config.width,
                                   self.config.height, camera_rays=True)
        return label_maps(hits, snapshot)[1]

    def render(self, snapshot: SceneSnapshot, camera: PinholeCamera, rgb: bool = True,
               show_progress: bool = False, condition: Condition | None = None,
               seed: int | None = None) -> RenderedFrame:
        """RGB (unless ``rgb`` is False) and labels of ``snapshot`` seen by ``camera`` under ``condition``
        (None: the stage's UsdLux lights as they are, no weather); ``seed`` (default: the config's) seeds the
        sampler and the rain.

        ``seconds`` in the result holds ``load`` (first load or reload) or ``update``, then ``labels``,
        ``rgb``, ``denoise`` (with the config's ``denoise``: fireflies and OIDN, before any weather) and
        ``weather`` (fog, rain and exposure in image space)."""
        seconds = {}
        if self.count_compiles and not self.variant.startswith("scalar"):
            import drjit as dr

            dr.kernel_history()  # what came before this frame is not its
        t0 = time.perf_counter()
        if self._scene is None:
            self._load(snapshot, camera, condition)
            seconds["load"] = time.perf_counter() - t0
            seconds["load_translate"] = self.translate_seconds
        elif not self._same_layout(snapshot, condition):
            self._load(snapshot, camera, condition)
            self.reloads += 1
            seconds["load"] = time.perf_counter() - t0
            seconds["load_translate"] = self.translate_seconds
        else:
            self._update(snapshot, camera, condition)
            seconds["update"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        w, h = self.config.width, self.config.height
        hits = trace_pixel_centres(self.mi, self._scene, self._translation.shape_ids, camera, w, h)
        class_ids, instance_ids = label_maps(hits, snapshot)
        seconds["labels"] = time.perf_counter() - t0
        image = exposure = denoised = None
        if rgb:
            t0 = time.perf_counter()
            if condition is not None and self._translation.lamps:
                self._focus_lamps(hits, camera)
            # Mitsuba's perspective sensor cannot distort: a lens with distortion renders through its own sensor.
            sensor = distorted_sensor(self.mi, camera, self.config) if camera.distortion is not None else None
            if self.config.denoise and self._guides is None:
                # The scalar variant needs the guides wrapped around the path tracer (see guide_integrator_dict).
                wrapped = self.variant.startswith("scalar")
                self._guides = self.mi.load_dict(guide_integrator_dict(self.config if wrapped else None))
                self.denoiser()
            rgb_pass = render_rgb(self.mi, self._scene, self.config, show_progress, sensor=sensor, seed=seed,
                                  guides=self._guides if self.config.denoise else None)
            image = rgb_pass.rgb
            seconds["rgb"] = time.perf_counter() - t0
            if self.config.denoise:
                # Path-traced radiance only: fog and rain are added afterwards, noise-free, in image space.
                t0 = time.perf_counter()
                image, fireflies = self._denoiser.denoise_pass(image, rgb_pass.albedo, rgb_pass.normal)
                seconds["denoise"] = time.perf_counter() - t0
                denoised = {"denoiser": "Intel Open Image Denoise (RT filter, HDR, albedo and normal guides)",
                            "firefly_pixels": fireflies.pixels}
            t0 = time.perf_counter()
            if condition is not None:
                image = self._weather(image, hits, camera, condition, snapshot,
                                      self.config.seed if seed is None else seed)
            exposure = choose_exposure(image, hits.mesh_index >= 0, camera.exposure_ev)
            seconds["weather"] = time.perf_counter() - t0
        if self.count_compiles and not self.variant.startswith("scalar"):
            import drjit as dr

            seconds["compile"] = sum(k.get("codegen_time", 0.0) + k.get("backend_time", 0.0)
                                     for k in dr.kernel_history() if not k.get("cache_hit", True)) / 1000.0
        return RenderedFrame(rgb=image, class_ids=class_ids, instance_ids=instance_ids, hits=hits,
                             variant=self.variant, seconds=seconds, exposure=exposure, condition=condition,
                             denoised=denoised)

    def amodal(self, snapshot: SceneSnapshot, camera: PinholeCamera, instance_ids: Iterable[int]) -> dict[int, np.ndarray]:
        """Amodal masks of ``instance_ids`` (ids of ``snapshot.instances``) seen by ``camera``: each id → (k,)
        int64 sorted flat pixel indices (``y * width + x`` at the session's size) whose pixel-centre ray, the
        label pass's own, meets the instance at any depth (:mod:`synthua_usd.backends.mitsuba.amodal`).

        The instances' meshes live in a second scene of their own, kept for the next call with the same ids
        and the same gprims (then only the sensor and moved vertices are updated), loaded afresh otherwise.
        It is independent of the scene :meth:`render` holds and of its condition."""
        ids = checked_ids(snapshot, instance_ids)
        if self._amodal is not None and self._amodal.holds(snapshot, ids):
            self._amodal.update(snapshot, camera, self.config)
        else:
            self._amodal = None  # let the old scene go before the new one is built
            self._amodal = AmodalScene.build(self.mi, snapshot, camera, self.config, ids)
        w, h = self.config.width, self.config.height
        return self._amodal.trace(camera, w, h)

    def _focus_lamps(self, hits, camera: PinholeCamera, count: int = 1024) -> None:
        """Sample lamps in proportion to what they bring to ``count`` surface points this frame sees (an
        even spread of the label rays' hits)."""
        h, w = hits.distance_m.shape
        hit = np.flatnonzero(hits.mesh_index.ravel() >= 0)
        if len(hit):
            chosen = hit[np.linspace(0, len(hit) - 1, min(count, len(hit))).astype(np.int64)]
            origins, directions = camera.pixel_center_rays(w, h)
            points = origins[chosen] + directions[chosen] * hits.distance_m.ravel()[chosen, None]
            weather_scene.focus_lamps(self._params, self._translation.shape_ids, self._translation.lamps,
                                      self._lighting, points)
            self._params.update()

    def _weather(self, image: np.ndarray, hits, camera: PinholeCamera, condition: Condition,
                 snapshot: SceneSnapshot, seed: int) -> np.ndarray:
        """The sun's disk where it is seen, fog, then rain streaks in front of it; the rain of a frame is seeded
        by the session's seed, the camera and the time code."""
        lighting = self._lighting
        airlight = lighting.airlight
        if lighting.sun_direction is not None:
            image = weather.sun_disk(image, hits.mesh_index < 0, camera, lighting.sun_direction,
                                     lighting.sun_irradiance)
        image = weather.apply_fog(image, hits.distance_m, hits.mesh_index >= 0, condition.fog_extinction_per_m,
                                  airlight)
        rng = np.random.default_rng([seed, zlib.crc32(camera.path.encode("utf-8")),
                                     int(round(snapshot.time_code * 1000)) & 0xFFFFFFFF])
        return weather.rain_streaks(image, hits.z_m, camera, condition.rain_rate_mm_per_h, airlight, rng,
                                    snapshot.up_axis)
