"""What a randomised person wears beyond colours, and the materials that show it: a fabric per garment with its
second colour, shoes on a sole of another colour, the face and the skin's clear coat (the ``looks`` part of the
``randomise`` block, :class:`synthua_usd.randomisation.config.LooksRandomisation`).

Plain data: :func:`draw_wear` draws a :class:`Wear`, :func:`wear_materials` turns a person's colours and wear into
:class:`synthua_usd.model.scene.Material` values whose textures are the shipped images of
:mod:`synthua_usd.assets.look_images` (masks between two colours, :func:`~synthua_usd.assets.look_images.two_colour`),
laid on the body by :mod:`synthua_usd.assets.garments`; the USD side authors them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd.assets.look_images import FACE_OFFSET, image_path, two_colour
from synthua_usd.model.materials import CONTRAST_COLOURS, FABRIC_SHADE, FACE_FEATURES, SKIN_CLEARCOAT, SOLE_COLOURS
from synthua_usd.model.normal_maps import NORMAL_BIAS, NORMAL_SCALE
from synthua_usd.model.scene import Material, Texture
from synthua_usd.randomisation.config import LooksRandomisation

RGB = tuple[float, float, float]
#: Roughness of garments and of each kind of shoe (leather shoes are smoother than a sneaker's canvas).
FABRIC_ROUGHNESS = 0.85
SHOE_ROUGHNESS = {"sneaker": 0.6, "shoe": 0.4}
#: Skin: the base roughness under the clear coat (:data:`synthua_usd.model.materials.SKIN_CLEARCOAT`).
SKIN_ROUGHNESS = 0.5


@dataclass(frozen=True)
class Wear:
    """A person's fabrics (names of :data:`synthua_usd.assets.look_images.FABRICS`) of the upper and lower garment
    with their second colours, the kind of shoes (of :data:`~synthua_usd.assets.look_images.SHOES`) and the sole's
    colour; colours linear Rec.709."""

    upper_fabric: str
    upper_second: RGB
    lower_fabric: str
    lower_second: RGB
    shoes: str
    sole: RGB


def _second(fabric: str, colour, u: float) -> RGB:
    """The second colour of ``fabric`` on a garment of ``colour``: a contrasting palette colour (the one ``u`` picks,
    or the next when it is close to ``colour``) for stripes and checks, else a lighter shade of ``colour``."""
    colour = np.asarray(colour, float)
    if fabric in FABRIC_SHADE:
        return tuple(float(c) for c in np.clip(colour * FABRIC_SHADE[fabric] + 0.01, 0.0, 1.0))
    k = int(u * len(CONTRAST_COLOURS))
    for step in range(len(CONTRAST_COLOURS)):
        pick = np.asarray(CONTRAST_COLOURS[(k + step) % len(CONTRAST_COLOURS)], float)
        if np.linalg.norm(pick - colour) > 0.2:
            break
    return tuple(float(c) for c in pick)


def draw_wear(rng: np.random.Generator, upper, lower, config: LooksRandomisation) -> Wear:
    """The wear of a person whose garments are ``upper`` and ``lower`` (RGB): fabrics, shoes and sole uniform over
    the config's choices and their palettes. Always six numbers of ``rng``, whatever is drawn."""
    u = rng.random(6)
    upper_fabric = config.upper_fabrics[int(u[0] * len(config.upper_fabrics))]
    lower_fabric = config.lower_fabrics[int(u[1] * len(config.lower_fabrics))]
    shoes = config.shoes[int(u[2] * len(config.shoes))]
    soles = SOLE_COLOURS[shoes]
    return Wear(upper_fabric, _second(upper_fabric, upper, u[3]), lower_fabric, _second(lower_fabric, lower, u[4]),
                shoes, tuple(float(c) for c in soles[int(u[5] * len(soles))]))


def _masked(key: str, stem: str, c1, c2, roughness: float, offset: float = 0.0, wrap: str = "repeat",
            normal: bool = True, **extra) -> Material:
    scale, bias = two_colour(c1, c2, offset)
    base = Texture(str(image_path(stem)), color_space="raw", wrap_s=wrap, wrap_t=wrap, scale=scale, bias=bias)
    normals = Texture(str(image_path(f"{stem}_normal")), color_space="raw", scale=NORMAL_SCALE,
                      bias=NORMAL_BIAS) if normal else None
    return Material(key, tuple(float(c) for c in c1), roughness, base_color_texture=base, normal_texture=normals,
                    **extra)


def skin_material(key: str, skin) -> Material:
    """The skin of tone ``skin`` (RGB) with the face image (clamped: plain skin wherever the face is not) and a
    clear coat."""
    coat, coat_roughness = SKIN_CLEARCOAT
    return _masked(key, "face", skin, FACE_FEATURES, SKIN_ROUGHNESS, offset=FACE_OFFSET, wrap="clamp", normal=False,
                   clearcoat=coat, clearcoat_roughness=coat_roughness)


def wear_materials(prefix: str, upper, lower, shoes, wear: Wear) -> dict[str, Material]:
    """The materials of a person's upper and lower garment and shoes (colours ``upper``, ``lower``, ``shoes``) in
    ``wear``, keyed ``<prefix>_Upper``, ``_Lower``, ``_Shoes``, by region name (``upper``, ``lower``, ``shoes``)."""
    return {"upper": _masked(f"{prefix}_Upper", f"fabric_{wear.upper_fabric}", upper, wear.upper_second,
                             FABRIC_ROUGHNESS),
            "lower": _masked(f"{prefix}_Lower", f"fabric_{wear.lower_fabric}", lower, wear.lower_second,
                             FABRIC_ROUGHNESS),
            "shoes": _masked(f"{prefix}_Shoes", f"shoe_{wear.shoes}", shoes, wear.sole, SHOE_ROUGHNESS[wear.shoes])}
