"""The demo district's textured materials: which palette materials take which procedural image
(:mod:`synthua_usd.demo.textures`), at what size, projected how.

A textured material keeps its palette colour as its mean: the image's ``scale`` is the palette colour over
the image's own mean (linear), so a view from afar looks as before, and the palette (whose flat colours
the agents, the importers and the street demo use) stays the one owner of colours. Only the district's
copies of these materials are textured.

Projections (:mod:`synthua_usd.uv`): ``ground`` maps x, y straight down and keeps every point as it is; the
cobbles and pavers use it, since they are tens of thousands of boxes whose sides are a few centimetres
tall. ``box`` aligns the image to each face (walls upright at any heading), splitting points at the box's
edges. Neither moves a triangle, so the label maps are those of the untextured district.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from synthua_usd.demo.textures import decode_srgb8, district_images
from synthua_usd.scene import Texture
from synthua_usd.texture_images import texture_path
from synthua_usd.twin import TwinModel, TwinObject, TwinPart
from synthua_usd.uv import box_uvs, planar_uvs

#: Palette key → (image, metres per repeat of the image, projection).
TEXTURED: dict[str, tuple[str, float, str]] = {
    "Asphalt": ("asphalt", 4.0, "box"),
    **{k: ("stone", 1.5, "ground") for k in ("Cobble0", "Cobble1", "Cobble2")},
    **{k: ("stone", 2.0, "ground") for k in ("PaverLight", "PaverWarm", "PaverGrey")},
    "Granite": ("stone", 1.0, "box"),
    **{k: ("plaster", 2.5, "box") for k in ("Concrete", "RampConcrete", "Mortar")},
    **{k: ("plaster", 3.0, "box") for k in ("Stucco", "Whitewash", *(f"Wall{i}" for i in range(8)))},
    **{k: ("wood", 1.2, "box") for k in ("Wood", "DoorWood")},
}


def add_textures(model: TwinModel, seed: int) -> TwinModel:
    """``model`` with the materials of :data:`TEXTURED` textured, texture coordinates on their parts, and the
    images they use (made for ``seed``)."""
    images = district_images(seed)
    materials = dict(model.materials)
    used = set()
    for key, spec in model.materials.items():
        if key not in TEXTURED:
            continue
        name = TEXTURED[key][0]
        mean = decode_srgb8(images[name]).mean(axis=(0, 1))
        scale = np.asarray(spec.base_color, np.float64) / mean
        materials[key] = replace(spec, base_color_texture=Texture(texture_path(f"{name}.png"), color_space="sRGB",
                                                                  scale=(*scale.tolist(), 1.0)))
        used.add(name)
    objects = tuple(TwinObject(o.path, o.label, tuple(_mapped(p) for p in o.parts), o.attributes)
                    for o in model.objects)
    return replace(model, objects=objects, materials=materials,
                   images={texture_path(f"{name}.png"): images[name] for name in sorted(used)})


def _mapped(part: TwinPart) -> TwinPart:
    if part.material not in TEXTURED or len(part.triangles) == 0:
        return part
    _, tile_m, projection = TEXTURED[part.material]
    if projection == "ground":
        return part.with_mesh(part.points, part.triangles, planar_uvs(part.points, tile_m))
    return part.with_mesh(*box_uvs(part.points, part.triangles, tile_m))
