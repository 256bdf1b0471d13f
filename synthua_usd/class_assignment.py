"""Rule-based semantic assignment for imported geometry: (field, regex) → class, first match wins.

Rules files are JSON documents checked against ``schemas/semantic_rules.schema.json``; every class a
rule names must exist in the class map, and every pattern must compile.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from synthua_usd.errors import InputError
from synthua_usd.schemas import read_json, validate_document
from synthua_usd.taxonomy import ClassMap

FIELDS = ("object", "material", "group", "type", "las_class")


@dataclass(frozen=True)
class Rule:
    field: str
    pattern: re.Pattern
    class_name: str

    def matches(self, fields: dict[str, str]) -> bool:
        keys = FIELDS if self.field == "any" else (self.field,)
        return any(fields.get(k) is not None and self.pattern.search(str(fields[k])) for k in keys)


@dataclass(frozen=True)
class AssignmentRules:
    rules: tuple[Rule, ...]
    default: str = "unlabelled"
    source: str = "(built in)"

    @classmethod
    def from_document(cls, doc: dict, class_map: ClassMap, source: str = "(in memory)") -> "AssignmentRules":
        validate_document(doc, "semantic_rules", source)
        rules = []
        for i, r in enumerate(doc["rules"]):
            try:
                pattern = re.compile(r["pattern"], re.IGNORECASE)
            except re.error as exc:
                raise InputError(f"{source}: rules[{i}].pattern '{r['pattern']}' is not a valid regular expression: "
                                 f"{exc}") from None
            cls_ = class_map.resolve(r["class"])
            if cls_ is None:
                raise InputError(f"{source}: rules[{i}].class '{r['class']}' is not a class of {class_map.source}")
            rules.append(Rule(r["field"], pattern, cls_.name))
        default = doc.get("default", "unlabelled")
        if class_map.resolve(default) is None:
            raise InputError(f"{source}: default class '{default}' is not a class of {class_map.source}")
        return cls(tuple(rules), class_map.resolve(default).name, source)

    @classmethod
    def load(cls, path: str | Path, class_map: ClassMap) -> "AssignmentRules":
        return cls.from_document(read_json(path), class_map, str(path))

    def classify(self, fields: dict[str, str]) -> tuple[str, int | None]:
        """(class name, index of the rule that matched, or None for the default)."""
        for i, rule in enumerate(self.rules):
            if rule.matches(fields):
                return rule.class_name, i
        return self.default, None
