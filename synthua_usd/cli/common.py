"""What every ``synthua`` subcommand module shares: exit statuses and the class-map option's loader."""

from __future__ import annotations

from pathlib import Path

from synthua_usd.cli.failures import EXIT_FINDINGS, EXIT_INPUT, EXIT_OK  # noqa: F401 (re-exported)


def load_class_map(path: Path | None):
    """The class map at ``path``, or the bundled one."""
    from synthua_usd.taxonomy import ClassMap

    return ClassMap.load(path) if path else ClassMap.default()
