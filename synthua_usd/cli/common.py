"""What every ``synthua`` subcommand module shares: exit statuses, printing a line of output, and the time-code
options' parser (a ``--class-map`` option is read by :meth:`synthua_usd.model.taxonomy.ClassMap.load_or_bundled`)."""

from __future__ import annotations

import click

from synthua_usd.cli.failures import EXIT_FINDINGS, EXIT_INPUT, EXIT_OK  # noqa: F401 (re-exported)
from synthua_usd.core.errors import escape_controls
from synthua_usd.model.timecodes import parse_time_code_spec


def say(line: str) -> None:
    """Print ``line`` on stdout as one line, its control characters escaped as in the error messages: a path
    the user typed with a newline or a terminal escape in it cannot split the line or reach the terminal."""
    click.echo(escape_controls(line))


def parse_time_codes(ctx, param, values: tuple[str, ...]) -> tuple[float, ...]:
    """``--time-code 24 --time-code 1:48:8 --frame 1,12``: single time codes, comma lists, and START:END[:STEP]
    ranges with END included when the steps reach it (:func:`synthua_usd.model.timecodes.parse_time_code_spec`)."""
    out: list[float] = []
    for value in values:
        try:
            out += parse_time_code_spec(value)
        except ValueError as exc:
            raise click.BadParameter(f"{value!r} is not a time code, a comma list or a range; expected {exc}", ctx,
                                     param) from None
    return tuple(dict.fromkeys(out))
