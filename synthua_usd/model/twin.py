"""A digital twin as plain data: labelled objects made of triangle meshes, before it becomes USD layers.

Importers (:mod:`synthua_usd.importers`) and procedural generators produce a :class:`TwinModel`;
:func:`synthua_usd.usd.twin_writer.author_twin` turns it into a twin layer and a semantics layer.
Coordinates are local metres, Z up; ``origin_offset_m`` is what was subtracted from the source.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from synthua_usd.core.errors import InputError
from synthua_usd.model.meshes import Mesh
from synthua_usd.model.scene import Material

_NAME_OK = re.compile(r"[^A-Za-z0-9_]")


def prim_name(text: str, fallback: str = "Object") -> str:
    """A valid USD prim name from arbitrary source text (letters, digits, underscores; no leading digit)."""
    name = _NAME_OK.sub("_", str(text)).strip("_") or fallback
    return f"_{name}" if name[0].isdigit() else name


@dataclass(frozen=True, eq=False)
class TwinPart:
    """One named mesh with a material, before it becomes a USD ``Mesh`` prim.

    ``points`` (n, 3) float64, metres, in the frame of the twin (procedural assets: the asset's own frame
    until :func:`synthua_usd.assets.place` moves them); ``triangles`` (m, 3) int64, counter-clockwise seen
    from outside; ``material`` a key of the twin's materials (:mod:`synthua_usd.model.materials` for ours).

    Its job: the unit importers and procedural assets produce and the twin writer authors. It carries
    the part name and source attributes that become prim names and ``synthua:`` attributes; it has no
    class (its :class:`TwinObject` has) and no world placement beyond its points. Builders of raw
    geometry use :data:`synthua_usd.model.meshes.Mesh`; renderers see :class:`synthua_usd.model.scene.MeshItem`.
    """

    name: str
    points: np.ndarray = field(repr=False)
    triangles: np.ndarray = field(repr=False)
    material: str
    attributes: dict = field(default_factory=dict)
    #: (n, 2) float32 texture coordinates per point in USD's st convention (authored as ``primvars:st``), or
    #: None. Parts whose material has textures need them (:func:`synthua_usd.geometry.uv` makes them).
    uvs: np.ndarray | None = field(default=None, repr=False)

    @classmethod
    def of(cls, name: str, mesh: Mesh, material: str, **attributes) -> "TwinPart":
        """A part from a ``(points, triangles)`` mesh of :mod:`synthua_usd.model.meshes`."""
        return cls(name, np.asarray(mesh[0], np.float64), np.asarray(mesh[1], np.int64), material, attributes)

    @property
    def mesh(self) -> Mesh:
        return self.points, self.triangles

    def moved(self, points: np.ndarray) -> "TwinPart":
        """The same part with new ``points`` (same topology)."""
        return TwinPart(self.name, points, self.triangles, self.material, self.attributes, self.uvs)

    def renamed(self, name: str) -> "TwinPart":
        """The same part under another ``name``."""
        return TwinPart(name, self.points, self.triangles, self.material, self.attributes, self.uvs)

    def with_mesh(self, points: np.ndarray, triangles: np.ndarray, uvs: np.ndarray | None) -> "TwinPart":
        """The same part with new geometry and texture coordinates (e.g. points split at texture seams)."""
        return TwinPart(self.name, points, triangles, self.material, self.attributes, uvs)

    def __post_init__(self) -> None:
        if self.points.ndim != 2 or self.points.shape[1] != 3:
            raise InputError(f"part {self.name}: points of shape {self.points.shape}; expected (n, 3)")
        if not np.all(np.isfinite(self.points)):
            raise InputError(f"part {self.name}: points contain NaN or infinite coordinates; expected finite metres")
        if self.triangles.ndim != 2 or self.triangles.shape[1] != 3:
            raise InputError(f"part {self.name}: triangles of shape {self.triangles.shape}; expected (m, 3) vertex "
                             f"indices")
        if len(self.triangles) and (self.triangles.min() < 0 or self.triangles.max() >= len(self.points)):
            raise InputError(f"part {self.name}: triangle indices reach outside its {len(self.points)} points; "
                             f"expected indices in [0, {len(self.points) - 1}]")
        if self.uvs is not None:
            uvs = np.asarray(self.uvs)
            if uvs.shape != (len(self.points), 2) or not np.all(np.isfinite(uvs)):
                raise InputError(f"part {self.name}: texture coordinates of shape {uvs.shape}; expected "
                                 f"({len(self.points)}, 2) finite numbers, one pair per point")
            object.__setattr__(self, "uvs", uvs.astype(np.float32))


@dataclass(frozen=True, eq=False)
class TwinObject:
    """A labelled object: one instance of ``label`` (a class name of the class map) made of parts.

    ``path`` is relative to ``/World/Twin`` and may contain '/' to group objects.
    """

    path: str
    label: str
    parts: tuple[TwinPart, ...]
    attributes: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class TwinModel:
    """Everything an importer or generator produced, plus provenance for stage metadata.

    ``images`` are the texture images the materials' textures name: each texture's ``path`` (relative to
    the folder the twin layer is written in, e.g. ``textures/asphalt.png``) → (H, W, C) uint8 pixels, C 1 to
    4, row 0 at the image's top. They are written beside the twin layer, with it (:mod:`synthua_usd.core.texture_images`).
    """

    objects: tuple[TwinObject, ...]
    materials: dict[str, Material]
    source: str
    origin_offset_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    crs: str | None = None
    report: dict = field(default_factory=dict)
    images: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    #: True when the source does not guarantee closed, outward-facing shells (meshes, CityJSON, point-cloud
    #: surfaces): every mesh is authored ``doubleSided`` and renders lit from both sides. False when the
    #: builder closes its shells itself, facing out (footprint extrusions, the demo district).
    double_sided: bool = False

    def triangle_count(self) -> int:
        return int(sum(len(p.triangles) for o in self.objects for p in o.parts))

    def labelled_triangles(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All triangles in one soup: vertices (n, 3) float64, faces (m, 3) int64 and the class label of
        each face (m,) object, as the walkable grid of the agents wants them."""
        verts, faces, labels, offset = [], [], [], 0
        for obj in self.objects:
            for part in obj.parts:
                verts.append(part.points)
                faces.append(part.triangles + offset)
                labels.append(np.full(len(part.triangles), obj.label, object))
                offset += len(part.points)
        if not verts:
            return np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros(0, object)
        return np.concatenate(verts), np.concatenate(faces), np.concatenate(labels)

    def label_counts(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for o in self.objects:
            out[o.label] = out.get(o.label, 0) + 1
        return dict(sorted(out.items()))


def unique_paths(objects: list[TwinObject]) -> list[TwinObject]:
    """Make object paths unique by suffixing _2, _3, ... in order."""
    seen: dict[str, int] = {}
    out = []
    for o in objects:
        path = o.path
        if path in seen:
            seen[path] += 1
            path = f"{path}_{seen[o.path]}"
        else:
            seen[path] = 1
        out.append(o if path == o.path else TwinObject(path, o.label, o.parts, o.attributes))
    return out
