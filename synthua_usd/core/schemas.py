"""The JSON Schemas bundled with the package (the top-level ``schemas/`` folder) and validation against them."""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema

from synthua_usd.core.errors import InputError, SchemaError, echo
from synthua_usd.core.input_files import MAX_DOCUMENT_BYTES, read_input_text, shown

SCHEMA_PACKAGE = "synthua_usd.schema_files"


def bundled_path(name: str) -> Path:
    """Filesystem path of a file shipped in ``schemas/`` (e.g. ``classmap.json``)."""
    path = Path(str(resources.files(SCHEMA_PACKAGE).joinpath(name)))
    if not path.is_file():
        raise InputError(f"{name}: no such bundled schema file in {path.parent}")
    return path


@lru_cache(maxsize=None)
def load_schema(name: str) -> dict:
    """The JSON Schema ``schemas/<name>.schema.json`` as a dict. Not checked against the metaschema here (that
    took ~1 s of every process, which reads all of them): ``tests/core/test_schemas.py`` checks every bundled
    schema."""
    return json.loads(bundled_path(f"{name}.schema.json").read_text(encoding="utf-8"))


def bundled_schema_names() -> list[str]:
    """The names of every bundled schema (``generate`` for ``schemas/generate.schema.json``), sorted."""
    suffix = ".schema.json"
    return sorted(f.name[:-len(suffix)] for f in resources.files(SCHEMA_PACKAGE).iterdir() if f.name.endswith(suffix))


#: Where the bundled schemas live as URIs: one refers to a part of another by its file name, e.g.
#: ``frame.schema.json#/properties/condition``, which resolves here, never on the network.
SCHEMA_BASE = "https://synthua-usd.org/schemas/"


@lru_cache(maxsize=None)
def _registry():
    """Every bundled schema, by :data:`SCHEMA_BASE` + its file name."""
    from referencing import Registry
    from referencing.jsonschema import DRAFT202012

    return Registry().with_resources((f"{SCHEMA_BASE}{name}.schema.json", DRAFT202012.create_resource(load_schema(name)))
                                     for name in bundled_schema_names())


#: Deepest nesting of arrays and objects accepted in a JSON document. CityJSON's MultiSolid boundaries, the
#: deepest structure we read, sit about 10 levels down; without a limit a deep document would exhaust the
#: recursion of the parser or of schema validation.
MAX_JSON_DEPTH = 64
#: Longest integer accepted in a JSON document (uint64 has 20 digits); Python refuses to convert integers of
#: more than 4300 digits at all, and no field we read needs more.
MAX_INTEGER_DIGITS = 20


class _Refused(ValueError):
    """A JSON token the parser hooks refuse (the message is the what-was-found part)."""


def _parse_int(text: str) -> int:
    digits = len(text.lstrip("-"))
    if digits > MAX_INTEGER_DIGITS:
        raise _Refused(f"an integer of {digits} digits ({text[:12]}...); expected at most {MAX_INTEGER_DIGITS} digits")
    return int(text)


def _parse_float(text: str) -> float:
    value = float(text)
    if value in (float("inf"), float("-inf")):
        raise _Refused(f"the number {text[:40]} is beyond double precision; expected finite numbers")
    return value


def _parse_constant(name: str):
    raise _Refused(f"{name} is not JSON; expected finite numbers (NaN and Infinity are not allowed)")


def _depth(document: Any) -> int:
    """Nesting depth of arrays and objects (a scalar document has depth 0), without recursion."""
    deepest, stack = 0, [(document, 1)]
    while stack:
        node, depth = stack.pop()
        children = node.values() if isinstance(node, dict) else node if isinstance(node, list) else None
        if children is None:
            continue
        deepest = max(deepest, depth)
        if depth > MAX_JSON_DEPTH:
            break
        stack.extend((child, depth + 1) for child in children if isinstance(child, (dict, list)))
    return deepest


def read_json(path: str | Path, what: str = "a JSON document") -> Any:
    """Parse a JSON file (a regular file of at most :data:`MAX_DOCUMENT_BYTES`, UTF-8, strict RFC 8259
    numbers, at most :data:`MAX_JSON_DEPTH` levels deep); anything else raises :class:`InputError` naming
    the file."""
    path = Path(path)
    text = read_input_text(path, MAX_DOCUMENT_BYTES, what)
    try:
        document = json.loads(text, parse_int=_parse_int, parse_float=_parse_float, parse_constant=_parse_constant)
    except json.JSONDecodeError as exc:
        raise InputError(f"{shown(path)}: not valid JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}; "
                         f"expected {what}") from None
    except _Refused as exc:
        raise InputError(f"{shown(path)}: {exc}") from None
    except RecursionError:
        raise InputError(f"{shown(path)}: nested too deeply to parse; expected at most {MAX_JSON_DEPTH} levels of "
                         f"arrays and objects") from None
    depth = _depth(document)
    if depth > MAX_JSON_DEPTH:
        raise InputError(f"{shown(path)}: nested more than {MAX_JSON_DEPTH} levels deep; expected at most "
                         f"{MAX_JSON_DEPTH} levels of arrays and objects")
    return document


def type_name(value: Any) -> str:
    """The JSON name of a value's type, for messages: object, array, string, number, boolean, null."""
    if isinstance(value, bool):
        return "a boolean"
    return {dict: "an object", list: "an array", str: "a string", int: "a number", float: "a number",
            type(None): "null"}.get(type(value), type(value).__name__)


def schema_errors(document: Any, schema_name: str, definition: str | None = None) -> list[jsonschema.ValidationError]:
    """All violations of ``schemas/<schema_name>.schema.json`` (of its ``$defs/<definition>`` when given), most
    specific first."""
    schema = (load_schema(schema_name) if definition is None
              else {"$ref": f"{SCHEMA_BASE}{schema_name}.schema.json#/$defs/{definition}"})
    validator = jsonschema.Draft202012Validator(schema, registry=_registry())
    return sorted(validator.iter_errors(document), key=lambda e: (list(e.absolute_path), e.message))


def json_pointer(error: jsonschema.ValidationError) -> str:
    """Where in the document an error is, as ``classes[3].color``."""
    out = ""
    for part in error.absolute_path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "(document)"


def schema_message(error: jsonschema.ValidationError) -> str:
    """A violation's message with a long echoed value cut (jsonschema starts most messages with the
    value's repr, which can be a whole document)."""
    message, value = error.message, repr(error.instance)
    if message.startswith(value) and len(value) > 60:
        message = echo(value[:57] + "...") + message[len(value):]
    return message


def unknown_key(where: str, key: str, valid) -> str:
    """``<where>.<key>: not a key of <where>; expected <nearest>, the nearest valid key (valid: ...)``: a misspelt key
    named with the key it most likely meant (difflib), or the valid keys when none is near."""
    import difflib

    valid = sorted(valid)
    top = not where or where == "(document)"
    field, parent = (echo(key, 60), "the document") if top else (f"{where}.{echo(key, 60)}", where)
    near = difflib.get_close_matches(str(key), valid, n=1, cutoff=0.6)
    listed = ", ".join(valid)
    if near:
        return f"{field}: not a key of {parent}; expected {near[0]}, the nearest valid key (valid: {listed})"
    return f"{field}: not a key of {parent}; expected one of {listed}"


def _specific(error: jsonschema.ValidationError) -> jsonschema.ValidationError:
    """The violation that says what is wrong: inside a ``oneOf``/``anyOf`` (``randomise``: null or the block), the
    branch's own (jsonschema's ``best_match``: a misspelt key of the block, not "is not valid under any of the
    given schemas")."""
    from jsonschema.exceptions import best_match

    return best_match([error]) if error.context else error


def _extra_key(error: jsonschema.ValidationError) -> str | None:
    """:func:`unknown_key` for an ``additionalProperties`` violation of an object with listed properties."""
    import re

    schema, instance = error.schema, error.instance
    if error.validator != "additionalProperties" or not isinstance(schema, dict) or not isinstance(instance, dict):
        return None
    known = schema.get("properties") or {}
    patterns = list(schema.get("patternProperties") or {})
    extra = [k for k in instance if k not in known and not any(re.search(p, k) for p in patterns)]
    if not extra or not known:
        return None
    return unknown_key(json_pointer(error), extra[0], known)


def schema_problem(document: Any, schema_name: str, definition: str | None = None) -> str | None:
    """The first violation as ``<field>: <what was found>; expected ...`` (None when there is none); a misspelt key
    as :func:`unknown_key` says it."""
    errors = schema_errors(document, schema_name, definition)
    if not errors:
        return None
    first = _specific(errors[0])
    more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
    part = f"$defs/{definition} of " if definition is not None else ""
    extra = _extra_key(first)
    if extra is not None:
        return f"{extra}{more}"
    return (f"{json_pointer(first)}: {schema_message(first)}; expected a document matching "
            f"{part}{schema_name}.schema.json{more}")


def validate_document(document: Any, schema_name: str, source: str, definition: str | None = None) -> None:
    """Raise :class:`SchemaError` with the first violation, naming ``source`` and the field."""
    problem = schema_problem(document, schema_name, definition)
    if problem is not None:
        raise SchemaError(f"{shown(source)}: {problem}")
