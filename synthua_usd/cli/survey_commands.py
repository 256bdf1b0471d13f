"""``synthua survey``: photogrammetry helpers."""

from __future__ import annotations

from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_FINDINGS, EXIT_OK, say
from synthua_usd.cli.options import InRange
from synthua_usd.core import json_text
from synthua_usd.core.errors import echo
from synthua_usd.model.survey import LIMITS, THRESHOLD

# --- survey -----------------------------------------------------------------------------------------------

@click.group()
def survey() -> None:
    """Photogrammetry helpers: UAV flight plans and ground-control-point accuracy."""


def option_name(field: str) -> str:
    """The option a flight-plan field comes from, as the user typed it: altitude_m -> --altitude-m."""
    return "--" + field.replace("_", "-")


@survey.command("flight-plan")
@click.option("--altitude-m", type=InRange(LIMITS["altitude_m"]), required=True,
              help="Flight height above ground, h (m).")
@click.option("--fov-deg", type=InRange(LIMITS["fov_deg"]), required=True,
              help="Camera field of view across the footprint, theta (degrees).")
@click.option("--frontal-overlap", type=InRange(LIMITS["frontal_overlap"]), default=0.7, show_default=True,
              help="Fraction along a line.")
@click.option("--lateral-overlap", type=InRange(LIMITS["lateral_overlap"]), default=0.8, show_default=True,
              help="Fraction between lines.")
@click.option("--area-width-m", type=InRange(LIMITS["area_width_m"]), required=True,
              help="Area extent across flight lines (m).")
@click.option("--area-length-m", type=InRange(LIMITS["area_length_m"]), required=True,
              help="Area extent along flight lines (m).")
@click.option("--sensor-width-mm", type=InRange(LIMITS["sensor_width_mm"]), help="For GSD: sensor width (mm).")
@click.option("--focal-length-mm", type=InRange(LIMITS["focal_length_mm"]), help="For GSD: focal length (mm).")
@click.option("--image-width-px", type=InRange(LIMITS["image_width_px"]), help="For GSD: image width (pixels).")
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
def survey_flight_plan(as_json: bool, **kwargs) -> int:
    """Footprint W = 2 h tan(theta/2), spacing D = (1 - overlap) W, image count, and GSD.

    Plans of more than 1,000,000 images are refused.

    \b
    The paper's survey: synthua survey flight-plan --altitude-m 150 --fov-deg 84 \\
        --area-width-m 1225 --area-length-m 1225 --sensor-width-mm 13.2 --focal-length-mm 10.26 \\
        --image-width-px 5472
    """
    from synthua_usd.model.survey import FlightPlanInput, check_flight_input, plan_flight

    check_flight_input(kwargs, option_name)  # the GSD options go together: named as typed
    plan = plan_flight(FlightPlanInput(**kwargs), option_name)
    if as_json:
        click.echo(json_text.dumps(plan.to_dict(), indent=2, ascii_only=True))
    else:
        say(f"footprint W        {plan.footprint_m:.1f} m")
        say(f"frontal spacing    {plan.frontal_spacing_m:.1f} m")
        say(f"lateral spacing    {plan.lateral_spacing_m:.1f} m")
        say(f"flight lines       {plan.flight_lines}")
        say(f"images per line    {plan.images_per_line}")
        say(f"images             {plan.images}")
        if plan.gsd_m is not None:
            say(f"GSD                {plan.gsd_m * 100:.2f} cm/px")
    return EXIT_OK


@survey.command("gcp")
@click.argument("surveyed", type=click.Path(path_type=Path))
@click.argument("model", type=click.Path(path_type=Path))
@click.option("--threshold-m", type=InRange(THRESHOLD), default=0.05, show_default=True, help="Accepted RMSE (m).")
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
def survey_gcp(surveyed: Path, model: Path, threshold_m: float, as_json: bool) -> int:
    """Per-point 3-D error and RMSE = sqrt(mean(dX^2 + dY^2 + dZ^2)) between SURVEYED and MODEL GCPs.

    Both are CSV files with a header id,x,y,z (metres). Exit 1 when the RMSE exceeds --threshold-m.
    """
    from synthua_usd.model.survey import gcp_report, read_points_csv

    report = gcp_report(read_points_csv(surveyed), read_points_csv(model), threshold_m,
                        names=(str(surveyed), str(model)))
    if as_json:
        click.echo(json_text.dumps(report.to_dict(), indent=2, ascii_only=True))
    else:
        say(f"{'id':>10} {'dX m':>9} {'dY m':>9} {'dZ m':>9} {'error m':>9}")
        for i, d, e in zip(report.ids, report.delta_m, report.errors_m):
            say(f"{echo(i):>10} {d[0]:9.4f} {d[1]:9.4f} {d[2]:9.4f} {e:9.4f}")
        x, y, z = report.rmse_xyz_m
        say(f"RMSE {report.rmse_m:.4f} m (X {x:.4f}, Y {y:.4f}, Z {z:.4f}); threshold {threshold_m:g} m: "
                   f"{'pass' if report.passed else 'FAIL'}")
    return EXIT_OK if report.passed else EXIT_FINDINGS
