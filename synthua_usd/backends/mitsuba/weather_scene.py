"""What a condition (:class:`synthua_usd.model.conditions.Condition`) puts into a Mitsuba scene, and how the loaded
scene is switched from one condition to another.

Built into the scene when it is loaded with a condition (:mod:`synthua_usd.backends.mitsuba.translate`):

* the environment: an ``envmap`` whose upper half is the sky, Mitsuba's ``sunsky`` (Hosek–Wilkie sky,
  turbidity, ground albedo) evaluated at every texel while the sun is up, else the night sky's uniform
  radiance; and whose lower half is the ground beyond the twin, to the horizon: a Lambertian plain of the
  sky model's own ground albedo under the condition's unshadowed sun and sky, radiance albedo · E / π
  (``sunsky`` alone is black below the horizon, which showed as black bands and voids wherever a camera
  looks past the modelled ground). Mitsuba allows one environment emitter per scene, hence one map for
  both; it is importance-sampled, and the ground lights the twin from below as a real plain would. What
  it leaves out: the plain has no relief, texture or shadows, and it meets the twin's ground at infinity
  (on the horizon line), not at the twin's edge;
* the sun: a ``directional`` emitter, dark at night, with the irradiance of ``sunsky``'s own sun disk
  (measured by :class:`LightMeter`), whose disk is switched off (``sun_scale`` 0). A delta light is sampled
  exactly by every shadow ray, where the disk's own sampling also spends samples on the sky and puts
  penumbra noise into every sunlit pixel: measured on the district at 640×480, 16 spp, two seeds, the same
  mean image (within 0.03 %) with 21 % less noise variance on CCTV_Largo and PedestrianEye_Street, equal on
  UAV_Oblique, and 15–18 % less RGB time on UAV_Oblique at 1280×960. What it leaves out: the sun's 0.27°
  penumbrae and its disk seen in mirror-like reflections; the disk seen straight is drawn in image space
  (:func:`synthua_usd.backends.weather.sun_disk`);
* an ``area`` emitter on every lamp mesh (:mod:`synthua_usd.model.lamps`), dark until a condition turns it on;
* weathered surfaces, only when the condition has them: a ``blendbsdf`` per material between the dry
  ``principled`` BSDF and a wet or snowy one, weighted per face (``face_wet``, ``face_snow``: the wetness or
  snow cover of upward-facing faces) read from the scene's tables of face weights
  (:mod:`synthua_usd.backends.mitsuba.shape_tables`).

:func:`apply_condition` then sets, through ``traverse()`` parameters and without reloading: the environment
map (the sky of the sun's direction and turbidity, or the night sky, and the ground under them; fog dims the
sky, see :mod:`synthua_usd.backends.weather`), the sun's direction and irradiance (zero at night), every
lamp's radiance, and the emitters' sampling weights (lumens, so unlit lamps are never sampled). Changing
wetness or snow cover changes the BSDFs and mesh attributes the scene was built with: :func:`scene_key`
differs and the session reloads.

Wet surfaces (Lekner & Dorf 1988, "Why some things are darker when wet", Applied Optics 27(7)): light
enters the water film (diffuse reflectance of water r_e ≈ 0.066), and of what the ground (albedo a)
returns, the share r_i = 1 − (1 − r_e)/n² (n = 1.33) is reflected back down by the film, so the wet
albedo is a' = (1 − r_e)·a·(1 − r_i)/(1 − a·r_i): darker. The film itself is a smooth clearcoat; the
ground's roughness halves. Snow: a white (albedo 0.85) rough BSDF.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from synthua_usd.backends.mitsuba import surfaces
from synthua_usd.backends.mitsuba.shape_tables import ShapeTables
from synthua_usd.backends.weather import fog_lighting
from synthua_usd.composition.scenario import ENVIRONMENT_PATH
from synthua_usd.model.conditions import SNOW_FREE_CLASSES, SNOW_SLOPE_DEG, WET_GROUND_CLASSES, WET_MAX_SLOPE_DEG, Condition
from synthua_usd.model.lamps import KINDS, is_on, lamp_role
from synthua_usd.model.photometry import CCT_4000K, CD_PER_M2_PER_UNIT, radiance_rgb
from synthua_usd.model.scene import Material, SceneSnapshot

SKY = "sky_environment"
SUN = "sky_sun"
GROUND_ALBEDO = 0.2
#: Texels (width, height) of the environment map: 0.35° at JIT variants; scalar ones evaluate the sky one
#: direction per call, so they bake a coarser map.
ENVIRONMENT_TEXELS = {"jit": (1024, 512), "scalar": (256, 128)}
SNOW_ALBEDO = 0.85
WATER_N = 1.33
WATER_DIFFUSE_REFLECTANCE = 0.066
#: Emitters are sampled in proportion to the illuminance (lux) they bring: the sky its horizontal
#: illuminance, a lamp Φ / (4π d²) at d = REFERENCE_DISTANCE_M until :func:`focus_lamps` measures d for a
#: camera (never nearer than NEAR_M). The sky keeps a little weight so that a scene with every lamp off
#: still has an emitter to sample.
MIN_SKY_WEIGHT = 1e-6
REFERENCE_DISTANCE_M = 10.0
NEAR_M = 1.0


@dataclass(frozen=True)
class LampMesh:
    """A mesh that is a lamp: its index in the snapshot's meshes, role, the labelled instance it belongs to,
    its area and the area of its instance's meshes of that role (m²), and its centre (3,) world metres."""

    index: int
    role: str
    instance_path: str
    area_m2: float
    instance_area_m2: float
    centre: tuple[float, float, float]


@dataclass(frozen=True)
class Lighting:
    """What :func:`apply_condition` set: the sun and sky scales (fog), ``airlight`` (3,) float64, the linear
    RGB radiance of fog at infinite distance (renderer units), the luminous flux of every lit lamp mesh by
    mesh index, and the sun: its unit world ``sun_direction`` (3,) (towards the sun; None at night) and
    ``sun_irradiance`` (3,) linear RGB on a surface facing it, after fog."""

    sun_scale: float
    sky_scale: float
    airlight: np.ndarray
    lamp_flux_lm: dict[int, float]
    sun_direction: np.ndarray | None = None
    sun_irradiance: np.ndarray | None = None


def up_vector(up_axis: str) -> np.ndarray:
    return np.array([0.0, 1.0, 0.0]) if up_axis == "Y" else np.array([0.0, 0.0, 1.0])


def _class_names(snapshot: SceneSnapshot) -> dict[int, str]:
    names = {0: "unlabelled"}
    names.update({inst.class_id: inst.class_name for inst in snapshot.instances})
    return names


def _instance_paths(snapshot: SceneSnapshot) -> dict[int, str]:
    return {inst.id: inst.prim_path for inst in snapshot.instances}


def _areas(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    a, b, c = (points[triangles[:, i]] for i in range(3))
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)


def lamp_meshes(snapshot: SceneSnapshot) -> tuple[LampMesh, ...]:
    """Every lamp mesh of ``snapshot`` (authored ``synthua:lamp`` or a lamp class)."""
    names, paths = _class_names(snapshot), _instance_paths(snapshot)
    found = []
    for i, item in enumerate(snapshot.meshes):
        role = lamp_role(item.lamp, names.get(item.class_id, ""))
        if role:
            found.append((i, role, paths.get(item.instance_id, item.prim_path),
                          float(_areas(item.points, item.triangles).sum()), tuple(item.points.mean(axis=0))))
    totals: dict[tuple[str, str], float] = {}
    for _, role, path, area, _ in found:
        totals[(path, role)] = totals.get((path, role), 0.0) + area
    return tuple(LampMesh(i, role, path, area, totals[(path, role)], centre) for i, role, path, area, centre in found)


# --- surfaces -------------------------------------------------------------------------------------------

def scene_key(condition: Condition | None) -> tuple | None:
    """The part of a condition built into the loaded scene, a change of which means a reload: wetness and snow
    cover (BSDFs and mesh attributes). Day and night share the scene: the environment map and the sun are
    parameters (the sun is dark at night)."""
    if condition is None:
        return None
    return (condition.ground_wetness, condition.snow_cover)


def wet_albedo(albedo: np.ndarray) -> np.ndarray:
    """Lekner & Dorf's albedo of a surface of ``albedo`` under a water film (see the module docstring)."""
    a = np.asarray(albedo, np.float64)
    r_i = 1.0 - (1.0 - WATER_DIFFUSE_REFLECTANCE) / WATER_N ** 2
    return (1.0 - WATER_DIFFUSE_REFLECTANCE) * a * (1.0 - r_i) / (1.0 - a * r_i)


def face_weights(item, class_name: str, up: np.ndarray, condition: Condition) -> dict[str, np.ndarray]:
    """``face_wet`` and ``face_snow`` (m,) float32 weights of ``item``'s triangles, only those not all zero."""
    wetness = condition.ground_wetness if class_name in WET_GROUND_CLASSES else 0.0
    snow = condition.snow_cover if class_name not in SNOW_FREE_CLASSES else 0.0
    if wetness == 0.0 and snow == 0.0:
        return {}
    p, t = item.points, item.triangles
    normals = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])
    cos_up = normals @ up / np.maximum(np.linalg.norm(normals, axis=1), 1e-12)
    out = {}
    if wetness:
        out["face_wet"] = wetness * (cos_up >= math.cos(math.radians(WET_MAX_SLOPE_DEG)))
    if snow:
        full, none = (math.cos(math.radians(a)) for a in SNOW_SLOPE_DEG)
        out["face_snow"] = snow * np.clip((cos_up - none) / (full - none), 0.0, 1.0)
    return {k: v.astype(np.float32) for k, v in out.items() if np.any(v > 0)}


def _wet_dict(material: Material, images: surfaces.TextureImages | None,
              tables: ShapeTables | None = None) -> tuple[dict, dict]:
    wet, values = surfaces.principled_dict(material, images, tables, albedo=wet_albedo, roughness_factor=0.5,
                                           name="_wet")
    wet["clearcoat"] = 1.0
    wet["clearcoat_gloss"] = 0.9
    return wet, values


def surface_bsdf_dict(material: Material, layers: frozenset[str], images: surfaces.TextureImages | None = None,
                      tables: ShapeTables | None = None) -> tuple[dict, dict]:
    """The BSDF dict of ``material`` (:mod:`surfaces`, textured when ``images`` is given) with the weathering
    ``layers`` (``face_wet``, ``face_snow``) over its dry ``principled`` BSDF, weighted per face; the normal map
    and the opacity mask wrap the whole (water and snow follow the surface's relief and holes). With ``tables``
    (:class:`~synthua_usd.backends.mitsuba.shape_tables.ShapeTables`) the material's constants and the face
    weights are the shape's rows of its tables (returned: column -> value), so materials of one kind share one
    BSDF; without, constants and Mitsuba's ``mesh_attribute`` are in the dict."""
    def weight(name: str):
        return tables.weight(name) if tables is not None else {"type": "mesh_attribute", "name": name}

    node, values = surfaces.principled_dict(material, images, tables)
    if "face_wet" in layers:
        wet, wet_values = _wet_dict(material, images, tables)
        node = {"type": "blendbsdf", "weight": weight("face_wet"), "bsdf_0": node, "bsdf_1": wet}
        values.update(wet_values)
    if "face_snow" in layers:
        node = {"type": "blendbsdf", "weight": weight("face_snow"),
                "bsdf_0": node, "bsdf_1": {"type": "principled", "roughness": 0.7,
                                           "base_color": {"type": "rgb", "value": [SNOW_ALBEDO] * 3}}}
    node, wrap_values = surfaces.wrapped(node, material, images, tables)
    return node, {**values, **wrap_values}


def mesh_face_weights(snapshot: SceneSnapshot, condition: Condition | None) -> list[dict[str, np.ndarray]]:
    """Per mesh of ``snapshot``, its weathering attributes under ``condition`` (empty dicts when dry)."""
    if condition is None or (condition.ground_wetness, condition.snow_cover) == (0.0, 0.0):
        return [{} for _ in snapshot.meshes]
    names, up = _class_names(snapshot), up_vector(snapshot.up_axis)
    return [face_weights(item, names.get(item.class_id, ""), up, condition) for item in snapshot.meshes]


# --- emitters ------------------------------------------------------------------------------------------

def own_lights(snapshot: SceneSnapshot, condition: Condition | None) -> tuple:
    """The snapshot's UsdLux lights to render: all of them without a condition; with one, all but the
    environment prim's own sun and sky, which stand in for the condition in viewers."""
    if condition is None:
        return snapshot.lights
    return tuple(light for light in snapshot.lights if not light.prim_path.startswith(ENVIRONMENT_PATH + "/"))


def sunsky_dict(mi, up_axis: str) -> dict:
    """Mitsuba's ``sunsky`` (its frame is Z up; on Y-up stages it is turned so that its zenith is +Y; its
    ``sun_direction`` is a world direction), dark: what :class:`LightMeter` measures and the environment's
    sky is evaluated from."""
    to_world = mi.ScalarTransform4f().rotate([1, 0, 0], -90) if up_axis == "Y" else mi.ScalarTransform4f()
    return {"type": "sunsky", "sun_direction": up_vector(up_axis).tolist(), "to_world": to_world,
            "sun_scale": 0.0, "sky_scale": 0.0}


def environment_to_world(mi, up_axis: str):
    """The ``envmap`` frame: its latitude-longitude map has +Y as zenith, turned to +Z on Z-up stages."""
    return mi.ScalarTransform4f() if up_axis == "Y" else mi.ScalarTransform4f().rotate([1, 0, 0], 90)


def environment_texels(mi) -> tuple[int, int]:
    return ENVIRONMENT_TEXELS["scalar" if mi.variant().startswith("scalar") else "jit"]


def texel_directions(mi, up_axis: str) -> np.ndarray:
    """(H, W, 3) unit world directions of the environment map's texel centres (Mitsuba's ``envmap``
    convention: u = φ / 2π, v = θ / π, local direction (sin φ sin θ, cos θ, −cos φ sin θ)); read-only, computed
    once per map size and up axis (every new sky evaluates itself at them)."""
    return _texel_directions(mi, environment_texels(mi), up_axis)


@functools.lru_cache(maxsize=4)
def _texel_directions(mi, size: tuple[int, int], up_axis: str) -> np.ndarray:
    w, h = size
    theta = (np.arange(h) + 0.5) / h * math.pi
    phi = (np.arange(w) + 0.5) / w * 2.0 * math.pi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    local = np.stack([np.sin(p) * np.sin(t), np.cos(t), -np.cos(p) * np.sin(t)], axis=-1)
    rotation = np.array(environment_to_world(mi, up_axis).matrix, np.float64)[:3, :3]
    directions = local @ rotation.T
    directions.setflags(write=False)
    return directions


def sky_emitter(mi, up_axis: str) -> dict:
    """The environment emitter and the sun (a ``directional`` emitter), dark until :func:`apply_condition` bakes
    the condition's sky and ground into the one and, while the sun is up, gives the other its irradiance."""
    w, h = environment_texels(mi)
    return {SKY: {"type": "envmap", "bitmap": mi.Bitmap(np.zeros((h, w, 3), np.float32)),
                  "to_world": environment_to_world(mi, up_axis)},
            SUN: {"type": "directional", "direction": (-up_vector(up_axis)).tolist(),
                  "irradiance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}}


def environment_radiance(mi, up_axis: str, sky: np.ndarray, ground: np.ndarray) -> np.ndarray:
    """(H, W, 3) float32 texels: ``sky`` (H, W, 3) or (3,) above the horizon, ``ground`` (3,) below. The map's
    zenith is the stage's up axis (:func:`environment_to_world`), so its upper half of rows is the sky."""
    w, h = environment_texels(mi)
    out = np.empty((h, w, 3), np.float32)
    out[:h // 2] = np.broadcast_to(np.asarray(sky, np.float64), (h, w, 3))[:h // 2]
    out[h // 2:] = np.asarray(ground, np.float64)
    return out


def _set_environment(mi, params, texels: np.ndarray) -> None:
    """Replace the environment map's texels: the data of a map loaded from them (so that its layout, with
    the columns Mitsuba pads for periodicity, is Mitsuba's own); the scene rebuilds its sampling on update."""
    fresh = mi.traverse(mi.load_dict({"type": "envmap", "bitmap": mi.Bitmap(texels)}))
    params[f"{SKY}.data"] = fresh["data"]


def _perpendicular(direction) -> np.ndarray:
    """A unit vector perpendicular to ``direction`` (3,): the ``up`` a look-at frame needs."""
    d = np.asarray(direction, np.float64)
    axis = np.eye(3)[int(np.argmin(np.abs(d)))]
    return np.cross(d, axis) / np.linalg.norm(np.cross(d, axis))


def dark_area_emitter(mi):
    return mi.load_dict({"type": "area", "radiance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}})


def apply_condition(mi, params, shape_ids: tuple[str, ...], lamps: tuple[LampMesh, ...], condition: Condition,
                    up_axis: str, meter: "LightMeter") -> Lighting:
    """Set the sky and lamp parameters of a scene loaded by ``translate(..., condition=...)`` to ``condition``
    (``params.update()`` is left to the caller)."""
    albedo = GROUND_ALBEDO + (SNOW_ALBEDO - GROUND_ALBEDO) * condition.snow_cover
    if condition.sun_up:
        direction = condition.sun_direction(up_axis)
        e_sun, e_sky = meter.measure(direction, condition.turbidity, albedo, up_axis)
        sun_scale, sky_scale, airlight = fog_lighting(condition, e_sun, e_sky)
        sky = sky_scale * meter.sky_texels(direction, condition.turbidity, albedo, up_axis)
        # The directional sun gives, on a surface facing it, what sunsky's sun disk gives: E_horizontal / cos(zenith).
        cos_zenith = float(np.dot(direction, up_vector(up_axis)))
        normal = sun_scale * np.asarray(e_sun, np.float64) / max(cos_zenith, 1e-6)
        params[f"{SUN}.irradiance.value"] = type(params[f"{SUN}.irradiance.value"])(*map(float, normal))
        params[f"{SUN}.to_world"] = mi.ScalarTransform4f().look_at(
            origin=[0.0, 0.0, 0.0], target=(-np.asarray(direction, np.float64)).tolist(),
            up=_perpendicular(direction).tolist())
        sun_lux = float(np.mean(sun_scale * e_sun)) * CD_PER_M2_PER_UNIT
        sky_lux = float(np.mean(sky_scale * e_sky)) * CD_PER_M2_PER_UNIT
        params[f"{SUN}.sampling_weight"] = max(sun_lux, MIN_SKY_WEIGHT)
        params[f"{SKY}.sampling_weight"] = max(sky_lux, MIN_SKY_WEIGHT)
    else:
        sun_scale = sky_scale = 0.0
        direction = normal = None
        airlight = np.asarray(radiance_rgb(condition.night_sky_luminance_cd_m2, CCT_4000K))
        sky = airlight
        params[f"{SUN}.irradiance.value"] = type(params[f"{SUN}.irradiance.value"])(0.0, 0.0, 0.0)
        params[f"{SUN}.sampling_weight"] = MIN_SKY_WEIGHT
        params[f"{SKY}.sampling_weight"] = max(math.pi * condition.night_sky_luminance_cd_m2, MIN_SKY_WEIGHT)
    # The ground below the horizon: a Lambertian plain of the sky model's albedo under the light that makes the
    # airlight (E / π of the sun and sky after fog; at night the sky's own radiance, E = π L).
    _set_environment(mi, params, environment_radiance(mi, up_axis, sky, albedo * np.asarray(airlight, np.float64)))
    flux_lm: dict[int, float] = {}
    for lamp in lamps:
        kind = KINDS[lamp.role]
        on = is_on(kind, condition, lamp.instance_path)
        luminance = kind.luminance(lamp.instance_area_m2) if on else 0.0
        key = shape_ids[lamp.index]
        params[f"{key}.emitter.radiance.value"] = type(params[f"{key}.emitter.radiance.value"])(
            *radiance_rgb(luminance, kind.color))
        flux_lm[lamp.index] = math.pi * lamp.area_m2 * luminance
        params[f"{key}.emitter.sampling_weight"] = flux_lm[lamp.index] / (4.0 * math.pi * REFERENCE_DISTANCE_M ** 2)
    return Lighting(sun_scale=sun_scale, sky_scale=sky_scale, airlight=np.asarray(airlight, np.float64),
                    lamp_flux_lm=flux_lm, sun_direction=direction, sun_irradiance=normal)


def focus_lamps(params, shape_ids: tuple[str, ...], lamps: tuple[LampMesh, ...], lighting: Lighting,
                points: np.ndarray) -> None:
    """Weight lit lamps for the frame about to be rendered: by the illuminance Φ / (4π d²) each would give,
    on average, at ``points`` (n, 3) world metres, the surfaces this camera sees (d at least
    :data:`NEAR_M`). Only the choice of which emitter to sample changes, not the image it converges to
    (every lit lamp keeps a positive weight); with tens of lamps it is what keeps a night frame from being
    mostly noise. ``params.update()`` is left to the caller."""
    if not lamps or len(points) == 0:
        return
    centres = np.array([lamp.centre for lamp in lamps])
    d2 = np.maximum(((points[None, :, :] - centres[:, None, :]) ** 2).sum(axis=2), NEAR_M ** 2)
    mean_inverse_square = (1.0 / d2).mean(axis=1)
    for lamp, focus in zip(lamps, mean_inverse_square):
        flux = lighting.lamp_flux_lm.get(lamp.index, 0.0)
        params[f"{shape_ids[lamp.index]}.emitter.sampling_weight"] = flux / (4.0 * math.pi) * float(focus)


def radiance_towards(mi, emitter, directions: np.ndarray) -> np.ndarray:
    """(n, 3) float64 radiance an environment ``emitter`` sends from unit world ``directions`` (n, 3) (towards
    the sky), by its own ``eval``: one kernel on JIT variants, one call per direction on scalar ones."""
    d = np.asarray(directions, np.float64)
    if mi.variant().startswith("scalar"):
        out = np.zeros((len(d), 3))
        for k, w in enumerate(d):
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*map(float, -w))
            value = emitter.eval(si)
            out[k] = (value[0], value[1], value[2])
        return out
    import drjit as dr

    si = dr.zeros(mi.SurfaceInteraction3f, len(d))
    si.wi = mi.Vector3f(*(np.ascontiguousarray(-d[:, i], np.float32) for i in range(3)))
    value = emitter.eval(si)
    return np.column_stack([np.asarray(value[i], np.float64) for i in range(3)])


class LightMeter:
    """Horizontal irradiance (3,) of a ``sunsky``'s sun and of its sky alone, renderer units:
    E = ∫ L cosθ dω, estimated by sampling directions from the emitter itself (2^16 of them, seeded), so
    the sun disk is sampled as well as the dome; and the sky's radiance at the environment map's texels.
    Results are cached per sky."""

    SAMPLES = 1 << 16

    def __init__(self, mi) -> None:
        self.mi = mi
        self._cache: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
        self._textures: dict[tuple, np.ndarray] = {}

    def _irradiance(self, emitter: dict, up: np.ndarray) -> np.ndarray:
        mi = self.mi
        sky = mi.load_dict({"type": "scene", "sky": emitter}).emitters()[0]
        origin = mi.Interaction3f()
        origin.p = mi.Point3f(0.0, 0.0, 0.0)
        if mi.variant().startswith("scalar"):  # one direction per call: a golden-ratio lattice of 4096
            n, total = 4096, np.zeros(3)
            for k in range(n):
                ds, weight = sky.sample_direction(origin, mi.Point2f((k + 0.5) / n, (k * 0.6180339887498949) % 1.0))
                total += np.array([weight[0], weight[1], weight[2]]) * max(float(np.dot(ds.d, up)), 0.0)
            return total / n
        sampler = mi.load_dict({"type": "independent"})
        sampler.seed(0, self.SAMPLES)
        ds, weight = sky.sample_direction(origin, sampler.next_2d())
        cos = mi.Float(0.0) + ds.d[0] * float(up[0]) + ds.d[1] * float(up[1]) + ds.d[2] * float(up[2])
        cos = np.maximum(np.asarray(cos, np.float64), 0.0)
        return np.array([float(np.mean(np.asarray(weight[i], np.float64) * cos)) for i in range(3)])

    def measure(self, direction: np.ndarray, turbidity: float, albedo: float,
                up_axis: str) -> tuple[np.ndarray, np.ndarray]:
        key = (tuple(np.round(direction, 9)), turbidity, albedo, up_axis)
        if key not in self._cache:
            base = self._sunsky(direction, turbidity, albedo, up_axis)
            up = up_vector(up_axis)
            self._cache[key] = (self._irradiance(dict(base, sun_scale=1.0, sky_scale=0.0), up),
                                self._irradiance(dict(base, sun_scale=0.0, sky_scale=1.0), up))
        return self._cache[key]

    def sky_texels(self, direction: np.ndarray, turbidity: float, albedo: float, up_axis: str) -> np.ndarray:
        """(H, W, 3) float64: the clear sky alone (no sun disk) at the environment map's texel centres
        (:func:`texel_directions`), by the emitter's own ``eval``; zero below the horizon. Cached per sky."""
        key = ("texels", tuple(np.round(direction, 9)), turbidity, albedo, up_axis)
        if key not in self._textures:
            mi = self.mi
            sky = mi.load_dict({"type": "scene", "sky": dict(self._sunsky(direction, turbidity, albedo, up_axis),
                                                              sky_scale=1.0)}).emitters()[0]
            dirs = texel_directions(mi, up_axis)
            flat = dirs.reshape(-1, 3)
            values = radiance_towards(mi, sky, flat)
            values[flat @ up_vector(up_axis) <= 0.0] = 0.0
            self._textures.clear()  # one sky at a time: 12 MB each
            self._textures[key] = values.reshape(dirs.shape)
        return self._textures[key]

    def _sunsky(self, direction: np.ndarray, turbidity: float, albedo: float, up_axis: str) -> dict:
        return dict(sunsky_dict(self.mi, up_axis), sun_direction=[float(x) for x in direction], turbidity=float(turbidity),
                    albedo=float(albedo))
