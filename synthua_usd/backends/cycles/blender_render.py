"""Render an interchange folder with Blender Cycles: the script the Cycles interpreter runs.

    CYCLES_PYTHON blender_render.py INTERCHANGE_DIR JOBS_JSON OUT_DIR

Run by the Python of a virtual environment holding PyPI's ``bpy`` (Blender as a Python module), never
imported by synthua itself (:mod:`synthua_usd.backends.cycles.runner` starts it). It builds the Blender scene
from what :mod:`synthua_usd.backends.cycles.interchange` wrote (one mesh per soup, flat shading, a Principled
BSDF of the material's constants or, for a textured soup, its textures (:func:`principled`) on the soup's UV
map, a sun lamp and a uniform world for UsdLux distant and dome lights, the camera with its conformed
horizontal field of view and clipping range), sets Cycles up (CPU, fixed threads, path length, view
transform ``Standard`` so the output stays scene-linear), renders a warm-up frame (scene sync and BVH build,
kept by ``use_persistent_data``), then renders every job of ``JOBS_JSON`` and writes ``OUT_DIR/{name}.exr``
(float, linear Rec.709) and ``OUT_DIR/cycles.json`` (timings: ``build_s``, ``warmup_s``, per job
``render_s``, the wall time of ``bpy.ops.render.render`` alone; Blender's version).

A job: ``{"name": str, "samples": int, "denoise": bool, "adaptive": bool, "adaptive_threshold": float, "seed":
int}``. Settings: ``{"threads": int, "max_bounces": int}`` under ``settings`` in ``JOBS_JSON``.

Units: Blender's sun strength is irradiance in W/m² and a world background of colour C at strength 1 is
radiance C: the same units Mitsuba's ``directional`` irradiance and ``constant`` radiance use, so light values
pass through unchanged. Mitsuba's directional light is a delta light: the sun's angle is set to 0 to match it.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import bpy  # noqa: E402 - only in the Cycles interpreter
import numpy as np
from mathutils import Matrix, Vector

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))  # the repository root: the interchange reader
from synthua_usd.backends.cycles.interchange import read_interchange  # noqa: E402


def build_scene(document: dict, soups: list) -> bpy.types.Scene:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for material, (points, triangles, uvs) in zip(document["materials"], soups):
        mesh = bpy.data.meshes.new(f"mesh_{material['index']}")
        n, m = len(points), len(triangles)
        mesh.vertices.add(n)
        mesh.vertices.foreach_set("co", points.astype(np.float32).ravel())
        mesh.loops.add(3 * m)
        mesh.loops.foreach_set("vertex_index", triangles.astype(np.int32).ravel())
        mesh.polygons.add(m)
        mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * m, 3, dtype=np.int32))
        mesh.update(calc_edges=True)
        # Flat shading, as Mitsuba renders these meshes (no vertex normals): a Blender mesh made through the API
        # is smooth-shaded unless its faces are marked sharp, which rounds every box and tilts walls to the sun.
        mesh.polygons.foreach_set("use_smooth", np.zeros(m, dtype=bool))
        if uvs is not None:  # per point in USD's st: Blender's UVs also put (0, 0) at the image's bottom-left
            layer = mesh.uv_layers.new(name=UV_MAP)
            layer.data.foreach_set("uv", np.ascontiguousarray(uvs[triangles.ravel()], np.float32).ravel())
        mesh.materials.append(principled(material))
        obj = bpy.data.objects.new(mesh.name, mesh)
        scene.collection.objects.link(obj)
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    background.inputs["Strength"].default_value = 1.0
    scene.world = world
    for k, light in enumerate(document["lights"]):
        if light["kind"] == "distant":
            data = bpy.data.lights.new(f"sun_{k}", "SUN")
            data.energy = float(light["irradiance"])  # W/m²
            data.color = light["color"]
            data.angle = 0.0  # Mitsuba's directional emitter is a delta light
            obj = bpy.data.objects.new(data.name, data)
            # a sun shines along its local -Z
            obj.rotation_mode = "QUATERNION"
            obj.rotation_quaternion = Vector(light["direction"]).normalized().to_track_quat("-Z", "Y")
            scene.collection.objects.link(obj)
        elif light["kind"] == "dome":
            colour = [c * float(light["radiance"]) for c in light["color"]]
            previous = background.inputs["Color"].default_value
            background.inputs["Color"].default_value = tuple(p + c for p, c in zip(previous[:3], colour)) + (1.0,)
        else:
            raise ValueError(f"light {light['prim_path']}: kind {light['kind']!r}; expected distant or dome")
    cam = document["camera"]
    data = bpy.data.cameras.new("camera")
    data.sensor_fit = "HORIZONTAL"
    data.sensor_width = float(cam["aperture_x_mm"])
    data.lens_unit = "FOV"
    data.angle = math.radians(cam["fov_x_deg"])
    data.clip_start = float(cam["clip_near_m"])
    data.clip_end = float(cam["clip_far_m"])
    obj = bpy.data.objects.new("camera", data)
    obj.matrix_world = Matrix(cam["camera_to_world"])  # both look down local -Z with +Y up
    scene.collection.objects.link(obj)
    scene.camera = obj
    scene.render.resolution_x = document["width"]
    scene.render.resolution_y = document["height"]
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    return scene


UV_MAP = "st"
#: Texture wrap modes → Blender's image extension (one for both axes, as Mitsuba: ``wrap_s`` decides).
EXTENSION = {"repeat": "REPEAT", "mirror": "MIRROR", "clamp": "EXTEND", "black": "CLIP"}


def principled(material: dict) -> bpy.types.Material:
    """A Principled BSDF of ``material``'s constants, its textured inputs replaced by image textures decoded as
    Mitsuba's translation does (:mod:`synthua_usd.backends.mitsuba.surfaces`): texels by colour space, then
    ``value * scale + bias`` and the channel, clipped to [0, 1]; a normal map's [-1, 1] values into a
    tangent-space Normal Map node (red along +s, green along +t). One difference stays: Cycles filters an 8-bit
    sRGB image between texels before decoding it, Mitsuba after (the texel values agree)."""
    out = bpy.data.materials.new(material["key"])
    out.use_nodes = True
    tree = out.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = tuple(material["base_color"]) + (1.0,)
    bsdf.inputs["Roughness"].default_value = min(max(material["roughness"], 0.0), 1.0)
    bsdf.inputs["Metallic"].default_value = min(max(material["metallic"], 0.0), 1.0)
    if any(material["emissive_color"]):
        bsdf.inputs["Emission Color"].default_value = tuple(material["emissive_color"]) + (1.0,)
        bsdf.inputs["Emission Strength"].default_value = 1.0
    textures = material.get("textures", {})
    if "base_color" in textures:
        tree.links.new(clipped(tree, texture_values(tree, textures["base_color"])), bsdf.inputs["Base Color"])
    for name, socket in (("roughness", "Roughness"), ("metallic", "Metallic")):
        if name in textures:
            tree.links.new(clipped(tree, texture_values(tree, textures[name])), bsdf.inputs[socket])
    if "normal" in textures:
        normals = texture_values(tree, textures["normal"])
        encode = tree.nodes.new("ShaderNodeVectorMath")  # [-1, 1] → the [0, 1] colour a Normal Map node decodes
        encode.operation = "MULTIPLY_ADD"
        encode.inputs[1].default_value = (0.5, 0.5, 0.5)
        encode.inputs[2].default_value = (0.5, 0.5, 0.5)
        tree.links.new(normals, encode.inputs[0])
        normal_map = tree.nodes.new("ShaderNodeNormalMap")
        normal_map.space = "TANGENT"
        normal_map.uv_map = UV_MAP
        tree.links.new(encode.outputs["Vector"], normal_map.inputs["Color"])
        tree.links.new(normal_map.outputs["Normal"], bsdf.inputs["Normal"])
    return out


def texture_values(tree, texture: dict):
    """The output socket of ``texture``'s decoded values after scale, bias and channel: a vector for 'rgb', a
    float for one channel."""
    image = bpy.data.images.load(texture["path"], check_existing=True)
    image.alpha_mode = "CHANNEL_PACKED"  # colour independent of alpha, as Mitsuba reads it
    space = texture["color_space"]
    if space == "auto":  # UsdUVTexture's rule, as surfaces.TextureImages applies it: 8-bit RGB(A) is sRGB
        space = "sRGB" if not image.is_float and image.channels in (3, 4) else "raw"
    image.colorspace_settings.name = "sRGB" if space == "sRGB" else "Non-Color"
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    node.interpolation = "Linear"  # Mitsuba's bilinear filter
    node.extension = EXTENSION[texture["wrap_s"]]
    uv = tree.nodes.new("ShaderNodeUVMap")
    uv.uv_map = UV_MAP
    tree.links.new(uv.outputs["UV"], node.inputs["Vector"])
    scale, bias, channel = texture["scale"], texture["bias"], texture["channel"]
    if channel == "rgb":
        affine = tree.nodes.new("ShaderNodeVectorMath")
        affine.operation = "MULTIPLY_ADD"
        affine.inputs[1].default_value = scale[:3]
        affine.inputs[2].default_value = bias[:3]
        tree.links.new(node.outputs["Color"], affine.inputs[0])
        return affine.outputs["Vector"]
    index = "rgba".index(channel)
    if channel == "a":
        source = node.outputs["Alpha"]
    else:
        separate = tree.nodes.new("ShaderNodeSeparateColor")
        tree.links.new(node.outputs["Color"], separate.inputs["Color"])
        source = separate.outputs[index]
    affine = tree.nodes.new("ShaderNodeMath")
    affine.operation = "MULTIPLY_ADD"
    affine.inputs[1].default_value = scale[index]
    affine.inputs[2].default_value = bias[index]
    tree.links.new(source, affine.inputs[0])
    return affine.outputs["Value"]


def clipped(tree, socket):
    """``socket`` clipped to [0, 1] (per component for a vector), as Mitsuba's translation clips texture values."""
    if socket.type == "VECTOR":
        low = tree.nodes.new("ShaderNodeVectorMath")
        low.operation = "MAXIMUM"
        low.inputs[1].default_value = (0.0, 0.0, 0.0)
        high = tree.nodes.new("ShaderNodeVectorMath")
        high.operation = "MINIMUM"
        high.inputs[1].default_value = (1.0, 1.0, 1.0)
        tree.links.new(socket, low.inputs[0])
        tree.links.new(low.outputs["Vector"], high.inputs[0])
        return high.outputs["Vector"]
    clamp = tree.nodes.new("ShaderNodeClamp")
    tree.links.new(socket, clamp.inputs["Value"])
    return clamp.outputs["Result"]


def configure(scene: bpy.types.Scene, settings: dict) -> None:
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    scene.render.threads_mode = "FIXED"
    scene.render.threads = int(settings["threads"])
    scene.render.use_persistent_data = True  # keep the synced scene and BVH between renders
    bounces = int(settings["max_bounces"])
    cycles.max_bounces = bounces
    cycles.diffuse_bounces = cycles.glossy_bounces = cycles.transmission_bounces = bounces
    cycles.volume_bounces = 0
    cycles.transparent_max_bounces = bounces
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings_out = scene.render.image_settings
    settings_out.file_format = "OPEN_EXR"
    settings_out.color_depth = "32"
    settings_out.exr_codec = "ZIP"
    settings_out.color_mode = "RGB"


def apply_job(scene: bpy.types.Scene, job: dict) -> None:
    cycles = scene.cycles
    cycles.samples = int(job["samples"])
    cycles.use_adaptive_sampling = bool(job.get("adaptive", False))
    cycles.adaptive_threshold = float(job.get("adaptive_threshold", 0.01))
    cycles.adaptive_min_samples = 0  # automatic
    cycles.use_denoising = bool(job.get("denoise", False))
    if cycles.use_denoising:
        cycles.denoiser = "OPENIMAGEDENOISE"
        cycles.denoising_input_passes = "RGB_ALBEDO_NORMAL"
        cycles.denoising_prefilter = "ACCURATE"
    cycles.seed = int(job.get("seed", 0))


def main(argv: list[str]) -> int:
    interchange, jobs_path, out = Path(argv[0]), Path(argv[1]), Path(argv[2])
    jobs = json.loads(jobs_path.read_text(encoding="utf-8"))
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    document, soups = read_interchange(interchange)
    scene = build_scene(document, soups)
    configure(scene, jobs["settings"])
    timings = {"blender": bpy.app.version_string, "build_s": time.perf_counter() - t0, "jobs": {}}
    apply_job(scene, {"samples": 1})
    t0 = time.perf_counter()
    bpy.ops.render.render()  # warm-up: scene sync and BVH build, kept by use_persistent_data
    timings["warmup_s"] = time.perf_counter() - t0
    for job in jobs["jobs"]:
        apply_job(scene, job)
        t0 = time.perf_counter()
        bpy.ops.render.render()
        seconds = time.perf_counter() - t0
        path = out / f"{job['name']}.exr"
        bpy.data.images["Render Result"].save_render(str(path), scene=scene)
        timings["jobs"][job["name"]] = {"render_s": seconds, "path": str(path), **job}
        print(f"cycles: {job['name']}: {seconds:.2f} s", flush=True)
    (out / "cycles.json").write_text(json.dumps(timings, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
