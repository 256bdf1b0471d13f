"""A scene snapshot and camera as plain files another renderer's interpreter can read (numpy and json only).

Blender Cycles runs in its own interpreter (PyPI ``bpy`` bundles its own USD and OpenImageIO, which clash
with ``usd-core`` in one process), so the scene crosses a process boundary as two files in a folder:

``geometry.npz``
    per soup k, ``points_{k}`` (n, 3) float32 world metres and ``triangles_{k}`` (m, 3) int32, and for a textured
    soup ``uvs_{k}`` (n, 2) float32 per point in USD's ``st`` convention ((0, 0) the image's bottom-left corner, t
    upwards: Blender's UV convention too). A soup is every mesh of one material merged (Cycles needs no per-gprim
    identity: it renders RGB only), split in two where some of its meshes have texture coordinates and some
    not: as in Mitsuba, a mesh without them renders the material's constants.
``scene.json``
    ``materials``, one entry per soup (key, index k, ``textured``, base colour linear Rec.709, roughness,
    metallic, emissive colour, ``textures``: per textured input (``base_color``, ``roughness``, ``metallic``,
    ``normal``) the image's absolute ``path``, ``channel``, ``color_space``, ``wrap_s``, ``wrap_t``, ``scale``,
    ``bias`` of :class:`synthua_usd.model.scene.Texture`; triangle count, what was not exported), ``lights`` (as
    :class:`synthua_usd.model.scene.Light`), ``camera`` (camera_to_world (4, 4) column vectors, looking down local -Z
    with +Y up as USD and Blender both do; the conformed horizontal field of view and aperture for the image
    size; clipping range), ``up_axis``, ``width``, ``height``.

This module imports nothing but numpy and the standard library: the Cycles script imports it to read
what :func:`write_interchange` wrote, so the format has one owner.
"""

from __future__ import annotations

import json
import os
from dataclasses import fields
from pathlib import Path

import numpy as np

GEOMETRY = "geometry.npz"
SCENE = "scene.json"
FORMAT_VERSION = 2
#: The textured inputs exported (the ``*_texture`` fields of :class:`synthua_usd.model.scene.Material`), by their name here.
EXPORTED_TEXTURES = {"base_color_texture": "base_color", "roughness_texture": "roughness",
                     "metallic_texture": "metallic", "normal_texture": "normal"}


def write_interchange(snapshot, camera, width: int, height: int, folder: str | Path) -> Path:
    """Write ``snapshot`` (a :class:`synthua_usd.model.scene.SceneSnapshot`) seen by ``camera`` (a
    :class:`synthua_usd.model.cameras.PinholeCamera`) at ``width`` x ``height`` into ``folder`` (created); returns it.

    Lens distortion is not exported (Cycles' perspective camera has none): a distorted camera is refused."""
    if camera.distortion is not None:
        raise ValueError(f"camera {camera.path}: lens distortion cannot be exported to Cycles; use an ideal pinhole")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    parts: dict[tuple[str, bool], list] = {}
    for mesh in snapshot.meshes:
        # as Mitsuba's translation decides: textures only where the mesh has texture coordinates
        textured = mesh.uvs is not None and bool(snapshot.materials[mesh.material_key].textures)
        parts.setdefault((mesh.material_key, textured), []).append(mesh)
    arrays, materials = {}, []
    for k, (key, textured) in enumerate(sorted(parts)):
        meshes = parts[(key, textured)]
        points, triangles, _ = snapshot.world_triangles(meshes)
        arrays[f"points_{k}"] = np.ascontiguousarray(points, np.float32)
        arrays[f"triangles_{k}"] = np.ascontiguousarray(triangles, np.int32)
        material = snapshot.materials[key]
        if textured:  # world_triangles concatenates the meshes' points in order: their uvs follow alike
            arrays[f"uvs_{k}"] = np.ascontiguousarray(np.concatenate([m.uvs for m in meshes]), np.float32)
        else:
            material = material.untextured()
        materials.append({"key": key, "index": k, "textured": textured,
                          "base_color": [float(c) for c in material.base_color],
                          "roughness": float(material.roughness), "metallic": float(material.metallic),
                          "emissive_color": [float(c) for c in material.emissive_color],
                          "textures": {EXPORTED_TEXTURES[name]: _texture(texture)
                                       for name, texture in material.textures.items() if name in EXPORTED_TEXTURES},
                          "triangles": int(len(triangles)), "meshes": len(meshes),
                          "not_exported": _not_exported(material)})
    fov_x, fov_y = camera.fov_deg(width, height)
    aperture_x, aperture_y = camera.conformed_aperture_mm(width, height)
    document = {
        "format": FORMAT_VERSION,
        "width": int(width), "height": int(height), "up_axis": snapshot.up_axis,
        "time_code": float(snapshot.time_code),
        "materials": materials,
        "lights": [{f.name: _plain(getattr(light, f.name)) for f in fields(light)} for light in snapshot.lights],
        "camera": {"path": camera.path, "camera_to_world": np.asarray(camera.camera_to_world).tolist(),
                   "fov_x_deg": fov_x, "fov_y_deg": fov_y, "focal_length_mm": camera.focal_length_mm,
                   "aperture_x_mm": aperture_x, "aperture_y_mm": aperture_y,
                   "clip_near_m": camera.clip_near_m, "clip_far_m": camera.clip_far_m},
    }
    np.savez(folder / GEOMETRY, **arrays)
    from synthua_usd.core import json_text  # here, not at the top: the Cycles script imports this module alone

    (folder / SCENE).write_text(json_text.dumps(document, indent=1, ascii_only=True) + "\n", encoding="utf-8")
    return folder


def read_interchange(folder: str | Path) -> tuple[dict, list[tuple[np.ndarray, np.ndarray, np.ndarray | None]]]:
    """(scene document, [(points (n, 3) float32, triangles (m, 3) int32, uvs (n, 2) float32 or None) per soup, in
    ``materials`` order])."""
    folder = Path(folder)
    document = json.loads((folder / SCENE).read_text(encoding="utf-8"))
    if document.get("format") != FORMAT_VERSION:
        raise ValueError(f"{folder / SCENE}: interchange format {document.get('format')!r}, expected {FORMAT_VERSION}")
    with np.load(folder / GEOMETRY) as data:
        soups = [(data[f"points_{m['index']}"], data[f"triangles_{m['index']}"],
                  data[f"uvs_{m['index']}"] if m["textured"] else None) for m in document["materials"]]
    return document, soups


def _not_exported(material) -> list[str]:
    """What of the material Cycles does not get (its opacity, constant or textured), so the comparison says so."""
    missing = [name for name in material.textures if name not in EXPORTED_TEXTURES]
    if material.opacity < 1.0 and material.opacity_texture is None:
        missing.append("opacity")
    return sorted(missing)


def _texture(texture) -> dict:
    """A :class:`synthua_usd.model.scene.Texture` as plain data, its image path absolute (a snapshot read from a stage
    holds absolute paths; a relative one is taken from the working directory, as Mitsuba's translation reads it)."""
    return {"path": os.path.abspath(texture.path), "channel": texture.channel, "color_space": texture.color_space,
            "wrap_s": texture.wrap_s, "wrap_t": texture.wrap_t,
            "scale": [float(v) for v in texture.scale], "bias": [float(v) for v in texture.bias]}


def _plain(value):
    return [float(v) for v in value] if isinstance(value, (tuple, list)) else value
