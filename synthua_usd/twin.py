"""A digital twin as plain data: labelled objects made of triangle meshes, before it becomes USD layers.

Importers (:mod:`synthua_usd.importers`) and procedural generators produce a :class:`TwinModel`;
:func:`synthua_usd.usd.twin_writer.write_twin` turns it into a twin layer and a semantics layer.
Coordinates are local metres, Z up; ``origin_offset_m`` is what was subtracted from the source.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from synthua_usd.errors import InputError
from synthua_usd.scene import Material

_NAME_OK = re.compile(r"[^A-Za-z0-9_]")


def prim_name(text: str, fallback: str = "Object") -> str:
    """A valid USD prim name from arbitrary source text (letters, digits, underscores; no leading digit)."""
    name = _NAME_OK.sub("_", str(text)).strip("_") or fallback
    return f"_{name}" if name[0].isdigit() else name


@dataclass(frozen=True, eq=False)
class TwinPart:
    """One mesh: ``points`` (n, 3) float64 local metres, ``triangles`` (m, 3) int64, a material key."""

    name: str
    points: np.ndarray = field(repr=False)
    triangles: np.ndarray = field(repr=False)
    material: str
    attributes: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.points.ndim != 2 or self.points.shape[1] != 3:
            raise InputError(f"part {self.name}: points should be (n, 3), but were {self.points.shape}")
        if not np.all(np.isfinite(self.points)):
            raise InputError(f"part {self.name}: points contain NaN or infinite coordinates")
        if len(self.triangles) and (self.triangles.min() < 0 or self.triangles.max() >= len(self.points)):
            raise InputError(f"part {self.name}: triangle indices reach outside its {len(self.points)} points")


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
    """Everything an importer or generator produced, plus provenance for stage metadata."""

    objects: tuple[TwinObject, ...]
    materials: dict[str, Material]
    source: str
    origin_offset_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    crs: str | None = None
    report: dict = field(default_factory=dict)

    def triangle_count(self) -> int:
        return int(sum(len(p.triangles) for o in self.objects for p in o.parts))

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
