"""A scene snapshot and camera as plain files another renderer's interpreter can read (numpy and json only).

Blender Cycles runs in its own interpreter (PyPI ``bpy`` bundles its own USD and OpenImageIO, which clash
with ``usd-core`` in one process), so the scene crosses a process boundary as two files in a folder:

``geometry.npz``
    per material, ``points_{k}`` (n, 3) float32 world metres and ``triangles_{k}`` (m, 3) int32: every mesh of
    that material merged into one triangle soup (Cycles needs no per-gprim identity: it renders RGB only).
``scene.json``
    ``materials`` (key, index k, base colour linear Rec.709, roughness, metallic, emissive colour, triangle
    count, what was not exported), ``lights`` (as :class:`synthua_usd.scene.Light`), ``camera`` (camera_to_world
    (4, 4) column vectors, looking down local -Z with +Y up as USD and Blender both do; the conformed horizontal
    field of view and aperture for the image size; clipping range), ``up_axis``, ``width``, ``height``.

This module imports nothing but numpy and the standard library: the Cycles script imports it to read
what :func:`write_interchange` wrote, so the format has one owner.
"""

from __future__ import annotations

import json
from dataclasses import fields
from pathlib import Path

import numpy as np

GEOMETRY = "geometry.npz"
SCENE = "scene.json"
FORMAT_VERSION = 1


def write_interchange(snapshot, camera, width: int, height: int, folder: str | Path) -> Path:
    """Write ``snapshot`` (a :class:`synthua_usd.scene.SceneSnapshot`) seen by ``camera`` (a
    :class:`synthua_usd.cameras.PinholeCamera`) at ``width`` x ``height`` into ``folder`` (created); returns it.

    Lens distortion is not exported (Cycles' perspective camera has none): a distorted camera is refused."""
    if camera.distortion is not None:
        raise ValueError(f"camera {camera.path}: lens distortion cannot be exported to Cycles; use an ideal pinhole")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    by_material: dict[str, list] = {}
    for mesh in snapshot.meshes:
        by_material.setdefault(mesh.material_key, []).append(mesh)
    arrays, materials = {}, []
    for k, key in enumerate(sorted(by_material)):
        points, triangles, _ = snapshot.world_triangles(by_material[key])
        arrays[f"points_{k}"] = np.ascontiguousarray(points, np.float32)
        arrays[f"triangles_{k}"] = np.ascontiguousarray(triangles, np.int32)
        material = snapshot.materials[key]
        materials.append({"key": key, "index": k,
                          "base_color": [float(c) for c in material.base_color],
                          "roughness": float(material.roughness), "metallic": float(material.metallic),
                          "emissive_color": [float(c) for c in material.emissive_color],
                          "triangles": int(len(triangles)), "meshes": len(by_material[key]),
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
    (folder / SCENE).write_text(json.dumps(document, indent=1) + "\n", encoding="utf-8")
    return folder


def read_interchange(folder: str | Path) -> tuple[dict, list[tuple[np.ndarray, np.ndarray]]]:
    """(scene document, [(points (n, 3) float32, triangles (m, 3) int32) per material, in ``materials`` order])."""
    folder = Path(folder)
    document = json.loads((folder / SCENE).read_text(encoding="utf-8"))
    if document.get("format") != FORMAT_VERSION:
        raise ValueError(f"{folder / SCENE}: interchange format {document.get('format')!r}, expected {FORMAT_VERSION}")
    with np.load(folder / GEOMETRY) as data:
        soups = [(data[f"points_{m['index']}"], data[f"triangles_{m['index']}"]) for m in document["materials"]]
    return document, soups


def _not_exported(material) -> list[str]:
    """Names of the material's fields beyond the constants exported here (its textures, opacity), so the
    comparison says what Cycles did not get."""
    exported = {"key", "base_color", "roughness", "metallic", "emissive_color"}
    return sorted(f.name for f in fields(material) if f.name not in exported and getattr(material, f.name))


def _plain(value):
    return [float(v) for v in value] if isinstance(value, (tuple, list)) else value
