"""Plain scene data at one time code: what a backend needs to render, free of USD and of any renderer.

Coordinates are world space in metres with the stage's up axis; colours are linear Rec.709.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np


#: Which output of a texture feeds an input: the colour, or one channel.
TEXTURE_CHANNELS = ("rgb", "r", "g", "b", "a")
#: How texel values are decoded: 'auto' is UsdUVTexture's rule (sRGB for 8-bit images of 3 or 4 channels,
#: raw otherwise), resolved when the file is read.
COLOR_SPACES = ("auto", "sRGB", "raw")
WRAP_MODES = ("repeat", "mirror", "clamp", "black")


@dataclass(frozen=True)
class Texture:
    """An image feeding one material input: a UsdUVTexture reduced to plain data.

    ``path`` is the image file: absolute when read from a stage; in a :class:`synthua_usd.model.twin.TwinModel`,
    relative to the folder the twin layer is written in (e.g. ``textures/asphalt.png``). Texel values are
    decoded by ``color_space`` to linear values, then ``value * scale + bias`` per RGBA channel (UsdUVTexture's
    order), then ``channel`` is taken. Texture coordinates follow USD's ``st``: (0, 0) is the image's
    bottom-left corner, t grows upwards; ``wrap_s``/``wrap_t`` say what lies outside [0, 1].
    """

    path: str
    channel: str = "rgb"
    color_space: str = "auto"
    wrap_s: str = "repeat"
    wrap_t: str = "repeat"
    scale: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    bias: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        for name, value, allowed in (("channel", self.channel, TEXTURE_CHANNELS),
                                     ("color_space", self.color_space, COLOR_SPACES),
                                     ("wrap_s", self.wrap_s, WRAP_MODES), ("wrap_t", self.wrap_t, WRAP_MODES)):
            if value not in allowed:
                raise ValueError(f"texture {self.path}: {name} should be one of {', '.join(allowed)}, but was {value!r}")
        for name in ("scale", "bias"):
            value = tuple(float(v) for v in getattr(self, name))
            if len(value) != 4 or not all(math.isfinite(v) for v in value):
                raise ValueError(f"texture {self.path}: {name} should be 4 finite numbers (RGBA), but was {value}")
            object.__setattr__(self, name, value)


@dataclass(frozen=True)
class Material:
    """A UsdPreviewSurface reduced to constants and textures. Colours linear Rec.709, 0..1.

    A ``*_texture`` replaces its constant where the mesh has texture coordinates (the constant stays the
    fallback: meshes without them render with it). ``normal_texture`` is a tangent-space normal map whose
    values (after scale and bias) lie in [-1, 1]. ``opacity`` below ``opacity_threshold`` cuts the surface
    away when the threshold is above 0 (UsdPreviewSurface's cutout); otherwise it is partial coverage.
    ``uv_primvar`` names the mesh primvar holding the texture coordinates. ``clearcoat`` (0..1) weighs a second,
    clear specular layer of ``clearcoat_roughness`` over the base (skin's oily sheen, lacquer), as
    UsdPreviewSurface's inputs of those names.
    """

    key: str
    base_color: tuple[float, float, float] = (0.18, 0.18, 0.18)
    roughness: float = 0.5
    metallic: float = 0.0
    emissive_color: tuple[float, float, float] = (0.0, 0.0, 0.0)
    opacity: float = 1.0
    opacity_threshold: float = 0.0
    base_color_texture: Texture | None = None
    roughness_texture: Texture | None = None
    metallic_texture: Texture | None = None
    normal_texture: Texture | None = None
    opacity_texture: Texture | None = None
    uv_primvar: str = "st"
    clearcoat: float = 0.0
    clearcoat_roughness: float = 0.01

    @property
    def textures(self) -> dict[str, Texture]:
        """The textured inputs by field name (``base_color_texture``, ...), in field order."""
        return {name: getattr(self, name) for name in TEXTURED_INPUTS if getattr(self, name) is not None}

    def untextured(self) -> "Material":
        """The same material with its constants only: what meshes without texture coordinates render with."""
        return replace(self, **{name: None for name in TEXTURED_INPUTS})


#: Material fields that hold a texture, in the order backends build them.
TEXTURED_INPUTS = ("base_color_texture", "roughness_texture", "metallic_texture", "normal_texture", "opacity_texture")


@dataclass(frozen=True)
class Instance:
    """One labelled object: the prim carrying the label and everything below it.

    ``id`` is the pixel value in instance maps (1-based; 0 means no instance).
    """

    id: int
    prim_path: str
    class_id: int
    class_name: str
    isthing: bool
    relations: tuple[tuple[str, str], ...] = ()

    def to_dict(self) -> dict:
        out = {"id": self.id, "prim_path": self.prim_path, "class_id": self.class_id,
               "class_name": self.class_name, "isthing": self.isthing}
        if self.relations:
            out["relations"] = {name: target for name, target in self.relations}
        return out


@dataclass(frozen=True, eq=False)
class MeshItem:
    """One renderable gprim as world-space triangles.

    Attributes
    ----------
    prim_path : str
    points : (n, 3) float64, world metres
    triangles : (m, 3) int64, counter-clockwise seen from the front
    material_key : str, a key of :attr:`SceneSnapshot.materials`
    instance_id : int, an id of :attr:`SceneSnapshot.instances` (0 for unlabelled geometry)
    class_id : int
    lamp : str, the gprim's authored ``synthua:lamp`` role ('' when none; see :mod:`synthua_usd.model.lamps`)
    uvs : (n, 2) float32 texture coordinates per point in USD's ``st`` convention (origin at the image's
        bottom-left), or None when the mesh has none or its material has no textures. Face-varying
        coordinates arrive here already per point: the reader splits points where corners disagree.
    normals : (n, 3) float32 unit shading normals per point, world space, from the mesh's authored normals
        (smooth shading between them), or None: the mesh is shaded flat (its faces' own normals).
    """

    prim_path: str
    points: np.ndarray = field(repr=False)
    triangles: np.ndarray = field(repr=False)
    material_key: str
    instance_id: int
    class_id: int
    lamp: str = ""
    uvs: np.ndarray | None = field(default=None, repr=False)
    #: The gprim's ``doubleSided``: its back faces are shaded like its front faces.
    double_sided: bool = False
    normals: np.ndarray | None = field(default=None, repr=False)


@dataclass(frozen=True)
class Light:
    """A light reduced to what backends need.

    ``kind`` is ``distant`` (sun: ``direction`` is the unit world vector light travels along,
    ``irradiance`` W/m² per channel) or ``dome`` (uniform sky: ``radiance`` per channel).
    """

    prim_path: str
    kind: str
    color: tuple[float, float, float]
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    angle_deg: float = 0.53
    irradiance: float = 0.0
    radiance: float = 0.0


@dataclass(frozen=True, eq=False)
class Keypoints:
    """The named keypoints of one instance at one time code: ``names`` and ``points`` (k, 3) float64 world
    metres, one per name (a person's COCO body keypoints, a device's contact points)."""

    instance_id: int
    names: tuple[str, ...]
    points: np.ndarray = field(repr=False)


@dataclass(frozen=True, eq=False)
class SceneSnapshot:
    """Everything renderable in a stage at one time code."""

    time_code: float
    up_axis: str
    meshes: tuple[MeshItem, ...]
    materials: dict[str, Material]
    lights: tuple[Light, ...]
    instances: tuple[Instance, ...]
    #: Instance id -> its keypoints, for instances whose prim authors them.
    keypoints: dict[int, Keypoints] = field(default_factory=dict)

    def instance(self, instance_id: int) -> Instance:
        for inst in self.instances:
            if inst.id == instance_id:
                return inst
        raise KeyError(f"no instance with id {instance_id}")

    def triangle_count(self) -> int:
        return int(sum(len(m.triangles) for m in self.meshes))

    def world_triangles(self, meshes=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All triangles of ``meshes`` (default: every mesh) in one soup: vertices (n, 3), faces (m, 3), and
        (m,) int64 index into ``meshes`` per face."""
        verts, faces, owner, offset = [], [], [], 0
        for i, m in enumerate(self.meshes if meshes is None else meshes):
            verts.append(m.points)
            faces.append(m.triangles + offset)
            owner.append(np.full(len(m.triangles), i, np.int64))
            offset += len(m.points)
        if not verts:
            return np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros(0, np.int64)
        return np.concatenate(verts), np.concatenate(faces), np.concatenate(owner)
