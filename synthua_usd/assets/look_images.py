"""The images people wear, made from a seeded numpy Generator and shipped in the package
(``assets/data/looks/``, rebuilt by ``python tools/build_look_images.py``): fabric patterns with their folds,
shoes with their soles, and the face.

Each colour image is a **mask** between two colours, not a colour: a material shows ``c1 + m (c2 - c1)`` per
channel, which UsdPreviewSurface's UsdUVTexture gives as ``scale = c2 - c1``, ``bias = c1`` on a ``raw`` image
(:func:`two_colour`). So one image serves every garment colour, a stripe or a check in a second colour, a shoe of
any colour on a sole of another, and a face of any skin tone. Images are 8-bit RGB, :data:`SIZE` pixels square,
on the surfaces as :mod:`synthua_usd.assets.garments` maps them:

* **Fabrics** (:data:`FABRICS`, a repeat every :data:`garments.FABRIC_TILE_M`, tileable): the mask (heather,
  stripes, checks, twill, wales) and a normal map of the weave or knit plus **folds**: horizontal wrinkles
  across the limbs and torso (4-8 cm apart, up to ~4 mm deep, in patches) and a few diagonal drape folds.
* **Shoes** (:data:`SHOES`, :data:`garments.SHOE_TILE_M` high from the ground): the sole's band (the second
  colour) with its welt, the upper (the first), stitching; a normal map of the sole's edge and the upper's creases.
* **Face** (:data:`FACE`, :data:`garments.FACE_SPAN_M` square around the eyes, clamped: its edge is plain skin):
  per channel, eyes (brighter whites, dark iris and lash line), brows, nostrils, lips (redder: their red channel
  darkens less), a blush on the cheeks. Its mask stores ``(m + 0.5) / 1.5`` so that ``m`` may go below 0 (the
  whites of the eyes, lighter than skin): :data:`FACE_OFFSET` and :func:`two_colour`'s ``offset`` undo it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import ndimage

from synthua_usd.assets.garments import EYE_HALF_SPACING_M, EYE_TO_NOSE_M, FABRIC_TILE_M, FACE_SPAN_M, SHOE_TILE_M
from synthua_usd.model.normal_maps import encode_normals8, height_normals

SIZE = 256
LOOKS_DIR = Path(__file__).parent / "data" / "looks"
#: The face mask's stored values are (m + FACE_OFFSET) / (1 + FACE_OFFSET): m = 0 (skin) is stored as 1/3.
FACE_OFFSET = 0.5
#: Upper-garment and lower-garment fabrics (names of :data:`FABRICS`).
UPPER_FABRICS = ("jersey", "melange", "stripes", "check", "twill")
LOWER_FABRICS = ("denim", "twill", "corduroy", "jersey")
#: Every image's seed: the shipped files are what :func:`look_images` makes from it.
SEED = 0x10C5


def _noise(rng: np.random.Generator, shape: tuple[int, int], sigma) -> np.ndarray:
    """Tileable smooth noise of feature size ``sigma`` texels (scalar or (rows, cols)), zero mean, unit SD."""
    field = ndimage.gaussian_filter(rng.standard_normal(shape), sigma, mode="wrap")
    return (field - field.mean()) / max(float(field.std()), 1e-12)


def _grid(size: int) -> tuple[np.ndarray, np.ndarray]:
    """(s, t) of every texel centre in [0, 1), (size, size) each: s along columns, t up (row 0 is t near 1)."""
    s = (np.arange(size) + 0.5) / size
    t = 1.0 - (np.arange(size) + 0.5) / size
    return np.broadcast_to(s[None, :], (size, size)), np.broadcast_to(t[:, None], (size, size))


def _bands(u: np.ndarray, count: int, duty: float, soft: float = 0.004) -> np.ndarray:
    """1 inside ``count`` bands per unit of ``u`` each ``duty`` of its period wide, 0 between, edges eased over
    ``soft`` of a unit (tileable when ``u`` runs over whole units; no edge on the image's own edge)."""
    phase = (u * count + 0.5 * (1.0 - duty)) % 1.0
    edge = soft * count
    return np.clip(np.minimum(phase, duty - phase) / max(edge, 1e-9) + 0.5, 0.0, 1.0) * (phase < duty + edge)


def folds(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    """(size, size) metres of fold height on a fabric tile: horizontal wrinkles (4-8 per tile, bent by a smooth
    drift, deeper in patches) and diagonal drape folds; tileable."""
    s, t = _grid(size)
    height = np.zeros((size, size))
    for cycles in (4, 6, 8):
        drift = 0.08 * _noise(rng, (size, size), (size / 3, size / 5))
        patches = np.clip(0.5 + 0.5 * _noise(rng, (size, size), size / 6), 0.0, 1.0) ** 2
        height += 0.0025 * patches * np.sin(2 * np.pi * (cycles * (t + drift) + rng.random()))
    for direction in (1, -1):
        patches = np.clip(_noise(rng, (size, size), size / 5), 0.0, None)
        height += 0.0015 * patches * np.sin(2 * np.pi * (3 * (t + direction * s) + rng.random()))
    return height


def _weave(rng: np.random.Generator, size: int, kind: str) -> tuple[np.ndarray, np.ndarray]:
    """(mask, height metres) of a fabric's own structure, both (size, size) and tileable."""
    s, t = _grid(size)
    heather = _noise(rng, (size, size), 0.8)
    streaks = _noise(rng, (size, size), (0.6, 6.0))  # fibres along s
    if kind == "jersey":  # knit: fine wales along t, a faint heather
        mask = np.clip(0.12 + 0.08 * heather, 0.0, 1.0)
        height = 0.00015 * np.sin(2 * np.pi * 85 * s) + 0.00005 * heather
    elif kind == "melange":  # heathered knit: streaks of lighter fibres
        mask = np.clip(0.35 + 0.25 * streaks + 0.1 * heather, 0.0, 1.0)
        height = 0.00015 * np.sin(2 * np.pi * 85 * s) + 0.00008 * streaks
    elif kind == "stripes":  # horizontal stripes, 10 per repeat (3 cm)
        mask = np.clip(_bands(t, 10, 0.4) + 0.05 * heather, 0.0, 1.0)
        height = 0.00012 * np.sin(2 * np.pi * 85 * s) + 0.00005 * heather
    elif kind == "check":  # gingham: two sets of bands crossing, their crossings darkest
        mask = np.clip(0.5 * (_bands(t, 10, 0.5) + _bands(s, 10, 0.5)) + 0.04 * heather, 0.0, 1.0)
        height = 0.0001 * (np.sin(2 * np.pi * 128 * s) * np.sin(2 * np.pi * 128 * t)) + 0.00005 * heather
    elif kind == "denim":  # 3/1 twill: diagonal ribs, faded (second colour) in streaks
        rib = 0.5 + 0.5 * np.sin(2 * np.pi * 64 * (s + t))
        mask = np.clip(0.25 + 0.35 * rib * (0.6 + 0.4 * streaks) + 0.1 * heather, 0.0, 1.0)
        height = 0.00022 * rib + 0.00006 * heather
    elif kind == "twill":  # chino: a finer, quieter twill
        rib = 0.5 + 0.5 * np.sin(2 * np.pi * 96 * (s + t))
        mask = np.clip(0.1 + 0.12 * rib + 0.05 * heather, 0.0, 1.0)
        height = 0.00015 * rib + 0.00004 * heather
    elif kind == "corduroy":  # wales along t, 50 per repeat (6 mm), their crowns lighter
        wale = np.abs(np.sin(2 * np.pi * 25 * s))
        mask = np.clip(0.1 + 0.35 * wale + 0.05 * heather, 0.0, 1.0)
        height = 0.0006 * wale + 0.00005 * heather
    else:
        raise ValueError(f"fabric {kind!r}; expected one of {', '.join(FABRICS)}")
    return mask, height


FABRICS = ("jersey", "melange", "stripes", "check", "denim", "twill", "corduroy")
SHOES = ("sneaker", "shoe")


def fabric(rng: np.random.Generator, kind: str, size: int = SIZE) -> tuple[np.ndarray, np.ndarray]:
    """(mask (size, size) in [0, 1], normals (size, size, 3)) of fabric ``kind`` over a repeat of
    :data:`FABRIC_TILE_M`, its folds included."""
    mask, height = _weave(rng, size, kind)
    return mask, height_normals(height + folds(rng, size), FABRIC_TILE_M / size)


def shoe(rng: np.random.Generator, kind: str, size: int = SIZE) -> tuple[np.ndarray, np.ndarray]:
    """(mask, normals) of a shoe over :data:`SHOE_TILE_M` along the foot (s) and up from the ground (t): the sole
    (mask 1) up to its height (3 cm on a sneaker, 1.5 cm on a shoe), a welt above it, a stitching line and a
    faint grain on the upper (mask near 0); the sole's edge and the upper's creases in the normals."""
    if kind not in SHOES:
        raise ValueError(f"shoe {kind!r}; expected one of {', '.join(SHOES)}")
    s, t = _grid(size)
    z = t * SHOE_TILE_M  # metres above the ground
    sole_m = 0.03 if kind == "sneaker" else 0.015
    texel = SHOE_TILE_M / size
    grain = _noise(rng, (size, size), 1.0)
    sole = np.clip((sole_m - z) / (2 * texel) + 0.5, 0.0, 1.0)
    welt = np.exp(-((z - sole_m - 0.002) / 0.0012) ** 2)
    stitch = (np.abs(z - sole_m - 0.012) < 0.0008) * (np.sin(2 * np.pi * 60 * s) > 0)
    mask = np.clip(sole + 0.55 * welt * (1 - sole) + 0.35 * stitch + 0.04 * grain, 0.0, 1.0)
    creases = 0.0003 * np.clip(_noise(rng, (size, size), (3.0, 10.0)), 0.0, None) * (z > sole_m)
    height = 0.002 * sole + 0.0008 * welt + creases + 0.00003 * grain
    return mask, height_normals(height, texel)


def _ellipse(s: np.ndarray, t: np.ndarray, cs: float, ct: float, rs: float, rt: float, soft: float) -> np.ndarray:
    """Coverage in [0, 1] of an ellipse centred (cs, ct) with half-axes (rs, rt) metres, edges eased over
    ``soft`` metres."""
    r = np.sqrt(((s - cs) / rs) ** 2 + ((t - ct) / rt) ** 2)
    return np.clip((1.0 - r) * min(rs, rt) / soft + 0.5, 0.0, 1.0)


def face(size: int = SIZE) -> np.ndarray:
    """(size, size, 3) stored face mask ((m + :data:`FACE_OFFSET`) / (1 + FACE_OFFSET), per channel) over
    :data:`FACE_SPAN_M` square centred on the eyes' midpoint (s to the person's left, t up), drawn for an adult
    whose eyes are 2 x :data:`EYE_HALF_SPACING_M` apart and :data:`EYE_TO_NOSE_M` above the nose tip. Plain skin
    (m = 0) everywhere else, the edge included."""
    s, t = _grid(size)
    s = (s - 0.5) * FACE_SPAN_M
    t = (t - 0.5) * FACE_SPAN_M
    soft = 0.0008
    m = np.zeros((size, size, 3))

    def paint(coverage: np.ndarray, value) -> None:
        m[:] = m + coverage[..., None] * (np.asarray(value, float) - m)

    e, mouth = EYE_HALF_SPACING_M, -(EYE_TO_NOSE_M + 0.024)
    paint(_ellipse(s, t, 0.042, -0.03, 0.018, 0.013, 0.01) + _ellipse(s, t, -0.042, -0.03, 0.018, 0.013, 0.01),
          (0.0, 0.06, 0.06))  # a blush on the cheeks
    for side in (1.0, -1.0):
        eye = _ellipse(s, t, side * e, 0.0, 0.0135, 0.0058, soft)
        paint(eye, (-0.5, -0.5, -0.5))  # whites
        paint(_ellipse(s, t, side * e, 0.0, 0.0056, 0.0056, soft) * eye, (0.85, 0.85, 0.85))  # iris
        paint(_ellipse(s, t, side * e, 0.0, 0.0024, 0.0024, soft) * eye, (1.0, 1.0, 1.0))  # pupil
        lash = _ellipse(s, t, side * e, 0.0012, 0.0145, 0.0058, soft) * (1 - eye) * (t > 0.0)
        paint(lash, (0.95, 0.95, 0.95))  # the upper lash line
        arc = 0.0135 + 0.006 * (1 - ((s - side * (e + 0.002)) / 0.018) ** 2)
        brow = np.clip(1 - np.abs(t - arc) / 0.0022, 0.0, 1.0) * (np.abs(s - side * (e + 0.002)) < 0.018)
        paint(brow, (0.8, 0.8, 0.8))
        paint(_ellipse(s, t, side * 0.0075, -EYE_TO_NOSE_M - 0.004, 0.0035, 0.0022, soft), (0.7, 0.7, 0.7))  # nostril
    lips = _ellipse(s, t, 0.0, mouth, 0.024, 0.0085, soft)
    paint(lips, (0.18, 0.45, 0.42))  # redder: the red channel darkens least
    paint(np.clip(1 - np.abs(t - mouth) / 0.0009, 0.0, 1.0) * lips, (0.8, 0.8, 0.8))  # between the lips
    return (m + FACE_OFFSET) / (1.0 + FACE_OFFSET)


def look_images(size: int = SIZE) -> dict[str, np.ndarray]:
    """Every image as 8-bit pixels (size, size, 3), by file stem: ``fabric_<kind>`` and ``fabric_<kind>_normal``,
    ``shoe_<kind>`` and ``shoe_<kind>_normal``, ``face``. Each kind draws from its own stream of :data:`SEED`."""
    out = {}
    for k, kind in enumerate(FABRICS):
        mask, normals = fabric(np.random.default_rng([SEED, 1, k]), kind, size)
        out[f"fabric_{kind}"] = _raw8(np.repeat(mask[..., None], 3, axis=2))
        out[f"fabric_{kind}_normal"] = encode_normals8(normals)
    for k, kind in enumerate(SHOES):
        mask, normals = shoe(np.random.default_rng([SEED, 2, k]), kind, size)
        out[f"shoe_{kind}"] = _raw8(np.repeat(mask[..., None], 3, axis=2))
        out[f"shoe_{kind}_normal"] = encode_normals8(normals)
    out["face"] = _raw8(face(size))
    return out


def _raw8(values: np.ndarray) -> np.ndarray:
    return np.round(np.clip(values, 0.0, 1.0) * 255.0).astype(np.uint8)


def image_path(stem: str) -> Path:
    """The shipped image ``stem`` (a key of :func:`look_images`)."""
    return LOOKS_DIR / f"{stem}.png"


def two_colour(c1, c2, offset: float = 0.0) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """UsdUVTexture (``scale``, ``bias``), RGBA, that turn a stored mask ``v`` into ``c1 + m (c2 - c1)`` per channel,
    where ``m = v (1 + offset) - offset`` (``offset`` :data:`FACE_OFFSET` for the face, 0 for the others)."""
    c1, c2 = np.asarray(c1, float), np.asarray(c2, float)
    scale = (1.0 + offset) * (c2 - c1)
    bias = c1 - offset * (c2 - c1)
    return (*map(float, scale), 1.0), (*map(float, bias), 0.0)
