"""Plain scene data at one time code: what a backend needs to render, free of USD and of any renderer.

Coordinates are world space in metres with the stage's up axis; colours are linear Rec.709.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Material:
    """A UsdPreviewSurface reduced to constants. Colours linear Rec.709, 0..1."""

    key: str
    base_color: tuple[float, float, float] = (0.18, 0.18, 0.18)
    roughness: float = 0.5
    metallic: float = 0.0
    emissive_color: tuple[float, float, float] = (0.0, 0.0, 0.0)


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
    lamp : str, the gprim's authored ``synthua:lamp`` role ('' when none; see :mod:`synthua_usd.lamps`)
    """

    prim_path: str
    points: np.ndarray = field(repr=False)
    triangles: np.ndarray = field(repr=False)
    material_key: str
    instance_id: int
    class_id: int
    lamp: str = ""


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
class SceneSnapshot:
    """Everything renderable in a stage at one time code."""

    time_code: float
    up_axis: str
    meshes: tuple[MeshItem, ...]
    materials: dict[str, Material]
    lights: tuple[Light, ...]
    instances: tuple[Instance, ...]

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
