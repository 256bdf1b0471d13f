"""Exception types. Every message names the file, prim or field, what was found and what was expected."""

import re


class SynthuaError(Exception):
    """Base class of the errors this package raises on purpose."""


class InputError(SynthuaError):
    """Unusable user input: a missing or malformed file, an unknown name, an impossible parameter.

    The CLI turns it into a one-line message and exit status 2.
    """


class SchemaError(InputError):
    """A JSON document does not conform to its JSON Schema."""


class StageError(InputError):
    """A USD stage cannot be opened or lacks what an operation needs (a camera, a time code, a label)."""


class UnsupportedPrimError(StageError):
    """A prim type the translator has no handler for."""


class OutputError(SynthuaError):
    """An output cannot be written: a path that is a file where a folder goes (or the reverse), an
    unwritable folder, a name too long, a full disk. Exit status 2; earlier results stay as they were."""


#: Longest piece of user input echoed in a message.
ECHO_LIMIT = 120


_CONTROL = re.compile(r"[\x00-\x1f\x7f\ud800-\udfff]")


def escape_controls(text: str) -> str:
    """``text`` with newlines and other control characters escaped (``\\n``, ``\\x1b``), and the lone surrogates
    that stand for the bytes of a file name that is not UTF-8 (``\\udce9``); other characters, accented letters
    included, kept as they are."""
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), str(text))


def echo(value, limit: int = ECHO_LIMIT) -> str:
    """``value`` as it may appear inside a one-line message: control characters escaped, cut to ``limit``
    characters."""
    out = escape_controls(value)
    return out if len(out) <= limit else out[:limit - 3] + "..."
