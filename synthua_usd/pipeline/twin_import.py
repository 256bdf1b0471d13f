"""Writing an imported twin: its layers, an automatic scenario around it, and ``import_report.json``,
as one set (a failed import leaves an earlier import in the folder untouched)."""

from __future__ import annotations

from pathlib import Path

from synthua_usd.atomic import output_set
from synthua_usd.atomic import write_json_atomic
from synthua_usd.framing import automatic_cameras
from synthua_usd.scenario import ScenarioSpec, StageMetadata
from synthua_usd.taxonomy import ClassMap
from synthua_usd.twin import TwinModel
from synthua_usd.usd.scenario_writer import write_scenario

REPORT_FILE = "import_report.json"
#: Imports are static: one time code.
IMPORT_METADATA = StageMetadata(start_time_code=1, end_time_code=1)


def import_scenario(model: TwinModel) -> ScenarioSpec:
    """The twin with automatic ``Overview`` and ``Street`` cameras, a clear day and default render settings."""
    return ScenarioSpec(doc=f"synthua twin imported from {model.source}", metadata=IMPORT_METADATA, twin=model,
                        cameras=automatic_cameras(model), render_camera="Overview")


def write_import(model: TwinModel, out_dir: str | Path, class_map: ClassMap, report: dict) -> list[Path]:
    """Write the scenario of ``model`` and ``report`` into ``out_dir``; returns the final paths."""
    out_dir = Path(out_dir)
    spec = import_scenario(model)
    with output_set(out_dir) as staging:
        written = write_scenario(spec, staging, class_map)
        write_json_atomic(staging / REPORT_FILE, report)
    return [out_dir / p.relative_to(staging) for p in written] + [out_dir / REPORT_FILE]
