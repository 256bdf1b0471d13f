"""Time-code specs as people type them: ``24``, ``1,12,24`` and ``START:END[:STEP]`` ranges (one parser for
the command line's ``--time-code`` and for generation configs)."""

from __future__ import annotations

import math

#: Most time codes one spec may hold.
MAX_TIME_CODES = 100_000


def parse_time_code_spec(text: str) -> tuple[float, ...]:
    """Time codes from ``"24"``, ``"1,12"`` and ``"START:END[:STEP]"`` ranges (END included when the steps
    reach it), in order, duplicates dropped. ``ValueError`` says what was expected."""
    out: list[float] = []
    expected = "comma-separated numbers and START:END[:STEP] ranges with finite numbers, STEP > 0 and END >= START"
    for item in (part.strip() for part in text.split(",")):
        try:
            parts = [float(x) for x in item.split(":")]
        except ValueError:
            raise ValueError(expected) from None
        if not all(map(math.isfinite, parts)) or len(parts) > 3:
            raise ValueError(expected)
        if len(parts) == 1:
            out.append(parts[0])
            continue
        start, end, step = parts[0], parts[1], parts[2] if len(parts) == 3 else 1.0
        if not (step > 0 and end >= start):
            raise ValueError(expected)
        count = int(math.floor((end - start) / step + 1e-9)) + 1
        if count + len(out) > MAX_TIME_CODES:
            raise ValueError(f"at most {MAX_TIME_CODES} time codes")
        out += [start + k * step for k in range(count)]
    return tuple(dict.fromkeys(out))
