"""Exception types. Every message names the file, prim or field, what was found and what was expected."""


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
