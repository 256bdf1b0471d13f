"""Photogrammetry helpers from SYNTHUA-DT §2.1: UAV flight planning and ground-control-point accuracy.

Flight plan (nadir images, flat ground): footprint W = 2·h·tan(θ/2); spacing between images
D = (1 − overlap)·W, frontal along a flight line and lateral between lines; ground sampling distance
GSD = sensor width · h / (focal length · image width in pixels).
GCP accuracy: per-point error e_i = sqrt(ΔX² + ΔY² + ΔZ²) and RMSE = sqrt(mean(ΔX² + ΔY² + ΔZ²)).
"""

from __future__ import annotations

import csv
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from synthua_usd.errors import InputError


@dataclass(frozen=True)
class FlightPlanInput:
    """A survey of a rectangular area. Overlaps are fractions in [0, 1)."""

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
        if not self.altitude_m > 0:
            raise InputError(f"altitude_m should be > 0, but was {self.altitude_m}")
        if not 0 < self.fov_deg < 180:
            raise InputError(f"fov_deg should be in (0, 180), but was {self.fov_deg}")
        for name in ("frontal_overlap", "lateral_overlap"):
            value = getattr(self, name)
            if not 0 <= value < 1:
                raise InputError(f"{name} should be a fraction in [0, 1), but was {value}")
        for name in ("area_width_m", "area_length_m"):
            if not getattr(self, name) > 0:
                raise InputError(f"{name} should be > 0, but was {getattr(self, name)}")
        gsd = (self.sensor_width_mm, self.focal_length_mm, self.image_width_px)
        if any(v is not None for v in gsd) and not all(v is not None and v > 0 for v in gsd):
            raise InputError("sensor_width_mm, focal_length_mm and image_width_px go together and must all be > 0, "
                             f"but were {gsd}")


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


def plan_flight(p: FlightPlanInput) -> FlightPlan:
    """Lines across the area's width, images along its length, both ends covered."""
    w = footprint_m(p.altitude_m, p.fov_deg)
    frontal = (1.0 - p.frontal_overlap) * w
    lateral = (1.0 - p.lateral_overlap) * w
    # A tolerance keeps 300 m / 100 m at 3 spans although tan() leaves 99.999... m.
    lines = math.ceil(p.area_width_m / lateral - 1e-9) + 1
    per_line = math.ceil(p.area_length_m / frontal - 1e-9) + 1
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
    """GCPs from a CSV with columns id, x, y, z (metres, any projected CRS shared by both files)."""
    path = Path(path)
    try:
        with path.open(newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            fields = [f.strip().lower() for f in reader.fieldnames or []]
            missing = [c for c in ("id", "x", "y", "z") if c not in fields]
            if missing:
                raise InputError(f"{path}: missing columns {missing}; expected a header with id,x,y,z, found {fields}")
            out: dict[str, np.ndarray] = {}
            for line, row in enumerate(reader, start=2):
                row = {k.strip().lower(): v for k, v in row.items() if k}
                try:
                    xyz = np.array([float(row[c]) for c in ("x", "y", "z")])
                except (TypeError, ValueError):
                    raise InputError(f"{path}: line {line}: x, y, z should be numbers, but were "
                                     f"{[row.get(c) for c in ('x', 'y', 'z')]}") from None
                if not np.all(np.isfinite(xyz)):
                    raise InputError(f"{path}: line {line}: coordinates should be finite, but were {xyz.tolist()}")
                if row["id"] in out:
                    raise InputError(f"{path}: line {line}: GCP id '{row['id']}' appears twice")
                out[row["id"]] = xyz
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    if not out:
        raise InputError(f"{path}: no GCP rows")
    return out


def gcp_report(surveyed: dict[str, np.ndarray], model: dict[str, np.ndarray], threshold_m: float = 0.05,
               names: tuple[str, str] = ("surveyed", "model")) -> GcpReport:
    """Compare the model's GCP coordinates with surveyed ones (same ids)."""
    only_a = sorted(set(surveyed) - set(model))
    only_b = sorted(set(model) - set(surveyed))
    if only_a or only_b:
        raise InputError(f"GCP ids differ: only in {names[0]}: {only_a}, only in {names[1]}: {only_b}")
    ids = tuple(sorted(surveyed))
    delta = np.array([model[i] - surveyed[i] for i in ids])
    return GcpReport(ids=ids, delta_m=delta, threshold_m=threshold_m)
