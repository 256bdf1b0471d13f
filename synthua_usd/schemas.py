"""The JSON Schemas bundled with the package (the top-level ``schemas/`` folder) and validation against them."""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema

from synthua_usd.errors import InputError, SchemaError

SCHEMA_PACKAGE = "synthua_usd.schema_files"


def bundled_path(name: str) -> Path:
    """Filesystem path of a file shipped in ``schemas/`` (e.g. ``classmap.json``)."""
    path = Path(str(resources.files(SCHEMA_PACKAGE).joinpath(name)))
    if not path.is_file():
        raise InputError(f"{name}: no such bundled schema file in {path.parent}")
    return path


@lru_cache(maxsize=None)
def load_schema(name: str) -> dict:
    """The JSON Schema ``schemas/<name>.schema.json`` as a dict, checked to be a valid schema."""
    schema = json.loads(bundled_path(f"{name}.schema.json").read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator.check_schema(schema)
    return schema


def read_json(path: str | Path) -> Any:
    """Parse a JSON file; a missing or malformed file raises :class:`InputError` naming it."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read ({exc})") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not valid JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}") from None


def schema_errors(document: Any, schema_name: str) -> list[jsonschema.ValidationError]:
    """All violations of ``schemas/<schema_name>.schema.json``, most specific first."""
    validator = jsonschema.Draft202012Validator(load_schema(schema_name))
    return sorted(validator.iter_errors(document), key=lambda e: (list(e.absolute_path), e.message))


def json_pointer(error: jsonschema.ValidationError) -> str:
    """Where in the document an error is, as ``classes[3].color``."""
    out = ""
    for part in error.absolute_path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "(document)"


def validate_document(document: Any, schema_name: str, source: str) -> None:
    """Raise :class:`SchemaError` with the first violation, naming ``source`` and the field."""
    errors = schema_errors(document, schema_name)
    if errors:
        first = errors[0]
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        raise SchemaError(f"{source}: {json_pointer(first)}: {first.message}; "
                          f"expected a document matching {schema_name}.schema.json{more}")
