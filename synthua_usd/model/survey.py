"""Photogrammetry helpers from SYNTHUA-DT §2.1: UAV flight planning and ground-control-point accuracy.

Flight plan (nadir images, flat ground): footprint W = 2·h·tan(θ/2); spacing between images
D = (1 − overlap)·W, frontal along a flight line and lateral between lines; ground sampling distance
GSD = sensor width · h / (focal length · image width in pixels).
GCP accuracy: per-point error e_i = sqrt(ΔX² + ΔY² + ΔZ²) and RMSE = sqrt(mean(ΔX² + ΔY² + ΔZ²)).
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import MAX_DOCUMENT_BYTES, read_input_text, shown
from synthua_usd.model.ranges import COORDINATE, Range, number_field

#: Stated range of every flight-plan parameter (the CLI builds its options from these).
LIMITS = {
    "altitude_m": Range(1, 20_000, "m"),
    "fov_deg": Range(1, 170, "deg"),
    "frontal_overlap": Range(0, 0.95),
    "lateral_overlap": Range(0, 0.95),
    "area_width_m": Range(1, 100_000, "m"),
    "area_length_m": Range(1, 100_000, "m"),
    "sensor_width_mm": Range(1, 100, "mm"),
    "focal_length_mm": Range(1, 2_000, "mm"),
    "image_width_px": Range(16, 100_000, "px", integer=True),
}
GSD_FIELDS = ("sensor_width_mm", "focal_length_mm", "image_width_px")
#: Most images a plan may have: far above any survey a person flies (the paper's 1.5 km² took 286).
MAX_IMAGES = 1_000_000
#: Accepted RMSE of a GCP report. GCP coordinates are projected metres within ranges.COORDINATE.
THRESHOLD = Range(0, 1_000, "m")


def _field(name: str) -> str:
    return name


def check_flight_input(values: dict, name: Callable[[str], str] = _field) -> None:
    """Raise :class:`InputError` for the first parameter outside :data:`LIMITS`, or a partial GSD set.
    ``name`` spells a field as the caller's user typed it (the CLI passes ``--altitude-m``)."""
    for field, allowed in LIMITS.items():
        value = values.get(field)
        if value is None and field in GSD_FIELDS:
            continue
        number_field(value, name(field), allowed)
    given = [f for f in GSD_FIELDS if values.get(f) is not None]
    if given and len(given) < len(GSD_FIELDS):
        missing = [name(f) for f in GSD_FIELDS if f not in given]
        raise InputError(f"{', '.join(missing)}: missing while {' and '.join(name(f) for f in given)} "
                         f"{'is' if len(given) == 1 else 'are'} given; expected {', '.join(name(f) for f in GSD_FIELDS)} to "
                         f"go together (for the GSD), or none of them")


@dataclass(frozen=True)
class FlightPlanInput:
    """A survey of a rectangular area. Overlaps are fractions; every field within :data:`LIMITS`."""

    altitude_m: float
    fov_deg: float
    frontal_overlap: float
    lateral_overlap: float
    area_width_m: float
    area_length_m: float
    sensor_width_mm: float | None = None
    focal_length_mm: float | None = None
    image_width_px: int | None = None

    def __post_init__(self) -> None:
        check_flight_input(asdict(self))


@dataclass(frozen=True)
class FlightPlan:
    footprint_m: float
    frontal_spacing_m: float
    lateral_spacing_m: float
    flight_lines: int
    images_per_line: int
    images: int
    gsd_m: float | None

    def to_dict(self) -> dict:
        return asdict(self)


def footprint_m(altitude_m: float, fov_deg: float) -> float:
    """Ground footprint W = 2·h·tan(θ/2) of a nadir image, metres."""
    return 2.0 * altitude_m * math.tan(math.radians(fov_deg) / 2.0)


def plan_flight(p: FlightPlanInput, name: Callable[[str], str] = _field) -> FlightPlan:
    """Lines across the area's width, images along its length, both ends covered. A plan of more than
    :data:`MAX_IMAGES` images raises :class:`InputError` (``name`` spells the parameters in it)."""
    w = footprint_m(p.altitude_m, p.fov_deg)
    frontal = (1.0 - p.frontal_overlap) * w
    lateral = (1.0 - p.lateral_overlap) * w
    # A tolerance keeps 300 m / 100 m at 3 spans although tan() leaves 99.999... m.
    lines = math.ceil(p.area_width_m / lateral - 1e-9) + 1
    per_line = math.ceil(p.area_length_m / frontal - 1e-9) + 1
    if lines * per_line > MAX_IMAGES:
        raise InputError(f"{name('area_width_m')} {p.area_width_m:g} x {name('area_length_m')} {p.area_length_m:g}: "
                         f"the plan needs {lines * per_line} images ({lines} lines of {per_line}); expected at most "
                         f"{MAX_IMAGES} images: fly higher ({name('altitude_m')}), use a wider {name('fov_deg')} "
                         f"or less overlap, or split the area")
    gsd = None
    if p.sensor_width_mm is not None:
        gsd = p.sensor_width_mm * p.altitude_m / (p.focal_length_mm * p.image_width_px)
    return FlightPlan(footprint_m=w, frontal_spacing_m=frontal, lateral_spacing_m=lateral, flight_lines=lines,
                      images_per_line=per_line, images=lines * per_line, gsd_m=gsd)


@dataclass(frozen=True)
class GcpReport:
    ids: tuple[str, ...]
    delta_m: np.ndarray  # (n, 3) float64: model − surveyed, metres
    threshold_m: float

    @property
    def errors_m(self) -> np.ndarray:
        """(n,) per-point 3-D error, metres."""
        return np.sqrt((self.delta_m ** 2).sum(axis=1))

    @property
    def rmse_m(self) -> float:
        return float(math.sqrt(np.mean((self.delta_m ** 2).sum(axis=1))))

    @property
    def rmse_xyz_m(self) -> tuple[float, float, float]:
        return tuple(float(v) for v in np.sqrt(np.mean(self.delta_m ** 2, axis=0)))

    @property
    def passed(self) -> bool:
        return self.rmse_m <= self.threshold_m

    def to_dict(self) -> dict:
        return {"points": [{"id": i, "dx_m": d[0], "dy_m": d[1], "dz_m": d[2], "error_m": e}
                           for i, d, e in zip(self.ids, self.delta_m.tolist(), self.errors_m.tolist())],
                "rmse_m": self.rmse_m, "rmse_xyz_m": list(self.rmse_xyz_m), "threshold_m": self.threshold_m,
                "passed": self.passed}


def read_points_csv(path: str | Path) -> dict[str, np.ndarray]:
    """GCPs from a CSV with columns id, x, y, z (metres, any projected CRS shared by both files): id →
    (3,) float64. The file is a regular UTF-8 file of at most 64 MiB; coordinates within
    :data:`COORDINATE`."""
    path = Path(path)
    where = shown(path)
    text = read_input_text(path, MAX_DOCUMENT_BYTES, "a CSV table with a header id,x,y,z")
    reader = csv.reader(io.StringIO(text, newline=""))
    out: dict[str, np.ndarray] = {}
    try:
        header = [f.strip().lower() for f in next(reader, [])]
        missing = [c for c in ("id", "x", "y", "z") if c not in header]
        if missing:
            raise InputError(f"{where}: missing columns {missing}; expected a header with id,x,y,z, found "
                             f"{echo(header)}")
        column = {c: header.index(c) for c in ("id", "x", "y", "z")}
        for row in reader:
            line = reader.line_num
            if not any(cell.strip() for cell in row):
                continue  # blank lines
            if len(row) < len(header):
                raise InputError(f"{where}: line {line}: {len(row)} fields; expected {len(header)} as in the header")
            gcp = row[column["id"]].strip()
            if not gcp:
                raise InputError(f"{where}: line {line}: the id is empty; expected a GCP name")
            xyz = np.array([number_field(row[column[c]].strip(), f"{where}: line {line}: {c}", COORDINATE, text=True)
                            for c in ("x", "y", "z")])
            if gcp in out:
                raise InputError(f"{where}: line {line}: GCP id '{echo(gcp)}' appears twice; expected unique ids")
            out[gcp] = xyz
    except csv.Error as exc:
        raise InputError(f"{where}: line {reader.line_num}: {exc}; expected a CSV table with a header id,x,y,z") from None
    if not out:
        raise InputError(f"{where}: no GCP rows; expected a row id,x,y,z for each ground control point")
    return out


def gcp_report(surveyed: dict[str, np.ndarray], model: dict[str, np.ndarray], threshold_m: float = 0.05,
               names: tuple[str, str] = ("surveyed", "model")) -> GcpReport:
    """Compare the model's GCP coordinates with surveyed ones (same ids)."""
    THRESHOLD.check(threshold_m, "threshold_m")
    only_a = sorted(set(surveyed) - set(model))
    only_b = sorted(set(model) - set(surveyed))
    if only_a or only_b:
        raise InputError(f"GCP ids differ: only in {shown(names[0])}: {echo(only_a)}, only in {shown(names[1])}: "
                         f"{echo(only_b)}; expected the same ids in both")
    ids = tuple(sorted(surveyed))
    delta = np.array([model[i] - surveyed[i] for i in ids])
    return GcpReport(ids=ids, delta_m=delta, threshold_m=threshold_m)
