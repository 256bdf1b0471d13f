"""The JSON text of every document synthua writes: one encoder for records, manifests, configs, reports and the
documents it hands to other programs.

Values computed with NumPy reach documents as NumPy scalars (``numpy.bool_`` from a comparison, ``numpy.int64``
from an index, ``numpy.float32`` from a pixel): Python's ``json`` refuses them (``Object of type bool is not JSON
serializable``; only ``numpy.float64``, a ``float`` subclass, passes). Here each becomes the JSON type of its value
(bool, int, float); anything else that is not a JSON type (an array, a
path, a dataclass) is refused by :class:`NotJsonError`, naming where in the document it sits and what it is, so
that the bug is found at its owner and not in a worker halfway through a dataset.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np


class NotJsonError(TypeError):
    """A value in a document that has no JSON type; the message names its place (``$.camera.K[0]``) and type."""


def _plain(value: Any):
    """A NumPy scalar as the Python value of its JSON type; anything else refused."""
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    raise NotJsonError(type(value).__name__)


def dumps(document: Any, indent: int | None = None, sort_keys: bool = False, compact: bool = False,
          ascii_only: bool = False) -> str:
    """``document`` as JSON text; NumPy scalars as their JSON types. ``compact``: no spaces after separators (the
    canonical text digests are taken of); ``ascii_only``: characters beyond ASCII escaped (else kept as they are).
    Raises :class:`NotJsonError` naming the first value that is not a JSON type."""
    separators = (",", ":") if compact else None
    try:
        return json.dumps(document, indent=indent, sort_keys=sort_keys, separators=separators,
                          ensure_ascii=ascii_only, default=_plain)
    except NotJsonError:
        where, what = _first_foreign(document, "$")
        where, what = (where, what) if where else ("$", "unknown")
        raise NotJsonError(f"{where}: a value of type {what} is not a JSON type; expected a string, number, bool, "
                           f"null, list or object (a bug: a writer passed it on unconverted)") from None


_JSON_TYPES = (str, int, float, bool, type(None), np.bool_, np.integer, np.floating)


def _first_foreign(value: Any, where: str) -> tuple[str, str]:
    """Where, in a document that failed to encode, the first value without a JSON type is, and its type."""
    if isinstance(value, dict):
        for key, item in value.items():
            if not isinstance(key, (str, int, float, bool, type(None))):
                return f"{where} (a key)", type(key).__name__
            found = _first_foreign(item, f"{where}.{key}")
            if found[0]:
                return found
        return "", ""
    if isinstance(value, (list, tuple)):
        for k, item in enumerate(value):
            found = _first_foreign(item, f"{where}[{k}]")
            if found[0]:
                return found
        return "", ""
    if isinstance(value, _JSON_TYPES):
        return "", ""
    return where, type(value).__name__
