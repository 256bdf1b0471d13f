"""Collecting a procedural twin's objects in order, with unique prim paths: what the demo district and the
procedural settings (:mod:`synthua_usd.demo.settings`) build their :class:`~synthua_usd.model.twin.TwinModel` with."""

from __future__ import annotations

from synthua_usd.model.twin import TwinObject, TwinPart


class TwinBuilder:
    """Collects objects in order; names are made unique per folder (``<folder>/<stem>_<nnn>``)."""

    def __init__(self) -> None:
        self.objects: list[TwinObject] = []
        self._counts: dict[str, int] = {}

    def add(self, folder: str, stem: str, label: str, pieces: list[TwinPart], **attributes) -> str:
        """Add one labelled object made of ``pieces``; returns its path (relative to ``/World/Twin``)."""
        n = self._counts.get(f"{folder}/{stem}", 0)
        self._counts[f"{folder}/{stem}"] = n + 1
        path = f"{folder}/{stem}_{n:03d}"
        parts, seen = [], set()
        for i, p in enumerate(pieces):
            name = f"{p.name}_{i}" if p.name in seen else p.name  # repeated part names get their index
            seen.add(p.name)
            parts.append(p if name == p.name else TwinPart(name, p.points, p.triangles, p.material, uvs=p.uvs))
        parts = tuple(parts)
        self.objects.append(TwinObject(path, label, parts, attributes))
        return path

    def sub(self, stem: str, kind: str, k: int, label: str, pieces: list[TwinPart]) -> None:
        """Add a part of the object at ``stem`` that is an instance of its own (a building's door, window or
        mural): ``<stem>_<kind>_<kk>``."""
        folder, name = stem.rsplit("/", 1)
        self.objects.append(TwinObject(f"{folder}/{name}_{kind}_{k:02d}", label, tuple(pieces)))
