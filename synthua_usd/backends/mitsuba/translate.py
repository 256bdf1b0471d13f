"""SceneSnapshot + camera → the dict ``mi.load_dict`` loads, and the shape key of every mesh.

Nothing is rendered and no global state is touched; the caller passes the ``mitsuba`` module with its
variant already active (:func:`synthua_usd.backends.mitsuba.variants.activate`). The dict is not pure
data: meshes and BSDFs in it are Mitsuba objects built from the snapshot's arrays (``mi.Mesh``), which
is how Mitsuba's Python API takes triangle soups without a file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from synthua_usd.backends.mitsuba import surfaces, weather_scene
from synthua_usd.backends.mitsuba.shape_tables import ShapeTables
from synthua_usd.backends.mitsuba.weather_scene import LampMesh
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.conditions import Condition
from synthua_usd.model.render_config import RenderConfig, takes_exactly
from synthua_usd.model.scene import Light, SceneSnapshot


@dataclass(frozen=True, eq=False)
class Translation:
    """``scene`` is the dict :meth:`load` loads; ``shape_ids`` (the Mitsuba shape ids) is aligned with the
    snapshot's meshes. Loading keeps ``optimize=False``: merging meshes would lose the instance identity labels
    depend on."""

    scene: dict
    shape_ids: tuple[str, ...]
    #: With a condition: the lamp meshes given (dark) area emitters, and what of the condition is built in
    #: (:func:`weather_scene.scene_key`).
    lamps: tuple[LampMesh, ...] = ()
    condition_key: tuple | None = None
    #: The materials' constants and face weights by shape (:mod:`shape_tables`), filled by :meth:`load`.
    tables: ShapeTables | None = None

    def load(self, mi):
        """The loaded Mitsuba scene (``mi`` with the translation's variant active), its tables filled."""
        scene = mi.load_dict(self.scene, optimize=False)
        if self.tables is not None:
            self.tables.fill(scene, self.shape_ids)
        return scene


def shape_id(index: int) -> str:
    return f"mesh_{index:06d}"


#: The share of a dome's illuminance its emitter-sampling weight gets (see :func:`light_sampling_weight`).
DOME_WEIGHT_SHARE = 0.1


def light_sampling_weight(light: Light, up: np.ndarray) -> float:
    """How often the path tracer's emitter sampling picks ``light`` among the stage's UsdLux lights (Mitsuba
    picks an emitter in proportion to these weights; every emitter weighs 1 by default): the illuminance it
    brings to a surface facing ``up`` (world unit vector), a sun's ``irradiance * cos`` and a dome's
    ``pi * radiance`` (mean over the colour's channels), the dome's scaled by :data:`DOME_WEIGHT_SHARE`.

    Why: a distant light is a delta light that only emitter sampling can reach, while BSDF sampling finds the
    dome as well (Mitsuba weighs the two by MIS), so sampling the sun more often removes most of the noise of
    sunlit surfaces. Measured on the district (320x240, two views, 256-spp reference; docs/rendering.md "Rendering
    backend"): picking by these weights instead of evenly gained 3.9 dB at 16 spp and 1.2-1.4 dB at 8 spp + OIDN.
    A light that brings nothing to an up-facing surface (a sun below the horizon) keeps a small weight."""
    tone = float(np.mean(light.color))
    if light.kind == "distant":
        cos = max(float(-np.dot(np.asarray(light.direction, float), up)), 0.05)
        return max(light.irradiance * tone * cos, 1e-6)
    return max(math.pi * light.radiance * tone * DOME_WEIGHT_SHARE, 1e-6)


def emitter_dict(light: Light, sampling_weight: float | None = None) -> dict:
    """The Mitsuba emitter of a UsdLux light; ``sampling_weight`` as :func:`light_sampling_weight` (None: Mitsuba's
    default of 1)."""
    weight = {} if sampling_weight is None else {"sampling_weight": float(sampling_weight)}
    if light.kind == "distant":
        value = [c * light.irradiance for c in light.color]
        return {"type": "directional", "direction": list(light.direction), "irradiance": {"type": "rgb", "value": value},
                **weight}
    if light.kind == "dome":
        value = [c * light.radiance for c in light.color]
        return {"type": "constant", "radiance": {"type": "rgb", "value": value}, **weight}
    raise ValueError(f"{light.prim_path}: light kind '{light.kind}' has no Mitsuba emitter; expected distant or dome")


def sensor_to_world(mi, camera: PinholeCamera):
    """The camera's pose as Mitsuba's ``to_world`` (Mitsuba cameras look down +Z; ``look_at`` converts)."""
    _, up, forward = camera.axes()
    origin = camera.origin
    return mi.ScalarTransform4f().look_at(origin=origin.tolist(), target=(origin + forward).tolist(), up=up.tolist())


def sensor_dict(mi, camera: PinholeCamera, config: RenderConfig, spp: int | None = None) -> dict:
    """A perspective sensor with the camera's conformed horizontal field of view."""
    fov_x, _ = camera.fov_deg(config.width, config.height)
    return {
        "type": "perspective",
        "fov": fov_x,
        "fov_axis": "x",
        "near_clip": camera.clip_near_m,
        "far_clip": camera.clip_far_m,
        "to_world": sensor_to_world(mi, camera),
        "film": film_dict(config),
        "sampler": sampler_dict(config, spp),
    }


def film_dict(config: RenderConfig, width: int | None = None, height: int | None = None) -> dict:
    """The RGB film of every sensor (``width``/``height`` override the config's size)."""
    return {"type": "hdrfilm", "width": width or config.width, "height": height or config.height,
            "pixel_format": "rgb", "rfilter": {"type": config.pixel_filter}}


#: The sampler of every RGB pass: Mitsuba's correlated multi-jittered sampler (Kensler 2013). Its samples are
#: stratified in each pair of dimensions, so where a pixel holds detail smaller than itself (edges of cobbles,
#: awnings, people, fine texture) its coverage is estimated far better than by independent samples, and the
#: denoiser starts from less noise (measured in docs/rendering.md, "Denoising").
SAMPLER = "multijitter"
#: Mitsuba's multi-jittered sampler draws an r x c grid with r = isqrt(n), c = ceil(n / r) and rounds other
#: counts up (5 -> 6); every pass asks for a count it takes as it is (:func:`pass_sample_counts`).
MAX_SPP_PER_PASS = 16


def pass_sample_counts(spp: int) -> list[int]:
    """``spp`` samples per pixel split into passes of at most :data:`MAX_SPP_PER_PASS`, each a count the sampler
    takes exactly (the largest that fits first): 8 -> [8], 16 -> [16], 40 -> [16, 16, 8], 5 -> [4, 1]."""
    counts, left = [], spp
    while left > 0:
        n = max(k for k in range(1, min(left, MAX_SPP_PER_PASS) + 1) if takes_exactly(k))
        counts.append(n)
        left -= n
    return counts


def sampler_dict(config: RenderConfig, spp: int | None = None) -> dict:
    """The sampler of every sensor (:data:`SAMPLER`), holding its first pass's count. Its base seed stays 0:
    Mitsuba adds it to the seed each ``mi.render`` call passes, and the render seed (:func:`render.render_rgb`)
    must be the only one."""
    return {"type": SAMPLER, "sample_count": pass_sample_counts(spp or config.spp)[0], "seed": 0}


def integrator_dict(config: RenderConfig) -> dict:
    """The path tracer of every RGB pass."""
    return {"type": "path", "max_depth": config.max_depth}


#: The denoiser's guides: albedo (channels 0..2) and shading normal (3..5) of the first hit.
GUIDE_AOVS = "albedo:albedo,nn:sh_normal"


def guide_integrator_dict(config: RenderConfig | None = None) -> dict:
    """Mitsuba's ``aov`` integrator with the denoiser's guides (:data:`GUIDE_AOVS`, channels 0..5); with
    ``config``, wrapped around the path tracer (RGB in channels 0..2, bit-identical to :func:`integrator_dict`'s,
    then the guides in 3..8).

    Without ``config`` it is meant for the JIT variants: rendered with the colour pass's seed and sample count
    it draws the same film positions as the path tracer (each sample's first dimensions), so its guides equal,
    bit for bit, those of the wrapped integrator (tested), at a fraction of the cost: wrapping doubled the time
    of the pass (measured 2.0 s against 0.9 s at 4 spp, 640x480, district). The scalar variant draws a pixel's
    samples from one sequence, so there a pass of its own would see other positions: it takes the wrapped
    integrator."""
    if config is None:
        return {"type": "aov", "aovs": GUIDE_AOVS}
    return {"type": "aov", "aovs": GUIDE_AOVS, "integrator": integrator_dict(config)}


def _mesh(mi, key: str, points: np.ndarray, triangles: np.ndarray, bsdf, emitter=None, face_attributes=None,
          uvs: np.ndarray | None = None, normals: np.ndarray | None = None):
    """A Mitsuba mesh of ``points`` (n, 3) and ``triangles`` (m, 3); ``uvs`` (n, 2) in USD's st convention;
    ``normals`` (n, 3) unit shading normals (smooth shading; without them Mitsuba shades each face flat)."""
    props = mi.Properties()
    if emitter is not None:
        props["emitter"] = emitter
    mesh = mi.Mesh(key, len(points), len(triangles), props=props, has_vertex_normals=normals is not None,
                   has_vertex_texcoords=uvs is not None)
    # The BSDF joins after the arrays: traversing a mesh traverses its BSDF too, and textured BSDFs made
    # every traversal copy their texture data (measured: 0.5 MB and ~9 ms per mesh on the district).
    params = mi.traverse(mesh)
    params["vertex_positions"] = type(params["vertex_positions"])(np.ascontiguousarray(points, np.float32).ravel())
    params["faces"] = type(params["faces"])(np.ascontiguousarray(triangles, np.uint32).ravel())
    if uvs is not None:
        params["vertex_texcoords"] = type(params["vertex_texcoords"])(surfaces.mitsuba_uvs(uvs).ravel())
    if normals is not None:  # set with the positions, or Mitsuba computes its own from the faces
        params["vertex_normals"] = type(params["vertex_normals"])(np.ascontiguousarray(normals, np.float32).ravel())
    params.update()
    for name, values in (face_attributes or {}).items():
        mesh.add_attribute(name, 1, type(params["vertex_positions"])(values))
    mesh.set_bsdf(bsdf)
    return mesh


def translate(mi, snapshot: SceneSnapshot, camera: PinholeCamera, config: RenderConfig,
              condition: Condition | None = None) -> Translation:
    """The Mitsuba scene for ``snapshot`` seen by ``camera`` (one shape per gprim; flat shading unless the gprim
    has authored normals).

    With a ``condition`` the scene also holds what :mod:`weather_scene` builds (sky emitters, dark area
    emitters on lamp meshes, weathered BSDFs and their face attributes), and leaves out the environment's
    own UsdLux sun and sky, which are the condition's approximation for viewers; the caller then sets the
    condition with :func:`weather_scene.apply_condition`."""
    face_weights = weather_scene.mesh_face_weights(snapshot, condition)
    lamps = weather_scene.lamp_meshes(snapshot) if condition is not None else ()
    lamp_indices = {lamp.index for lamp in lamps}
    bsdfs: dict = {}
    images = surfaces.TextureImages(mi)
    tables = ShapeTables(mi)
    scene: dict = {"type": "scene",
                   "integrator": integrator_dict(config),
                   "sensor": sensor_dict(mi, camera, config)}
    shape_ids = []
    for i, item in enumerate(snapshot.meshes):
        key = shape_id(i)
        material = snapshot.materials[item.material_key]
        textured = item.uvs is not None and bool(material.textures)
        if not textured:  # a mesh without texture coordinates renders its material's constants
            material = material.untextured()
        node, values = weather_scene.surface_bsdf_dict(material, frozenset(face_weights[i]), images, tables)
        node = surfaces.sided(node, item.double_sided)
        # one BSDF for every material of one kind: their constants are the shapes' rows of the tables
        kind = _kind(node)
        if kind not in bsdfs:
            bsdfs[kind] = mi.load_dict(node)
        tables.put(i, values)
        emitter = None
        if i in lamp_indices:
            emitter = weather_scene.dark_area_emitter(mi)
        elif any(material.emissive_color):
            emitter = mi.load_dict({"type": "area", "radiance": {"type": "rgb", "value": list(material.emissive_color)}})
        if tables.enabled:
            tables.put_weights(i, face_weights[i])
        scene[key] = _mesh(mi, key, item.points, item.triangles, bsdfs[kind], emitter,
                           None if tables.enabled else face_weights[i], item.uvs if textured else None, item.normals)
        shape_ids.append(key)
    # Without a condition the stage's own lights are all there is: sample them by what they bring (with one, the
    # condition's sky and lamps carry weights in other units, set by weather_scene, and these keep Mitsuba's 1).
    up = weather_scene.up_vector(snapshot.up_axis)
    for k, light in enumerate(weather_scene.own_lights(snapshot, condition)):
        weight = light_sampling_weight(light, up) if condition is None else None
        scene[f"light_{k:03d}"] = emitter_dict(light, weight)
    if condition is not None:
        scene.update(weather_scene.sky_emitter(mi, snapshot.up_axis))
    return Translation(scene=scene, shape_ids=tuple(shape_ids), lamps=lamps,
                       condition_key=weather_scene.scene_key(condition), tables=tables)


def _kind(node):
    """What tells BSDF dicts apart: their structure and constants, Mitsuba objects (bitmaps, table textures) by
    identity."""
    if isinstance(node, dict):
        return tuple(sorted((k, _kind(v)) for k, v in node.items()))
    if isinstance(node, (list, tuple)):
        return tuple(_kind(v) for v in node)
    if isinstance(node, (str, int, float, bool)) or node is None:
        return node
    return ("object", id(node))
