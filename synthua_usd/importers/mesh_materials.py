"""The material of a trimesh geometry → a :class:`Material`, its texture images and the geometry's uvs.

OBJ/MTL arrive as trimesh's ``SimpleMaterial`` (``Kd``; ``map_Kd`` as ``image``), glTF/GLB as ``PBRMaterial``
(``baseColorFactor``/``baseColorTexture``, ``metallicRoughnessTexture`` with roughness in G and metallic in B,
``normalTexture``, ``alphaMode``/``alphaCutoff``). Images are kept as 8-bit pixels under
``textures/<material>_<role>.png`` (written beside the twin layer, :mod:`synthua_usd.core.texture_images`), and
glTF's factors become UsdUVTexture scales: the factor multiplies the texture, as glTF says. trimesh gives
texture coordinates per vertex with v up (OBJ's convention; it flips glTF's on load): USD's ``st`` as is.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import trimesh

from synthua_usd.core.texture_images import texture_path
from synthua_usd.model import srgb
from synthua_usd.model.scene import Material, Texture
from synthua_usd.model.twin import prim_name

#: glTF normal textures hold n * 0.5 + 0.5; UsdPreviewSurface's normal input wants n.
NORMAL_SCALE, NORMAL_BIAS = (2.0, 2.0, 2.0, 1.0), (-1.0, -1.0, -1.0, 0.0)


def srgb8_to_linear(rgb8) -> tuple[float, float, float]:
    """An 8-bit sRGB colour (first three of ``rgb8``) as linear Rec.709."""
    # Colours come from the file: anything but 0..255 (NaN included) is clipped into it.
    c = np.clip(np.nan_to_num(np.asarray(rgb8[:3], float), nan=0.0), 0.0, 255.0) / 255.0
    lin = srgb.to_linear(c)
    return tuple(float(v) for v in lin)


def unit(value, default: float) -> float:
    """A factor of the file's material in [0, 1] (``default`` when absent or not a number)."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        return default
    return float(np.clip(number, 0.0, 1.0)) if np.isfinite(number) else default


def _pixels(image) -> np.ndarray | None:
    """(H, W, C) uint8 pixels of a PIL image (palette and 16-bit images converted), None when unusable."""
    if image is None or not hasattr(image, "convert"):
        return None
    if image.mode not in ("L", "LA", "RGB", "RGBA"):
        image = image.convert("RGBA" if "A" in image.mode or image.mode == "P" else "RGB")
    pixels = np.asarray(image, np.uint8)
    pixels = pixels[:, :, None] if pixels.ndim == 2 else pixels
    return pixels if pixels.size else None


def geometry_material(geom: trimesh.Trimesh, fallback: str
                      ) -> tuple[str, Material, dict[str, np.ndarray], np.ndarray | None]:
    """(material name, material, its images by relative path, (n, 2) float32 uvs or None) of ``geom``.

    The uvs are returned only when the material has a texture and the geometry has one pair per vertex."""
    visual = geom.visual
    mat = getattr(visual, "material", None)
    if mat is None:
        if getattr(visual, "kind", None) == "vertex" and len(visual.vertex_colors):
            colour = srgb8_to_linear(np.asarray(visual.vertex_colors).mean(axis=0))
            return fallback, Material(fallback, colour, 0.8), {}, None
        return fallback, Material(fallback), {}, None
    name = getattr(mat, "name", None) or fallback
    images: dict[str, np.ndarray] = {}

    def texture(image, role: str, **options) -> Texture | None:
        pixels = _pixels(image)
        if pixels is None:
            return None
        rel = texture_path(f"{prim_name(name, 'Material')}_{role}.png")
        images[rel] = pixels
        return Texture(rel, **options)

    if hasattr(mat, "baseColorFactor"):  # glTF's PBRMaterial
        factor = np.asarray(mat.baseColorFactor if mat.baseColorFactor is not None else [255] * 4, float)
        rough = unit(getattr(mat, "roughnessFactor", None), 1.0 if mat.metallicRoughnessTexture is not None else 0.8)
        metal = unit(getattr(mat, "metallicFactor", None), 1.0 if mat.metallicRoughnessTexture is not None else 0.0)
        scale = tuple(np.clip(factor / 255.0, 0.0, 1.0).tolist())
        base = texture(mat.baseColorTexture, "base_color", color_space="sRGB", scale=scale)
        masked = getattr(mat, "alphaMode", None) in ("MASK", "BLEND") and base is not None
        fields = {
            "base_color_texture": base,
            "roughness_texture": texture(mat.metallicRoughnessTexture, "metallic_roughness", channel="g",
                                         color_space="raw", scale=(rough,) * 4),
            "normal_texture": texture(mat.normalTexture, "normal", color_space="raw", scale=NORMAL_SCALE,
                                      bias=NORMAL_BIAS),
            "opacity_texture": (Texture(base.path, channel="a", color_space="sRGB", scale=scale) if masked else None),
        }
        if fields["roughness_texture"] is not None:
            fields["metallic_texture"] = Texture(fields["roughness_texture"].path, channel="b", color_space="raw",
                                                 scale=(metal,) * 4)
        threshold = unit(getattr(mat, "alphaCutoff", None), 0.5) if getattr(mat, "alphaMode", None) == "MASK" else 0.0
        material = Material(name, srgb8_to_linear(factor), rough, metal, opacity_threshold=threshold,
                            **{k: v for k, v in fields.items() if v is not None})
    elif getattr(mat, "diffuse", None) is not None or getattr(mat, "image", None) is not None:  # OBJ/MTL
        colour = srgb8_to_linear(np.asarray(mat.diffuse)) if getattr(mat, "diffuse", None) is not None else (0.18,) * 3
        base = texture(getattr(mat, "image", None), "base_color", color_space="sRGB")
        material = Material(name, colour, 0.8, base_color_texture=base)
    else:
        material = Material(name)
    uv = getattr(visual, "uv", None)
    if not material.textures or uv is None or np.shape(uv) != (len(geom.vertices), 2):
        return name, material, images, None
    uvs = np.asarray(uv, np.float64)
    if not np.all(np.isfinite(uvs)):
        return name, material, images, None
    return name, material, images, uvs.astype(np.float32)


class ImageFailures(logging.Handler):
    """Collects trimesh's own notes of texture images it could not load (it logs them at debug level and goes
    on without the texture): ``reasons`` holds each one's exception, as text. Use as a context manager around
    ``trimesh.load``."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.reasons: list[str] = []
        self._logger = logging.getLogger("trimesh")
        self._level = self._logger.level

    def emit(self, record: logging.LogRecord) -> None:
        if record.getMessage().startswith("failed to load image") and record.exc_info and record.exc_info[1]:
            exc = record.exc_info[1]
            self.reasons.append(f"{type(exc).__name__}: {exc}")

    def __enter__(self) -> "ImageFailures":
        self._logger.addHandler(self)
        if self._logger.getEffectiveLevel() > logging.DEBUG:
            self._logger.setLevel(logging.DEBUG)
        return self

    def __exit__(self, *exc) -> None:
        self._logger.removeHandler(self)
        self._logger.setLevel(self._level)


def obj_texture_problems(path: Path) -> list[tuple[str, str, str]]:
    """(material, texture file as the MTL writes it, why it cannot be read) for every ``map_Kd`` of the MTL files
    an OBJ names (``mtllib``, beside the OBJ) whose image is missing or not one OpenImageIO opens."""
    from synthua_usd.core.texture_files import unreadable

    problems = []
    with open(path, "rb") as fh:
        libraries = [line.split(None, 1)[1].strip().decode("utf-8", "replace") for line in fh
                     if line.startswith(b"mtllib") and len(line.split(None, 1)) == 2]
    for library in libraries:
        mtl = path.parent / library
        if not mtl.is_file():
            continue
        material = ""
        for line in mtl.read_text("utf-8", "replace").splitlines():
            key, _, rest = line.strip().partition(" ")
            if key.lower() == "newmtl":
                material = rest.strip()
            elif key.lower() == "map_kd" and rest.strip():
                name = rest.strip().split()[-1]  # options (-s 1 1 1) come before the file name
                reason = unreadable(str(path.parent / name))
                if reason is not None:
                    problems.append((material, name, reason))
    return problems
