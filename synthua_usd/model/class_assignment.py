"""Rule-based semantic assignment for imported geometry: (field, regex) → class, first match wins.

Rules files are JSON documents checked against ``schemas/semantic_rules.schema.json``; every class a
rule names must exist in the class map, and every pattern must compile.

Patterns run on RE2 (``google-re2``), a linear-time engine: a rules file is user input, and a pattern such
as ``(a+)+$`` takes exponential time in a backtracking engine (Python's ``re``) on a name like
``aaaa...a!``. RE2 has no backreferences or lookaround; patterns that use them are refused.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import re2

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import read_json, validate_document
from synthua_usd.model.taxonomy import ClassMap

FIELDS = ("object", "material", "group", "type", "las_class")
#: Memory RE2 may use for one compiled pattern; a pattern needing more (``((a{100}){100}){100}``) is refused.
PATTERN_MEMORY_BYTES = 8 * 2**20


def compile_pattern(pattern: str, where: str):
    """``pattern`` compiled by RE2, case-insensitive; :class:`InputError` naming ``where`` when RE2 cannot
    run it."""
    options = re2.Options()
    options.case_sensitive = False
    options.log_errors = False  # RE2 would print the same error to the process's stderr
    options.max_mem = PATTERN_MEMORY_BYTES
    try:
        return re2.compile(pattern, options)
    except (re2.error, UnicodeError, ValueError, TypeError) as exc:
        reason = exc.args[0] if exc.args and not isinstance(exc, UnicodeError) else "text that is not UTF-8"
        reason = reason.decode("utf-8", "replace") if isinstance(reason, bytes) else str(reason)
        raise InputError(f"{where} '{echo(pattern)}' is not a valid regular expression for RE2 ({echo(reason)}); "
                         f"expected one without backreferences or lookaround (RE2 syntax, linear time)") from None


@dataclass(frozen=True)
class Rule:
    field: str
    pattern: object  # a compiled RE2 pattern (re2._Regexp): search(text) -> match or None
    class_name: str

    def matches(self, fields: dict[str, str]) -> bool:
        keys = FIELDS if self.field == "any" else (self.field,)
        return any(fields.get(k) is not None and self.pattern.search(_utf8(fields[k])) for k in keys)


def _utf8(value) -> str:
    """``value`` as text RE2 can take: lone surrogates (undecodable bytes in a source name) replaced."""
    text = str(value)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        text = text.encode("utf-8", "replace").decode("utf-8")
    return text


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
            pattern = compile_pattern(r["pattern"], f"{shown(source)}: rules[{i}].pattern")
            cls_ = class_map.resolve(r["class"])
            if cls_ is None:
                raise InputError(f"{shown(source)}: rules[{i}].class '{echo(r['class'])}' is not a class of "
                                 f"{shown(class_map.source)}; expected a class name or alias of it")
            rules.append(Rule(r["field"], pattern, cls_.name))
        default = doc.get("default", "unlabelled")
        if class_map.resolve(default) is None:
            raise InputError(f"{shown(source)}: default: '{echo(default)}' is not a class of {shown(class_map.source)}; "
                             f"expected a class name or alias of it")
        return cls(tuple(rules), class_map.resolve(default).name, source)

    @classmethod
    def load(cls, path: str | Path, class_map: ClassMap) -> "AssignmentRules":
        return cls.from_document(read_json(path, "a rules document (schemas/semantic_rules.schema.json)"), class_map,
                                 str(path))

    def classify(self, fields: dict[str, str]) -> tuple[str, int | None]:
        """(class name, index of the rule that matched, or None for the default)."""
        for i, rule in enumerate(self.rules):
            if rule.matches(fields):
                return rule.class_name, i
        return self.default, None
