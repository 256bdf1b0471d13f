"""Procedural texture images of the demo district, made from a seeded numpy Generator (no downloads).

Each image is tileable (every filter wraps around the edges) and holds *variation around a mean*: the
district tints it per material through UsdUVTexture's ``scale`` so that a textured surface keeps its flat
colour's mean (:mod:`synthua_usd.demo.district_textures`). Images are 8-bit sRGB RGB, ``SIZE`` pixels square.

* ``stone``: granite for cobbles, pavers and kerbs: mineral speckles (light quartz and feldspar, dark mica)
  over mottling, and blotches of a few stones' size, with a slight warm/cool colour drift, so that stones
  next to each other differ;
* ``plaster``: walls: low-frequency damp and dirt blotches, fine sand grain, rain streaks running down;
* ``wood``: planks with grain: wavy stripes along the planks, per-plank tone and a few knots;
* ``asphalt``: bitumen with bright and dark aggregate, lighter worn patches where the binder is gone, and
  a few darker stains.

:func:`paving` makes the stones of the cobbled street and the largo: stones in running bond, each of one of a
few shades, with joints and rounded edges, as a colour image and a tangent-space normal map (the stones used
to be modelled one by one: 444,000 triangles of sub-pixel edges that no affordable sample count resolves).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from synthua_usd.model.normal_maps import height_normals
from synthua_usd.model.srgb import encode_srgb8

SIZE = 512
#: Image name → function of (rng, size) → (size, size, 3) linear values around 1.
TEXTURES: dict = {}


def texture(fn):
    TEXTURES[fn.__name__] = fn
    return fn


def _noise(rng: np.random.Generator, size: int, sigma_px: float) -> np.ndarray:
    """(size, size) tileable noise of feature size ``sigma_px``, zero mean, unit standard deviation."""
    field = ndimage.gaussian_filter(rng.standard_normal((size, size)), sigma_px, mode="wrap")
    return (field - field.mean()) / max(field.std(), 1e-12)


def _fractal(rng: np.random.Generator, size: int, sigmas: tuple[float, ...], gains: tuple[float, ...]) -> np.ndarray:
    return sum(g * _noise(rng, size, s) for s, g in zip(sigmas, gains))


def _tint(rng: np.random.Generator, size: int, grey: np.ndarray, drift: float, sigma_px: float) -> np.ndarray:
    """(size, size, 3): ``grey`` with a low-frequency colour drift of relative amplitude ``drift``."""
    warm = drift * _noise(rng, size, sigma_px)
    return np.stack([grey * (1 + warm), grey, grey * (1 - warm)], axis=2)


@texture
def stone(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    mottle = _fractal(rng, size, (24.0, 6.0), (0.12, 0.06))
    grain = rng.random((size, size))
    speckle = np.where(grain > 0.93, 0.35, 0.0) - np.where(grain < 0.05, 0.3, 0.0)
    speckle = ndimage.gaussian_filter(speckle, 0.6, mode="wrap")
    grey = np.clip(1.0 + mottle + speckle + 0.04 * rng.standard_normal((size, size)), 0.35, 1.8)
    return _tint(rng, size, grey, 0.06, 40.0)


@texture
def plaster(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    blotches = _fractal(rng, size, (48.0, 16.0), (0.1, 0.05))
    sand = 0.03 * rng.standard_normal((size, size))
    # Rain streaks: noise stretched down the image (rows are t, row 0 at the top), darker towards the bottom
    # of each streak.
    streaks = ndimage.gaussian_filter(rng.standard_normal((size, size)), (40.0, 1.5), mode="wrap")
    streaks = np.minimum(streaks / max(streaks.std(), 1e-12), 0.0) * 0.05
    grey = np.clip(1.0 + blotches + sand + streaks, 0.5, 1.5)
    return _tint(rng, size, grey, 0.03, 60.0)


@texture
def wood(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    planks = 4
    rows = np.arange(size)[:, None] * np.ones((1, size))
    cols = np.ones((size, 1)) * np.arange(size)[None, :]
    plank = (rows * planks // size).astype(int)
    tone = 1.0 + 0.12 * rng.standard_normal(planks)[plank]
    warp = 6.0 * _noise(rng, size, 30.0)
    rings = np.sin(2 * np.pi * (rows + warp) / (size / planks / 5.5) + 3.0 * plank)
    fine = ndimage.gaussian_filter(rng.standard_normal((size, size)), (0.7, 12.0), mode="wrap")
    grey = tone * (1.0 + 0.1 * rings + 0.05 * fine / max(fine.std(), 1e-12))
    for _ in range(3):  # knots: dark ellipses
        cy, cx = rng.integers(0, size, 2)
        dy = (rows - cy + size / 2) % size - size / 2
        dx = (cols - cx + size / 2) % size - size / 2
        grey = grey * (1.0 - 0.35 * np.exp(-((dx / 9.0) ** 2 + (dy / 5.0) ** 2)))
    seams = (rows % (size // planks)) < 2  # the gaps between planks
    grey = np.where(seams, 0.45, grey)
    return _tint(rng, size, np.clip(grey, 0.3, 1.6), 0.02, 50.0)


@texture
def asphalt(rng: np.random.Generator, size: int = SIZE) -> np.ndarray:
    grain = rng.random((size, size))
    aggregate = np.where(grain > 0.9, 0.9, 0.0) + np.where(grain < 0.06, -0.3, 0.0)
    aggregate = ndimage.gaussian_filter(aggregate, 0.8, mode="wrap")
    wear = np.clip(_fractal(rng, size, (60.0, 20.0), (1.0, 0.4)), 0.0, None)
    stains = np.clip(-_noise(rng, size, 25.0) - 1.6, 0.0, None)
    grey = (1.0 + 0.2 * wear) * (1.0 + aggregate * (0.5 + 0.5 * np.tanh(wear))) * (1.0 - 0.3 * stains)
    grey += 0.05 * rng.standard_normal((size, size))
    return _tint(rng, size, np.clip(grey, 0.4, 2.5), 0.02, 60.0)


def paving(rng: np.random.Generator, size: int, tile_m: float, stones: int, rows: int, joint_m: float,
           bevel_m: float, depth_m: float, shades: np.ndarray, joint_tone: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A square tile ``tile_m`` metres wide of stones in running bond (``stones`` per row, ``rows`` rows, even
    so that the bond repeats; every other row shifted by half a stone), ``joint_m`` wide joints ``depth_m``
    deep, stone edges rounded over ``bevel_m``. Each stone takes one of ``shades`` ((k, 3) linear factors)
    at random, times the ``stone`` grain; joints take ``joint_tone`` (3,) with a sandy grain.

    Returns (size, size, 3) linear colour (variation around the shades) and (size, size, 3) tangent-space
    normals in [-1, 1] (x along s, y along t, z out of the surface; the image's row 0 is at t = 1, as
    :mod:`synthua_usd.geometry.uv` has it), both tileable."""
    if rows % 2:
        raise ValueError(f"paving: rows should be even so that the running bond tiles, but was {rows}")
    texel = tile_m / size
    s = (np.arange(size) + 0.5) / size
    t = 1.0 - (np.arange(size) + 0.5) / size
    row = np.floor(t * rows).astype(np.int64)[:, None] * np.ones((1, size), np.int64)
    shifted = s[None, :] * stones - 0.5 * (row % 2)
    col = np.floor(shifted).astype(np.int64) % stones
    fs, ft = shifted - np.floor(shifted), (t * rows - np.floor(t * rows))[:, None]
    # distance (m) from the pixel to the nearest edge of its stone, less half a joint: < 0 in the joint
    inside = np.minimum(np.minimum(fs, 1 - fs) * tile_m / stones, np.minimum(ft, 1 - ft) * tile_m / rows)
    inside = inside - joint_m / 2
    height = np.where(inside <= 0, -depth_m, -depth_m * np.clip(1 - inside / bevel_m, 0, 1) ** 2)
    normals = height_normals(height, texel)
    shade = np.asarray(shades, np.float64)[rng.integers(len(shades), size=rows * stones)[row * stones + col]]
    grain = stone(rng, size)
    sand = np.clip(1.0 + 0.15 * rng.standard_normal((size, size)), 0.6, 1.4)[:, :, None]
    colour = np.where((inside <= 0)[:, :, None], np.asarray(joint_tone, np.float64) * sand, shade * grain)
    return colour, normals


def district_images(seed: int, size: int = SIZE) -> dict[str, np.ndarray]:
    """Every texture as 8-bit sRGB pixels, by name. The variation is stored around linear 0.4 (sRGB 170)
    so that 8 bits resolve it; the tint brings it to the material's colour. ``seed`` seeds its own
    Generator stream, apart from the district's geometry."""
    rng = np.random.default_rng([seed, 0x7E77])
    return {name: encode_srgb8(0.4 * make(rng, size)) for name, make in TEXTURES.items()}
