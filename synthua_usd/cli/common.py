"""What every ``synthua`` subcommand module shares: exit statuses and the class-map option's loader."""

from __future__ import annotations

from pathlib import Path

EXIT_OK, EXIT_FINDINGS, EXIT_INPUT = 0, 1, 2


def load_class_map(path: Path | None):
    """The class map at ``path``, or the bundled one."""
    from synthua_usd.taxonomy import ClassMap

    return ClassMap.load(path) if path else ClassMap.default()
