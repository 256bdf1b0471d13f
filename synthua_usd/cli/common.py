"""What every ``synthua`` subcommand module shares: exit statuses and the class-map option's loader."""

from __future__ import annotations

import math
from pathlib import Path

import click

from synthua_usd.cli.failures import EXIT_FINDINGS, EXIT_INPUT, EXIT_OK  # noqa: F401 (re-exported)


def load_class_map(path: Path | None):
    """The class map at ``path``, or the bundled one."""
    from synthua_usd.taxonomy import ClassMap

    return ClassMap.load(path) if path else ClassMap.default()


def parse_time_codes(ctx, param, values: tuple[str, ...]) -> tuple[float, ...]:
    """``--time-code 24 --time-code 1:48:8 --frame 1,12``: single time codes, comma lists, and START:END[:STEP]
    ranges with END included when the steps reach it."""
    out: list[float] = []
    for value in values:
        for item in value.split(","):
            item = item.strip()
            try:
                if ":" in item:
                    parts = [float(x) for x in item.split(":")]
                    if len(parts) not in (2, 3):
                        raise ValueError
                    start, end, step = parts[0], parts[1], parts[2] if len(parts) == 3 else 1.0
                    if not (all(map(math.isfinite, parts)) and step > 0 and end >= start):
                        raise ValueError
                    count = int(math.floor((end - start) / step + 1e-9)) + 1
                    if count > 100_000:
                        raise click.BadParameter(f"{item!r} holds {count} time codes; at most 100000", ctx, param)
                    out += [start + k * step for k in range(count)]
                else:
                    number = float(item)
                    if not math.isfinite(number):
                        raise ValueError
                    out.append(number)
            except ValueError:
                raise click.BadParameter(f"{item!r} is not a time code, a comma list or START:END[:STEP] with "
                                         f"finite numbers, STEP > 0 and END >= START", ctx, param) from None
    return tuple(dict.fromkeys(out))
