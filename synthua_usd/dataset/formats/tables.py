"""The metadata table (``metadata.csv`` and ``metadata.parquet``): one row per image, rejected ones included.

Columns, in this order:

* ``image_id, name, split, width, height, camera_path, camera_name, rig_type, fx, fy, cx, cy`` (pixels),
  ``focal_length_mm, horizontal_aperture_mm, vertical_aperture_mm``;
* ``camera_to_world_RC`` and ``world_to_camera_opencv_RC`` for row R and column C of the two 4x4 matrices
  (world metres; the second is the OpenCV extrinsic: x right, y down, z forward);
* ``time_code, seed, condition`` (its name) and ``condition.KEY`` for each parameter of any record's
  condition (a list or dict parameter is JSON text);
* ``instances.CLASS`` and ``pixels.CLASS`` for every class of the class map (instances: the record's
  instance entries of that class; pixels: its class pixel counts);
* ``qa_verdict``, ``qa_reasons`` (joined by ``"; "``) and ``qa.MEASURE`` for each QA measure;
* in a dataset of ``synthua composite``: ``background`` (the photo's path), ``background_labelled``,
  ``background_monochrome``, ``horizon_row_px``, ``camera_height_m``, ``pastes`` and the photo's ``boxes_kept`` and
  ``boxes_dropped``.

A value a record does not have is empty in the CSV and null in Parquet.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Iterable

import pyarrow as pa
import pyarrow.parquet as pq

from synthua_usd.core import json_text
from synthua_usd.core.atomic import atomic_path
from synthua_usd.core.errors import OutputError
from synthua_usd.dataset.formats.records import ordered
from synthua_usd.dataset.record import DatasetRecord
from synthua_usd.model.taxonomy import ClassMap


def _matrix(prefix: str, matrix) -> dict:
    if matrix is None:
        return {f"{prefix}_{r}{c}": None for r in range(4) for c in range(4)}
    return {f"{prefix}_{r}{c}": float(matrix[r][c]) for r in range(4) for c in range(4)}


def _scalar(value):
    if isinstance(value, (list, tuple, dict)):
        return json_text.dumps(value, sort_keys=True, ascii_only=True)
    return value


def _camera_columns(record: DatasetRecord) -> dict:
    """The camera's columns: a rendered image's camera prim, intrinsics and extrinsics; a composite's intrinsics only
    (its photo's camera has no prim, lens or pose: None there)."""
    if "composite" in record:
        K = record["camera"]["K"]
        return {"camera_path": None, "camera_name": None, "rig_type": None, "fx": float(K[0][0]), "fy": float(K[1][1]),
                "cx": float(K[0][2]), "cy": float(K[1][2]), "focal_length_mm": None, "horizontal_aperture_mm": None,
                "vertical_aperture_mm": None} | _matrix("camera_to_world", None) | _matrix("world_to_camera_opencv", None)
    cam = record["camera"]
    K = cam["K"]
    return ({"camera_path": cam["prim_path"], "camera_name": cam["name"], "rig_type": cam["rig_type"],
             "fx": float(K[0][0]), "fy": float(K[1][1]), "cx": float(K[0][2]), "cy": float(K[1][2]),
             "focal_length_mm": cam["focal_length_mm"], "horizontal_aperture_mm": cam["horizontal_aperture_mm"],
             "vertical_aperture_mm": cam["vertical_aperture_mm"]}
            | _matrix("camera_to_world", cam["camera_to_world"])
            | _matrix("world_to_camera_opencv", cam["world_to_camera_opencv"]))


def _condition(record: DatasetRecord) -> dict:
    """The record's condition (its name and parameters); empty for a composite (a photo's light is not rendered)."""
    return {} if "composite" in record else record["condition"] or {}


def metadata_rows(records: Iterable[DatasetRecord], class_map: ClassMap) -> list[dict]:
    """One dict per record, by image id, every dict with the same keys in the same order (see module)."""
    records = ordered(records)
    condition_keys = sorted({k for r in records for k in _condition(r) if k != "name"})
    measure_keys = sorted({k for r in records for k in r["qa"]["measures"]})
    composites = any("composite" in r for r in records)
    rows = []
    for r in records:
        cond = _condition(r)
        qa = r["qa"]
        row = {"image_id": int(r["id"]), "name": r["name"], "split": r["split"],
               "width": int(r["width"]), "height": int(r["height"])} | _camera_columns(r)
        row |= {"time_code": None if "composite" in r else float(r["time_code"]), "seed": int(r["seed"]),
                "condition": cond.get("name")}
        row |= {f"condition.{k}": _scalar(cond.get(k)) for k in condition_keys}
        counts = {c.name: 0 for c in class_map.classes}
        for inst in r["instances"]:
            counts[class_map.by_id(inst["category_id"]).name] += 1
        pixels = r["class_pixel_counts"]
        row |= {f"instances.{c.name}": counts[c.name] for c in class_map.classes}
        row |= {f"pixels.{c.name}": int(pixels.get(c.name, 0)) for c in class_map.classes}
        row |= {"qa_verdict": qa["verdict"], "qa_reasons": "; ".join(qa["reasons"])}
        row |= {f"qa.{k}": qa["measures"].get(k) for k in measure_keys}
        if composites:
            row |= _composite_columns(r)
        rows.append(row)
    return rows


def _composite_columns(record: DatasetRecord) -> dict:
    """The columns of a composite (None for a rendered image in the same table)."""
    if "composite" not in record:
        return dict.fromkeys(("background", "background_labelled", "background_monochrome", "horizon_row_px",
                              "camera_height_m", "pastes", "boxes_kept", "boxes_dropped"))
    composite, camera = record["composite"], record["camera"]
    boxes = composite["background_boxes"]
    background = composite["background"]
    return {"background": background["path"], "background_labelled": background["labelled"],
            "background_monochrome": background.get("monochrome", False), "horizon_row_px": camera["horizon_row_px"],
            "camera_height_m": camera["height_m"], "pastes": len(composite["pastes"]),
            "boxes_kept": sum(b["kept"] for b in boxes), "boxes_dropped": sum(not b["kept"] for b in boxes)}


def write_tables(rows: list[dict], csv_path: str | Path, parquet_path: str | Path) -> None:
    """Write ``rows`` (same keys in each) as CSV (``csv`` module, ``\\n`` line ends, empty for None) and as
    Parquet (pyarrow, types inferred per column), each atomically."""
    columns = list(rows[0]) if rows else []
    for i, row in enumerate(rows):
        if list(row) != columns:
            raise OutputError(f"metadata row {i}: columns {list(row)[:3]}...; expected the columns of row 0")
    with atomic_path(csv_path) as tmp:
        with open(tmp, "w", newline="", encoding="utf-8") as f:
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow(columns)
            for row in rows:
                writer.writerow(["" if row[c] is None else _csv_text(row[c]) for c in columns])
    table = pa.table({c: _column([row[c] for row in rows]) for c in columns})
    with atomic_path(parquet_path) as tmp:
        pq.write_table(table, tmp)


def _csv_text(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _column(values: list) -> pa.Array:
    """A Parquet column of inferred type; a column mixing text and numbers (a condition parameter that is a
    number in one record and a word in another) is written as text, as in the CSV."""
    try:
        return pa.array(values)
    except (pa.ArrowInvalid, pa.ArrowTypeError):
        return pa.array([None if v is None else _csv_text(v) for v in values], pa.string())


def write_rejected(records: Iterable[DatasetRecord], path: str | Path) -> Path:
    """``rejected.csv``: every image QA rejected or flagged, with its verdict and reasons, in image order
    (nothing is dropped silently), atomically."""
    import io

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["image_id", "name", "verdict", "reasons"])
    for r in ordered(records):
        if r["qa"]["verdict"] != "accepted":
            writer.writerow([r["id"], r["name"], r["qa"]["verdict"], "; ".join(r["qa"]["reasons"])])
    with atomic_path(path) as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")
    return Path(path)
