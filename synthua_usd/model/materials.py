"""The material palette: every named material synthua authors, in one place.

Procedural assets, the demo scenes, the agents and the importers all name materials by key; the twin and
agents writers author each key they use as a ``UsdPreviewSurface`` under ``/World/Looks`` (or the agents'
``Looks``). Colours are linear Rec.709 base colours, 0..1; roughness and metallic as in UsdPreviewSurface.
Importers that read materials from their input (OBJ/MTL, glTF) keep those; the rest take the material
of each class from :data:`CLASS_MATERIAL`.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.model.scene import Material
from synthua_usd.model.srgb import to_linear

WALL_COLOURS = [(0.62, 0.42, 0.2), (0.22, 0.35, 0.55), (0.6, 0.55, 0.45), (0.55, 0.2, 0.15), (0.35, 0.5, 0.3),
                (0.7, 0.62, 0.35), (0.45, 0.3, 0.45), (0.75, 0.72, 0.66)]

#: Skin tones: the ten swatches of the Monk Skin Tone scale (Monk 2019; Google 2022), lightest first, sRGB
#: hex decoded to linear; skin is slightly rough and non-metallic.
MONK_SKIN_TONES = ("f6ede4", "f3e7db", "f7ead0", "eadaba", "d7bd96", "a07e56", "825c43", "604134", "3a312a", "292420")
SKINS = tuple(Material(f"Skin{i}", tuple(float(c) for c in to_linear(np.array([int(h[k:k + 2], 16) / 255 for k in (0, 2, 4)]))), 0.6)
              for i, h in enumerate(MONK_SKIN_TONES))
SHIRTS = tuple(Material(f"Shirt{i}", c, 0.85) for i, c in enumerate(
    [(0.5, 0.06, 0.05), (0.05, 0.15, 0.45), (0.12, 0.35, 0.15), (0.7, 0.6, 0.1), (0.6, 0.6, 0.6), (0.05, 0.05, 0.05),
     (0.45, 0.15, 0.4), (0.8, 0.35, 0.1)]))
#: Upper garments in the colours most street clothing has: black, charcoal, greys, off-white, navy, dark green,
#: brown, beige, burgundy, denim blue, and one red (a wardrobe's ``street`` palette; SHIRTS is ``bright``).
STREET_SHIRTS = tuple(Material(f"StreetShirt{i}", c, 0.85) for i, c in enumerate(
    [(0.02, 0.02, 0.02), (0.07, 0.07, 0.07), (0.25, 0.25, 0.25), (0.55, 0.55, 0.53), (0.75, 0.74, 0.7),
     (0.03, 0.05, 0.14), (0.05, 0.1, 0.06), (0.12, 0.07, 0.04), (0.45, 0.38, 0.28), (0.2, 0.03, 0.04),
     (0.1, 0.18, 0.35), (0.5, 0.06, 0.05)]))
#: The palettes a wardrobe's upper garments can take their colours from (``randomise.looks.palette``).
UPPER_PALETTES = {"bright": SHIRTS, "street": STREET_SHIRTS}
TROUSERS = tuple(Material(f"Trousers{i}", c, 0.85) for i, c in enumerate(
    [(0.07, 0.08, 0.12), (0.15, 0.2, 0.35), (0.25, 0.2, 0.15), (0.3, 0.3, 0.3), (0.04, 0.04, 0.04), (0.35, 0.28, 0.18),
     (0.4, 0.08, 0.1)]))
SHOES = tuple(Material(f"Shoes{i}", c, 0.5) for i, c in enumerate(
    [(0.02, 0.02, 0.02), (0.15, 0.08, 0.04), (0.7, 0.7, 0.68), (0.05, 0.07, 0.15)]))

PALETTE: dict[str, Material] = {m.key: m for m in [
    # Ground: roads, sidewalks, kerbs, ramps, paint, cobbles and pavers.
    Material("Asphalt", (0.045, 0.045, 0.05), 0.9), Material("Concrete", (0.36, 0.35, 0.33), 0.85),
    Material("Granite", (0.48, 0.47, 0.46), 0.7), Material("RampConcrete", (0.55, 0.42, 0.22), 0.8),
    Material("RoadPaint", (0.8, 0.8, 0.78), 0.6), Material("Mortar", (0.12, 0.11, 0.1), 0.95),
    Material("Cobble0", (0.2, 0.19, 0.18), 0.75), Material("Cobble1", (0.28, 0.26, 0.23), 0.75),
    Material("Cobble2", (0.16, 0.16, 0.17), 0.7), Material("PaverLight", (0.55, 0.53, 0.5), 0.8),
    Material("PaverWarm", (0.45, 0.41, 0.35), 0.8), Material("PaverGrey", (0.33, 0.32, 0.31), 0.8),
    Material("Grass", (0.1, 0.28, 0.05), 0.95),
    # Buildings.
    Material("Stucco", (0.8, 0.78, 0.72), 0.9), Material("Whitewash", (0.85, 0.84, 0.8), 0.9),
    Material("RoofTile", (0.35, 0.12, 0.07), 0.8), Material("Glass", (0.04, 0.06, 0.08), 0.15),
    Material("DoorWood", (0.25, 0.12, 0.05), 0.7), Material("Wood", (0.35, 0.2, 0.08), 0.7),
    Material("Mural0", (0.1, 0.35, 0.6), 0.8), Material("Mural1", (0.7, 0.25, 0.4), 0.8),
    Material("Mural2", (0.8, 0.6, 0.1), 0.8),
    # Street furniture, signs and lamps.
    Material("Iron", (0.06, 0.06, 0.065), 0.5, metallic=0.8), Material("Metal", (0.3, 0.3, 0.32), 0.35, metallic=0.9),
    Material("LampGlass", (0.9, 0.88, 0.8), 0.3),
    Material("SignRed", (0.6, 0.03, 0.03), 0.5), Material("SignBlue", (0.03, 0.12, 0.5), 0.5),
    # Mobility aids.
    Material("Tyre", (0.02, 0.02, 0.02), 0.9), Material("Seat", (0.03, 0.05, 0.15), 0.8),
    Material("Frame", (0.55, 0.57, 0.6), 0.3, metallic=0.9), Material("CaneWhite", (0.85, 0.85, 0.85), 0.4),
    Material("CaneRed", (0.6, 0.03, 0.03), 0.4),
    # Vehicles.
    Material("PaintRed", (0.45, 0.03, 0.03), 0.3, metallic=0.3), Material("PaintBlue", (0.03, 0.1, 0.4), 0.3, metallic=0.3),
    Material("PaintBlack", (0.02, 0.02, 0.02), 0.3, metallic=0.3),
    Material("PaintWhite", (0.75, 0.75, 0.75), 0.3, metallic=0.3),
    Material("PaintSilver", (0.45, 0.46, 0.48), 0.3, metallic=0.6), Material("PaintOrange", (0.7, 0.25, 0.02), 0.4),
    Material("HeadLamp", (0.85, 0.85, 0.82), 0.1), Material("TailLamp", (0.5, 0.02, 0.02), 0.2),
    # Market.
    Material("CanvasWhite", (0.8, 0.8, 0.78), 0.9), Material("CanvasRed", (0.55, 0.06, 0.05), 0.9),
    Material("CanvasBlue", (0.06, 0.15, 0.5), 0.9), Material("CanvasYellow", (0.75, 0.55, 0.05), 0.9),
    Material("Goods", (0.5, 0.3, 0.15), 0.8), Material("PlasticWhite", (0.8, 0.8, 0.8), 0.5),
    # Nature and animals.
    Material("Bark", (0.18, 0.11, 0.06), 0.9), Material("Leaves", (0.07, 0.2, 0.04), 0.8),
    Material("Fur", (0.35, 0.22, 0.1), 0.9), Material("Feathers", (0.35, 0.36, 0.4), 0.8),
    # Imported geometry without materials of its own.
    Material("Roof", (0.35, 0.15, 0.1), 0.8), Material("Neutral", (0.3, 0.3, 0.3), 0.8),
    Material("Soil", (0.22, 0.18, 0.13), 0.95),
] + [Material(f"Wall{i}", c, 0.9) for i, c in enumerate(WALL_COLOURS)] + list(SKINS + SHIRTS + TROUSERS + SHOES)}

#: The palette key importers give each class when the input carries no material; classes not listed
#: take ``Neutral``.
CLASS_MATERIAL = {
    "building": "Wall2", "roof": "Roof", "road": "Asphalt", "street_road": "Cobble1", "sidewalk": "Concrete",
    "crosswalk": "RoadPaint", "curb_ramp": "RampConcrete", "vegetation": "Leaves", "grass": "Grass",
    "window": "Glass", "door": "DoorWood", "furniture": "Wood", "terrain": "Soil",
}


def material(key: str) -> Material:
    """The palette entry ``key``; a KeyError names the known keys."""
    try:
        return PALETTE[key]
    except KeyError:
        raise KeyError(f"material '{key}' is not in the palette; known: {', '.join(sorted(PALETTE))}") from None


def class_material(class_name: str) -> Material:
    """The material importers give geometry of ``class_name`` that has none of its own."""
    return PALETTE[CLASS_MATERIAL.get(class_name, "Neutral")]


def subset(keys) -> dict[str, Material]:
    """The palette entries for ``keys`` (a twin's ``materials``), sorted by key."""
    return {k: material(k) for k in sorted(set(keys))}


# --- palettes of scene randomisation (synthua_usd.randomisation) ------------------------------------------
# Linear Rec.709 base colours. Façades: lime washes and paints of colonial and 20th-century row houses (ochre,
# terracotta, blue, green, cream, white, pink, grey); car paints in rough proportion to the world's car colours
# (white, black, grey, silver most often); canvases, umbrellas and stands; door paints and woods; mural paints.
FACADE_COLOURS = (*WALL_COLOURS, (0.8, 0.62, 0.3), (0.72, 0.36, 0.22), (0.3, 0.45, 0.62), (0.55, 0.65, 0.5),
                  (0.85, 0.8, 0.65), (0.82, 0.82, 0.8), (0.8, 0.55, 0.55), (0.5, 0.5, 0.52), (0.62, 0.3, 0.3))
CAR_PAINTS = ((0.75, 0.75, 0.75), (0.75, 0.75, 0.75), (0.02, 0.02, 0.02), (0.02, 0.02, 0.02), (0.25, 0.25, 0.26),
              (0.45, 0.46, 0.48), (0.45, 0.46, 0.48), (0.45, 0.03, 0.03), (0.03, 0.1, 0.4), (0.05, 0.2, 0.08),
              (0.45, 0.38, 0.25), (0.7, 0.25, 0.02))
CANVAS_COLOURS = ((0.8, 0.8, 0.78), (0.55, 0.06, 0.05), (0.06, 0.15, 0.5), (0.75, 0.55, 0.05), (0.1, 0.35, 0.12),
                  (0.6, 0.25, 0.05), (0.45, 0.1, 0.35), (0.3, 0.3, 0.3))
WOOD_COLOURS = ((0.35, 0.2, 0.08), (0.25, 0.12, 0.05), (0.45, 0.3, 0.15), (0.18, 0.1, 0.05), (0.5, 0.38, 0.22))
DOOR_COLOURS = (*WOOD_COLOURS, (0.05, 0.2, 0.1), (0.05, 0.1, 0.3), (0.5, 0.05, 0.05), (0.8, 0.8, 0.78))
MURAL_COLOURS = ((0.1, 0.35, 0.6), (0.7, 0.25, 0.4), (0.8, 0.6, 0.1), (0.2, 0.55, 0.25), (0.75, 0.3, 0.1),
                 (0.4, 0.2, 0.6))
#: Ground materials keep their hue: a grey or a warm or cool stone, as multipliers of the material's own colour
#: or texture (road wear and paving lots).
GROUND_TINTS = ((1.0, 1.0, 1.0), (1.12, 1.05, 0.95), (0.92, 0.96, 1.05), (0.8, 0.8, 0.8), (1.25, 1.22, 1.18),
                (1.05, 0.98, 0.9))

#: Class -> ("colour", palette) for a new base colour, or ("tint", tints) for a multiplier of the material's own
#: colour or texture. Classes not listed keep their materials.
RECOLOUR_PALETTES = {
    "building": ("colour", FACADE_COLOURS), "mural": ("colour", MURAL_COLOURS), "door": ("colour", DOOR_COLOURS),
    "car": ("colour", CAR_PAINTS), "bus": ("colour", CAR_PAINTS), "motorcycle": ("colour", CAR_PAINTS),
    "bicycle": ("colour", CAR_PAINTS), "tent": ("colour", CANVAS_COLOURS), "umbrella": ("colour", CANVAS_COLOURS),
    "stand": ("colour", WOOD_COLOURS), "road": ("tint", GROUND_TINTS), "street_road": ("tint", GROUND_TINTS),
    "sidewalk": ("tint", GROUND_TINTS), "crosswalk": ("tint", GROUND_TINTS),
}

#: Mobility-aid frames: (base colour palette or None for the fixed colour, roughness, metallic) per finish.
DEVICE_FINISHES = {
    "painted_metal": (((0.45, 0.03, 0.03), (0.03, 0.1, 0.4), (0.02, 0.02, 0.02), (0.45, 0.46, 0.48), (0.05, 0.2, 0.08),
                       (0.6, 0.3, 0.02), (0.3, 0.05, 0.3)), 0.35, 0.0),
    "chrome": (((0.62, 0.62, 0.64),), 0.08, 1.0),
    "anodised": (((0.5, 0.05, 0.05), (0.05, 0.15, 0.5), (0.1, 0.1, 0.12), (0.4, 0.4, 0.42), (0.35, 0.1, 0.4)), 0.25, 0.85),
    "matte_black": (((0.025, 0.025, 0.028),), 0.75, 0.0),
}
#: Seat and backrest fabrics of wheelchairs (and the detailed chairs' armrest pads and clothing guards): black
#: nylon or vinyl in five draws of nine, as on most chairs, else charcoal, navy, red or brown.
SEAT_FABRICS = ((0.02, 0.02, 0.02),) * 5 + ((0.08, 0.08, 0.085), (0.03, 0.05, 0.15), (0.3, 0.04, 0.04),
                                            (0.25, 0.18, 0.1))
#: Natural hair colours, linear Rec.709 base colour: name -> (colour, roughness). Grey is drawn more with age
#: (:func:`synthua_usd.randomisation.scene.draw_hair`).
HAIR_COLOURS = {
    "black": ((0.012, 0.009, 0.008), 0.5), "dark_brown": ((0.035, 0.02, 0.012), 0.55),
    "brown": ((0.09, 0.05, 0.025), 0.55), "light_brown": ((0.2, 0.12, 0.06), 0.55),
    "blonde": ((0.42, 0.3, 0.15), 0.6), "auburn": ((0.2, 0.06, 0.025), 0.55), "grey": ((0.32, 0.31, 0.3), 0.6),
}
#: Fabrics whose second colour is a lighter shade of the garment's (its colour times this, plus 0.01, clipped):
#: a knit's heather, a melange's light fibres, a twill's and a corduroy's lighter crowns, denim's faded white weft.
#: The others (stripes, checks) take a contrasting colour of :data:`CONTRAST_COLOURS`.
FABRIC_SHADE = {"jersey": 1.2, "melange": 1.7, "twill": 1.35, "denim": 2.4, "corduroy": 1.6}
CONTRAST_COLOURS = ((0.8, 0.8, 0.78), (0.02, 0.02, 0.02), (0.05, 0.15, 0.45), (0.5, 0.06, 0.05), (0.7, 0.6, 0.1),
                    (0.12, 0.35, 0.15), (0.6, 0.6, 0.6), (0.45, 0.15, 0.4))
#: Sole colours per kind of shoe: a sneaker's white, black, gum or grey rubber; a shoe's black or brown leather.
SOLE_COLOURS = {"sneaker": ((0.78, 0.78, 0.76), (0.02, 0.02, 0.02), (0.32, 0.2, 0.1), (0.5, 0.5, 0.5)),
                "shoe": ((0.02, 0.02, 0.02), (0.15, 0.08, 0.04))}
#: The face image's dark colour (irises, lash lines, brows, nostrils; lips and blush part way towards it).
FACE_FEATURES = (0.025, 0.015, 0.01)
#: Skin's clear coat: (weight, roughness) of UsdPreviewSurface's clearcoat over the skin's base (an oily sheen).
SKIN_CLEARCOAT = (0.3, 0.35)

