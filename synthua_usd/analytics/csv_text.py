"""CSV text of analytics tables: one header, ``\\n`` line ends, empty cells for None, floats by ``repr`` (exact),
as the dataset's own ``metadata.csv`` writes them."""

from __future__ import annotations

import csv
import io


def csv_text(header: list[str], rows: list[list]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow(["" if v is None else (repr(v) if isinstance(v, float) else v) for v in row])
    return buf.getvalue()
