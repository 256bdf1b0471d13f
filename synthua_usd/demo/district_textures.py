"""The demo district's textured materials: which palette materials take which procedural image
(:mod:`synthua_usd.demo.textures`), at what size, projected how.

A textured material keeps its palette colour as its mean: the image's ``scale`` is the palette colour over
the image's own mean (linear), so a view from afar looks as before, and the palette (whose flat colours
the agents, the importers and the street demo use) stays the one owner of colours. Only the district's
copies of these materials are textured.

The cobbled street's setts and the largo's pavers are images too (:data:`PAVED`, :func:`textures.paving`):
a flat surface whose colour image holds stones of the palette's shades in running bond with joints, and
whose normal map rounds their edges.

Projections (:mod:`synthua_usd.geometry.uv`): ``ground`` maps x, y straight down and keeps every point as it is; the
paving uses it (the sides of its slabs are a few centimetres tall). ``box`` aligns the image to each face (walls upright at any heading), splitting points at the box's
edges. Neither moves a triangle, so the label maps are those of the untextured district.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from synthua_usd.core.texture_images import texture_path
from synthua_usd.demo.textures import SIZE, district_images, paving
from synthua_usd.model.normal_maps import NORMAL_BIAS, NORMAL_SCALE, encode_normals8
from synthua_usd.model.srgb import decode_srgb8, encode_srgb8
from synthua_usd.geometry.uv import box_uvs, planar_uvs
from synthua_usd.model.materials import PALETTE
from synthua_usd.model.scene import Texture
from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart

#: Palette key → (image, metres per repeat of the image, projection).
TEXTURED: dict[str, tuple[str, float, str]] = {
    "Asphalt": ("asphalt", 4.0, "box"),
    "Cobble0": ("setts", 2.16, "ground"),
    "PaverWarm": ("pavers", 2.8, "ground"),
    "Granite": ("stone", 1.0, "box"),
    **{k: ("plaster", 2.5, "box") for k in ("Concrete", "RampConcrete", "Mortar")},
    **{k: ("plaster", 3.0, "box") for k in ("Stucco", "Whitewash", *(f"Wall{i}" for i in range(8)))},
    **{k: ("wood", 1.2, "box") for k in ("Wood", "DoorWood")},
}


@dataclass(frozen=True)
class Paving:
    """Stones in running bond on a tile of :data:`TEXTURED`'s size (see :func:`textures.paving`): ``stones`` per
    row, ``rows`` rows, joints ``joint_m`` wide and ``depth_m`` deep, edges rounded over ``bevel_m``, each stone
    of one of the palette colours ``shades`` (relative to one another: the material's own colour is the image's
    mean), joints of the palette colour ``joint``."""

    stones: int
    rows: int
    joint_m: float
    bevel_m: float
    depth_m: float
    shades: tuple[str, ...]
    joint: str


#: Image name → its stones: setts of 18 x 13.5 cm with 1.5 cm joints up the cobbled street, pavers of 35 cm
#: with 2 cm joints on the largo, each in three shades (a tile of 192 and of 64 stones).
PAVED: dict[str, Paving] = {
    "setts": Paving(12, 16, 0.015, 0.02, 0.02, ("Cobble0", "Cobble1", "Cobble2"), "Mortar"),
    "pavers": Paving(8, 8, 0.02, 0.015, 0.012, ("PaverLight", "PaverWarm", "PaverGrey"), "Mortar"),
}


def paving_images(seed: int, size: int = SIZE) -> dict[str, np.ndarray]:
    """The :data:`PAVED` images for ``seed`` as 8-bit pixels: ``NAME`` (sRGB colour, around linear 0.4 as the
    other images) and ``NAME_normal`` (:func:`textures.encode_normals8`)."""
    rng = np.random.default_rng([seed, 0x9A7E])
    tiles = {image: tile_m for image, tile_m, _ in TEXTURED.values()}
    out = {}
    for name, p in PAVED.items():
        base = np.mean([PALETTE[k].base_color for k in p.shades], axis=0)
        shades = np.array([PALETTE[k].base_color for k in p.shades]) / base
        colour, normals = paving(rng, size, tiles[name], p.stones, p.rows, p.joint_m, p.bevel_m, p.depth_m,
                                 shades, np.asarray(PALETTE[p.joint].base_color) / base)
        out[name] = encode_srgb8(0.4 * colour)
        out[f"{name}_normal"] = encode_normals8(normals)
    return out


def add_textures(model: TwinModel, seed: int) -> TwinModel:
    """``model`` with the materials of :data:`TEXTURED` textured (the paving ones normal-mapped too), texture
    coordinates on their parts, and the images they use (made for ``seed``)."""
    images = {**district_images(seed), **paving_images(seed)}
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
        if name in PAVED:
            materials[key] = replace(materials[key], normal_texture=Texture(
                texture_path(f"{name}_normal.png"), color_space="raw", scale=NORMAL_SCALE, bias=NORMAL_BIAS))
            used.add(f"{name}_normal")
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
