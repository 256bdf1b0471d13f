"""Which records (:data:`synthua_usd.dataset.record.DatasetRecord`) a dataset-level format holds: one rule for every
format (QA's rejected images are left out: :func:`synthua_usd.dataset.record.is_rejected`)."""

from __future__ import annotations

from typing import Iterable

from synthua_usd.core.errors import InputError
from synthua_usd.dataset.record import DatasetRecord, is_rejected


def ordered(records: Iterable[DatasetRecord]) -> list[DatasetRecord]:
    """All records sorted by image id (formats are then the same whatever order workers finished in);
    duplicate ids raise :class:`InputError`."""
    out = sorted(records, key=lambda r: r["id"])
    for a, b in zip(out, out[1:]):
        if a["id"] == b["id"]:
            raise InputError(f"records {a['name']!r} and {b['name']!r}: both have image id {a['id']}; "
                             f"expected unique image ids")
    return out


def in_split(records: Iterable[DatasetRecord], split: str) -> list[DatasetRecord]:
    """The accepted or flagged records of ``split``, by image id."""
    return [r for r in ordered(records) if r["split"] == split and not is_rejected(r)]


def image_entry(record: DatasetRecord) -> dict:
    """A COCO ``images`` entry: ``file_name`` relative to ``images/{split}/``."""
    return {"id": int(record["id"]), "file_name": f"{record['name']}.png",
            "width": int(record["width"]), "height": int(record["height"])}
