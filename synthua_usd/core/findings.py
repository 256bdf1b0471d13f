"""Validation findings: rules collect them instead of raising; callers decide what is fatal."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from synthua_usd.core.errors import escape_controls


class Severity(enum.IntEnum):
    """How bad a finding is; ordered so that ``max()`` gives the worst."""

    INFO = 0
    WARNING = 1
    ERROR = 2


@dataclass(frozen=True)
class Finding:
    """One problem found by one rule.

    ``where`` is the offending entry: a prim path, a layer, or a class-map entry such as
    ``classes[12] 'light_pole'``. ``message`` says what was found, what was expected and how to fix it.
    """

    rule: str
    where: str
    message: str
    severity: Severity = Severity.ERROR

    def format(self) -> str:
        """One line: control characters of ``where`` and ``message`` (a layer path, a value) escaped."""
        return escape_controls(f"{self.severity.name.lower()}: {self.where}: {self.message} ({self.rule})")

    def to_dict(self) -> dict:
        return {"rule": self.rule, "where": self.where, "message": self.message,
                "severity": self.severity.name.lower()}

