"""What a randomised person wears beyond colours, and the materials that show it: a fabric per garment with its
second colour, shoes on a sole of another colour, the face and the skin's clear coat (the ``looks`` part of the
``randomise`` block, :class:`synthua_usd.randomisation.config.LooksRandomisation`).

Plain data: :func:`draw_wardrobe` draws what a scene's people wear, :func:`draw_wear` what one of them picks;
:func:`garment_material`, :func:`shoes_material` and :func:`skin_material` are
:class:`synthua_usd.model.scene.Material` values whose textures are the shipped images of
:mod:`synthua_usd.assets.look_images` (masks between two colours, :func:`~synthua_usd.assets.look_images.two_colour`),
laid on the body by :mod:`synthua_usd.assets.garments`; the USD side authors them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd.assets.look_images import FACE_OFFSET, image_path, two_colour
from synthua_usd.model.materials import (CONTRAST_COLOURS, FABRIC_SHADE, FACE_FEATURES, SKIN_CLEARCOAT, SOLE_COLOURS,
                                        TROUSERS, UPPER_PALETTES)
from synthua_usd.model.materials import SHOES as SHOE_PALETTE
from synthua_usd.model.normal_maps import NORMAL_BIAS, NORMAL_SCALE
from synthua_usd.model.scene import Material, Texture
from synthua_usd.randomisation.config import LooksRandomisation

RGB = tuple[float, float, float]
#: Roughness of garments and of each kind of shoe (leather shoes are smoother than a sneaker's canvas).
FABRIC_ROUGHNESS = 0.85
SHOE_ROUGHNESS = {"sneaker": 0.6, "shoe": 0.4}
#: Skin: the base roughness under the clear coat (:data:`synthua_usd.model.materials.SKIN_CLEARCOAT`).
SKIN_ROUGHNESS = 0.5


def jitter(rng: np.random.Generator, rgb, amount: float) -> RGB:
    """``rgb`` with each channel scaled by 1 + U(-amount, amount) (hue and value both move a little), clipped
    to [0, 1]."""
    scale = 1.0 + rng.uniform(-amount, amount, 3)
    return tuple(float(v) for v in np.clip(np.asarray(rgb, float) * scale, 0.0, 1.0))


def pick(rng: np.random.Generator, palette):
    """An item of ``palette``, uniform (one integer of ``rng``)."""
    return palette[int(rng.integers(len(palette)))]


@dataclass(frozen=True)
class Garment:
    """One garment of a scene's wardrobe: its fabric (a name of :data:`synthua_usd.assets.look_images.FABRICS`), its
    colour and the fabric's second colour (linear Rec.709)."""

    fabric: str
    colour: RGB
    second: RGB


@dataclass(frozen=True)
class Shoes:
    """A pair of shoes of a scene's wardrobe: the kind (of :data:`~synthua_usd.assets.look_images.SHOES`), the
    upper's colour and the sole's."""

    kind: str
    colour: RGB
    sole: RGB


@dataclass(frozen=True)
class Wardrobe:
    """What the people of one scene wear: ``uppers`` and ``lowers`` (garments) and ``shoes``. People pick from it,
    so garments repeat across the crowd and their materials are shared: a crowd's distinct normal-mapped
    materials cost the renderer more than their pixels (docs/people.md)."""

    uppers: tuple[Garment, ...]
    lowers: tuple[Garment, ...]
    shoes: tuple[Shoes, ...]


@dataclass(frozen=True)
class Wear:
    """What one person wears: indices into the scene's :class:`Wardrobe` (``upper``, ``lower``, ``shoes``)."""

    upper: int
    lower: int
    shoes: int


def _second(fabric: str, colour, u: float) -> RGB:
    """The second colour of ``fabric`` on a garment of ``colour``: a contrasting palette colour (the one ``u`` picks,
    or the next when it is close to ``colour``) for stripes and checks, else a lighter shade of ``colour``."""
    colour = np.asarray(colour, float)
    if fabric in FABRIC_SHADE:
        return tuple(float(c) for c in np.clip(colour * FABRIC_SHADE[fabric] + 0.01, 0.0, 1.0))
    k = int(u * len(CONTRAST_COLOURS))
    for step in range(len(CONTRAST_COLOURS)):
        choice = np.asarray(CONTRAST_COLOURS[(k + step) % len(CONTRAST_COLOURS)], float)
        if np.linalg.norm(choice - colour) > 0.2:
            break
    return tuple(float(c) for c in choice)


def draw_wardrobe(rng: np.random.Generator, config: LooksRandomisation, colour_jitter: float) -> Wardrobe:
    """``config.wardrobe`` upper and lower garments and a third as many pairs of shoes (at least 2): each a fabric
    and kind uniform over the config's, a colour of its palette (the config's upper palette, trousers, shoes of
    :mod:`synthua_usd.model.materials`) with each channel scaled by 1 + U(-``colour_jitter``, ``colour_jitter``),
    a second colour for its fabric, a sole colour for its kind."""
    def garments(fabrics, palette) -> tuple[Garment, ...]:
        out = []
        for _ in range(config.wardrobe):
            fabric = pick(rng, fabrics)
            colour = jitter(rng, pick(rng, palette).base_color, colour_jitter)
            out.append(Garment(fabric, colour, _second(fabric, colour, float(rng.random()))))
        return tuple(out)

    uppers = garments(config.upper_fabrics, UPPER_PALETTES[config.palette])
    lowers = garments(config.lower_fabrics, TROUSERS)
    shoes = []
    for _ in range(max(2, config.wardrobe // 3)):
        kind = pick(rng, config.shoes)
        shoes.append(Shoes(kind, jitter(rng, pick(rng, SHOE_PALETTE).base_color, colour_jitter),
                           tuple(float(c) for c in pick(rng, SOLE_COLOURS[kind]))))
    return Wardrobe(uppers, lowers, tuple(shoes))


def draw_wear(rng: np.random.Generator, wardrobe: Wardrobe) -> Wear:
    """A person's picks from ``wardrobe``, uniform. Always three numbers of ``rng``."""
    u = rng.random(3)
    return Wear(int(u[0] * len(wardrobe.uppers)), int(u[1] * len(wardrobe.lowers)), int(u[2] * len(wardrobe.shoes)))


def masked_material(key: str, stem: str, c1, c2, roughness: float, offset: float = 0.0, wrap: str = "repeat",
                    normal: bool = True, **extra) -> Material:
    """A material showing the look image ``stem``'s mask between ``c1`` and ``c2`` (linear RGB), with its normal
    map unless ``normal`` is False."""
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
    return masked_material(key, "face", skin, FACE_FEATURES, SKIN_ROUGHNESS, offset=FACE_OFFSET, wrap="clamp", normal=False,
                   clearcoat=coat, clearcoat_roughness=coat_roughness)


def garment_material(key: str, garment: Garment) -> Material:
    """The material of ``garment``: its fabric's mask between its two colours, the fabric's normal map."""
    return masked_material(key, f"fabric_{garment.fabric}", garment.colour, garment.second, FABRIC_ROUGHNESS)


def shoes_material(key: str, shoes: Shoes) -> Material:
    """The material of ``shoes``: the shoe image's mask between the upper's and the sole's colour."""
    return masked_material(key, f"shoe_{shoes.kind}", shoes.colour, shoes.sole, SHOE_ROUGHNESS[shoes.kind])
