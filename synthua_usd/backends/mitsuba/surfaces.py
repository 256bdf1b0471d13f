"""A :class:`Material` → Mitsuba BSDF dicts: ``principled`` with constants or ``bitmap`` textures, wrapped in a
``normalmap`` and a ``mask`` when the material has a normal map or an opacity below one.

Texture files are decoded here, once per file and colour space per translation (:class:`TextureImages`), with
OpenImageIO (files inside USDZ packages too: :mod:`synthua_usd.core.texture_files`): 8-bit sRGB images (and ``sRGB`` textures) through the exact sRGB transfer function, alpha never;
raw images as stored. Then UsdUVTexture's ``scale`` and ``bias`` and the chosen channel, and the result goes
to Mitsuba as a float bitmap with ``raw=True``: Mitsuba never converts it again, and a single channel stays
single (Mitsuba would take an RGB bitmap's luminance for a roughness, not its green). A tinted base colour
(``scale`` and ``bias`` on an RGB texture) is instead an ``affine`` texture over the image's one shared bitmap
(:mod:`synthua_usd.backends.mitsuba.affine_texture`): a crowd's garments, or a district's recoloured façades,
do not each copy their image. Mitsuba's bitmap puts
v = 0 on the image's first (top) row, USD's t = 0 on its bottom row: meshes get (s, 1 − t)
(:func:`mitsuba_uvs`).
"""

from __future__ import annotations

import logging
from dataclasses import replace
from typing import Callable

import numpy as np

from synthua_usd.backends.mitsuba import affine_texture
from synthua_usd.backends.mitsuba.shape_tables import ShapeTables
from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.texture_files import MAX_TEXELS, TextureFileError, open_image
from synthua_usd.model import srgb
from synthua_usd.model.scene import Material, Texture

log = logging.getLogger(__name__)

#: Our wrap modes → Mitsuba's. Mitsuba's bitmap has no black border: 'black' clamps (with a warning).
WRAP = {"repeat": "repeat", "mirror": "mirror", "clamp": "clamp", "black": "clamp"}
CHANNEL = {"r": 0, "g": 1, "b": 2, "a": 3}


def srgb_to_linear(values: np.ndarray) -> np.ndarray:
    """The sRGB transfer function's inverse (IEC 61966-2-1), elementwise on values in [0, 1]."""
    v = np.asarray(values, np.float32)
    return srgb.to_linear(v).astype(np.float32)


def mitsuba_uvs(uvs: np.ndarray) -> np.ndarray:
    """(n, 2) USD st → (n, 2) float32 Mitsuba uv: the same image point, v measured from the top row."""
    out = np.array(uvs, np.float32, copy=True)
    out[:, 1] = 1.0 - out[:, 1]
    return out


class TextureImages:
    """Decoded texture images and their Mitsuba bitmaps for one translation (``mi`` with its variant active)."""

    def __init__(self, mi) -> None:
        self.mi = mi
        self._rgba: dict[tuple[str, str], np.ndarray] = {}
        self._nodes: dict[tuple, object] = {}
        affine_texture.register(mi)

    def rgba(self, path: str, color_space: str) -> np.ndarray:
        """(H, W, 4) float32 linear RGBA of the image at ``path`` (grey fills RGB, missing alpha is 1), decoded
        by ``color_space`` ('auto' resolved by UsdUVTexture's rule). Raises :class:`InputError` when the file
        cannot be read as an image."""
        import OpenImageIO as oiio

        key = (path, color_space)
        if key in self._rgba:
            return self._rgba[key]
        try:
            with open_image(path) as image:
                spec = image.spec()
                if spec.width * spec.height > MAX_TEXELS or spec.nchannels < 1:
                    raise InputError(f"{path}: texture image of {spec.width}x{spec.height} pixels, {spec.nchannels} "
                                     f"channels; expected at most {MAX_TEXELS} pixels (8192 x 8192) and a channel")
                pixels = image.read_image(0, 0, 0, min(spec.nchannels, 4), "float")
        except TextureFileError as exc:
            raise InputError(f"{path}: cannot read the texture image: {echo(exc)}; expected a PNG, JPEG, EXR or "
                             f"another image OpenImageIO reads") from None
        if pixels is None:
            raise InputError(f"{path}: cannot decode the texture image; expected a readable image file")
        channels = min(spec.nchannels, 4)
        pixels = np.asarray(pixels, np.float32).reshape(spec.height, spec.width, channels)
        if color_space == "auto":
            color_space = "sRGB" if spec.format == oiio.UINT8 and channels in (3, 4) else "raw"
        colour = pixels[..., : min(3, channels)] if channels != 2 else pixels[..., :1]
        if color_space == "sRGB":
            colour = srgb_to_linear(colour)
        if colour.shape[2] == 1:
            colour = np.repeat(colour, 3, axis=2)
        alpha_index = {2: 1, 4: 3}.get(channels)
        alpha = pixels[..., alpha_index:alpha_index + 1] if alpha_index else np.ones_like(colour[..., :1])
        rgba = np.ascontiguousarray(np.concatenate([colour, alpha], axis=2), np.float32)
        self._rgba[key] = rgba
        return rgba

    def values(self, texture: Texture) -> np.ndarray:
        """(H, W, 3) or (H, W, 1) float32: ``texture``'s decoded values after scale, bias and channel."""
        rgba = self.rgba(texture.path, texture.color_space) * np.float32(texture.scale) + np.float32(texture.bias)
        if texture.channel == "rgb":
            return rgba[..., :3]
        return rgba[..., CHANNEL[texture.channel]:CHANNEL[texture.channel] + 1]

    def node(self, texture: Texture, transform: Callable[[np.ndarray], np.ndarray] | None = None,
             name: str = ""):
        """A loaded ``bitmap`` texture of ``texture``'s values, passed through ``transform`` first (``name``
        tells transforms apart in the cache). Loaded once and shared by every BSDF that uses it: a dict would
        make Mitsuba copy the pixels into each."""
        key = (texture, name)
        if key not in self._nodes:
            data = self.values(texture)
            if transform is not None:
                data = transform(data)
            if texture.wrap_s != texture.wrap_t or texture.wrap_s == "black":
                log.warning("%s: wrap modes %s/%s: Mitsuba wraps both axes alike and has no black border; using %s",
                            texture.path, texture.wrap_s, texture.wrap_t, WRAP[texture.wrap_s])
            self._nodes[key] = self.mi.load_dict({
                "type": "bitmap", "data": self.mi.TensorXf(np.ascontiguousarray(data, np.float32)), "raw": True,
                "filter_type": "bilinear", "wrap_mode": WRAP[texture.wrap_s]})
        return self._nodes[key]

    def tinted(self, texture: Texture, tables: ShapeTables | None = None):
        """``texture`` (RGB) as an ``affine`` texture (:mod:`affine_texture`: a scale and a bias, clipped to [0, 1])
        over its image's bitmap, which every material tinting that image shares; a texture without scale and bias
        is its bitmap. One copy of an image however many materials tint it. With ``tables`` (enabled), the scale
        and bias are the shape's rows of the ``tint_scale`` and ``tint_bias`` columns, and every tint of the
        image is one texture; else they are the texture's own."""
        plain = untinted(texture)
        if texture == plain:
            return self.node(texture, lambda d: np.clip(d, 0.0, 1.0), "albedo")
        mi = self.mi
        if tables is not None and tables.enabled:
            key = ("affine", plain)
            if key not in self._nodes:
                self._nodes[key] = mi.load_dict({"type": "affine", "texture": self.node(plain, None, "plain"),
                                                 "scale": tables.value("tint_scale", 3),
                                                 "bias": tables.value("tint_bias", 3)})
            return self._nodes[key]
        key = ("affine", texture)
        if key not in self._nodes:
            self._nodes[key] = mi.load_dict({"type": "affine", "texture": self.node(plain, None, "plain"),
                                             "scale": mi.ScalarColor3f(*texture.scale[:3]),
                                             "bias": mi.ScalarColor3f(*texture.bias[:3])})
        return self._nodes[key]


def untinted(texture: Texture) -> Texture:
    """``texture`` without its scale and bias: the image as it is."""
    return replace(texture, scale=(1.0, 1.0, 1.0, 1.0), bias=(0.0, 0.0, 0.0, 0.0))


def principled_dict(material: Material, images: TextureImages | None = None, tables: ShapeTables | None = None,
                    albedo: Callable[[np.ndarray], np.ndarray] | None = None, roughness_factor: float = 1.0,
                    name: str = "") -> tuple[dict, dict]:
    """Mitsuba ``principled`` of ``material`` and the shape's values it reads from ``tables``: constants, or
    bitmaps where it has textures and ``images`` is given. With ``tables`` (enabled), each constant is a column of
    the tables (``base_color``, ``roughness``, ... with ``name`` appended) and its value goes into the returned
    values (column -> value), so that materials differing only in constants give equal dicts; else the dict holds
    the constants and the values are empty. ``albedo`` maps base colours (weathering), ``roughness_factor`` scales
    roughness; ``name`` keys those variants' bitmaps and columns."""
    values: dict = {}
    tabled = tables is not None and tables.enabled

    def clip(v):
        return np.clip(v, 0.0, 1.0)

    def constant(column: str, value, channels: int = 1):
        if not tabled:
            return {"type": "rgb", "value": value} if channels == 3 else value
        values[f"{column}{name}"] = value
        return tables.value(f"{column}{name}", channels)

    def colour():
        texture = material.base_color_texture
        if texture is not None and images is not None:
            if albedo is None and texture.channel == "rgb":
                if tabled and texture != untinted(texture):
                    values["tint_scale"], values["tint_bias"] = tuple(texture.scale[:3]), tuple(texture.bias[:3])
                return images.tinted(texture, tables)
            return images.node(texture, lambda d: (albedo or clip)(clip(d)), f"albedo{name}")
        value = np.asarray(material.base_color, np.float64)
        return constant("base_color", (albedo(value) if albedo else value).tolist(), 3)

    def scalar(texture: Texture | None, value: float, factor: float = 1.0, field: str = ""):
        if texture is not None and images is not None:
            return images.node(texture, lambda d: clip(d) * np.float32(factor), f"{field}{name}")
        return constant(field, float(np.clip(value, 0.0, 1.0)) * factor)

    out = {"type": "principled", "base_color": colour(),
           "roughness": scalar(material.roughness_texture, material.roughness, roughness_factor, "roughness"),
           "metallic": scalar(material.metallic_texture, material.metallic, field="metallic")}
    if material.clearcoat > 0.0:  # Mitsuba's gloss is UsdPreviewSurface's 1 - roughness
        out["clearcoat"] = constant("clearcoat", float(np.clip(material.clearcoat, 0.0, 1.0)))
        out["clearcoat_gloss"] = constant("clearcoat_gloss", float(np.clip(1.0 - material.clearcoat_roughness, 0.0, 1.0)))
    return out, values


def wrapped(bsdf: dict, material: Material, images: TextureImages | None = None,
            tables: ShapeTables | None = None) -> tuple[dict, dict]:
    """``bsdf`` under ``material``'s normal map (Mitsuba's ``normalmap`` reads [0, 1]-encoded tangent-space
    normals: UsdPreviewSurface's [-1, 1] values are mapped there) and its opacity (``mask``; with
    ``opacity_threshold`` > 0 a cutout: coverage 0 below it, 1 from it on); and the shape's values it reads from
    ``tables`` (a constant opacity's column, as :func:`principled_dict`)."""
    node, values = bsdf, {}
    if material.normal_texture is not None and images is not None:
        node = {"type": "normalmap", "bsdf": node,
                "normalmap": images.node(material.normal_texture, _encoded_normals, "normal")}
    threshold = material.opacity_threshold

    def coverage(d):
        d = np.clip(d, 0.0, 1.0)
        return (d >= threshold).astype(np.float32) if threshold > 0 else d

    if material.opacity_texture is not None and images is not None:
        node = {"type": "mask", "bsdf": node, "opacity": images.node(material.opacity_texture, coverage, "opacity")}
    elif float(coverage(np.float32(material.opacity))) < 1.0:
        opacity = float(coverage(np.float32(material.opacity)))
        if tables is not None and tables.enabled:
            values["opacity"] = opacity
            opacity = tables.value("opacity", 1)
        node = {"type": "mask", "bsdf": node, "opacity": opacity}
    return node, values


def sided(bsdf: dict, double_sided: bool) -> dict:
    """``bsdf`` as is, or for a ``doubleSided`` gprim wrapped in Mitsuba's ``twosided`` (the same BSDF on the
    back, mirrored; Mitsuba's BSDFs are black seen from behind). ``twosided`` refuses BSDFs that transmit,
    so an opacity ``mask`` stays outside: the mask of a two-sided BSDF."""
    if not double_sided:
        return bsdf
    if bsdf.get("type") == "mask":
        return {**bsdf, "bsdf": sided(bsdf["bsdf"], True)}
    return {"type": "twosided", "bsdf": bsdf}


def _encoded_normals(values: np.ndarray) -> np.ndarray:
    n = values / np.maximum(np.linalg.norm(values, axis=2, keepdims=True), 1e-6)
    return (0.5 * n + 0.5).astype(np.float32)
