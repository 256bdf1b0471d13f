"""The semantic class taxonomy: classes with ids, names, colours and groups, loaded from a class map."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import bundled_path, read_json, validate_document

#: The wheelchair classes (each with its seated user).
WHEELCHAIRS = ("manual_wheelchair", "electric_wheelchair")


@dataclass(frozen=True)
class SemanticClass:
    """One class. ``color`` is sRGB, 8 bits a channel; ``isthing`` means countable instances."""

    id: int
    name: str
    display_name: str
    color: tuple[int, int, int]
    group: str
    isthing: bool
    aliases: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        return {"id": self.id, "name": self.name, "display_name": self.display_name,
                "color": list(self.color), "group": self.group, "isthing": self.isthing,
                "aliases": list(self.aliases)}


@dataclass(frozen=True)
class ClassMap:
    """All classes of one taxonomy. Build with :meth:`load` or :meth:`from_document`."""

    taxonomy: str
    classes: tuple[SemanticClass, ...]
    source: str = "(in memory)"

    @classmethod
    def default(cls) -> "ClassMap":
        """The project's class map, ``schemas/classmap.json``."""
        return cls.load(bundled_path("classmap.json"))

    @classmethod
    def load_or_bundled(cls, path: str | Path | None) -> "ClassMap":
        """The class map at ``path`` (a command's ``--class-map``), or the bundled one (:meth:`default`) when None:
        the one rule of every command that takes a class map."""
        return cls.load(path) if path else cls.default()

    @classmethod
    def load(cls, path: str | Path) -> "ClassMap":
        """Read, schema-check and rule-check a class map file; unusable maps raise :class:`InputError`."""
        return cls.from_document(read_json(path, "a class map (schemas/classmap.schema.json)"), source=str(path))

    @classmethod
    def from_document(cls, document: dict, source: str = "(in memory)") -> "ClassMap":
        # Imported here: the rules module builds on this one's data types.
        from synthua_usd.core.findings import Severity
        from synthua_usd.model.classmap_checks import REFUSING_RULES, check_classmap_rules

        validate_document(document, "classmap", source)
        errors = [f for f in check_classmap_rules(document, REFUSING_RULES) if f.severity is Severity.ERROR]
        if errors:
            more = f" (and {len(errors) - 1} more; run `synthua validate classes {source}`)" if len(errors) > 1 else ""
            raise InputError(f"{shown(source)}: {errors[0].where}: {errors[0].message}{more}")
        classes = tuple(
            SemanticClass(id=c["id"], name=c["name"], display_name=c["display_name"], color=tuple(c["color"]),
                          group=c["group"], isthing=c["isthing"], aliases=tuple(c["aliases"]))
            for c in sorted(document["classes"], key=lambda c: c["id"]))
        return cls(taxonomy=document["taxonomy"], classes=classes, source=source)

    def document(self) -> dict:
        """The class map as a document of ``schemas/classmap.schema.json`` (what :meth:`from_document` reads)."""
        return {"$schema": "classmap.schema.json", "taxonomy": self.taxonomy,
                "classes": [c.to_dict() for c in self.classes]}

    def resolve(self, label: str) -> SemanticClass | None:
        """The class whose name is ``label``, or whose alias matches it case-insensitively; else None."""
        return self._index().get(label) or self._index().get(label.casefold())

    def by_id(self, class_id: int) -> SemanticClass:
        for c in self.classes:
            if c.id == class_id:
                return c
        raise KeyError(f"class id {class_id} is not in class map {self.source}")

    def _index(self) -> dict[str, SemanticClass]:
        cached = self.__dict__.get("_index_cache")
        if cached is None:
            cached = {}
            for c in self.classes:
                cached[c.name] = c
                for alias in c.aliases:
                    cached[alias.casefold()] = c
                cached.setdefault(c.name.casefold(), c)
            object.__setattr__(self, "_index_cache", cached)
        return cached

    def palette(self) -> np.ndarray:
        """(256, 3) uint8 lookup table from class id to sRGB colour; unused ids are black."""
        lut = np.zeros((256, 3), np.uint8)
        for c in self.classes:
            lut[c.id] = c.color
        return lut
