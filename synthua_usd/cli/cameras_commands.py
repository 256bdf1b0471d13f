"""``synthua cameras``: camera rigs placed in a scenario and aimed at mobility-aid users, crossings and curb
ramps, with a report of how many pixels each target covers."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_FINDINGS, EXIT_OK, parse_time_codes, say
from synthua_usd.core.errors import escape_controls
from synthua_usd.model.render_config import MAX_SIDE, RenderConfig


@click.group()
def cameras() -> None:
    """Camera rigs (CCTV, dashcam, UAV, pedestrian and wheelchair eye level) as a cameras layer.

    \b
    See the rig types, their heights, lenses and options:
      synthua cameras types
    """


@cameras.command("types")
def cameras_types() -> int:
    """List the rig types with their height ranges, lenses, default aim and options."""
    from synthua_usd.composition.rigs import describe_types

    click.echo(describe_types())
    return EXIT_OK


@cameras.command("author")
@click.argument("scenario", type=click.Path(path_type=Path))
@click.option("--rig", "rigs", multiple=True, required=True, metavar="TYPE[:KEY=VALUE,...]",
              help="A rig to place; repeatable. TYPE is cctv, dashcam, uav_nadir, uav_oblique, pedestrian_eye or "
                   "wheelchair_eye; keys: name, height_m, aim, count, ride, focal_length_mm, horizontal_aperture_mm, "
                   "vertical_aperture_mm, k1, k2, k3, p1, p2 (Brown-Conrady distortion), and per type mount, "
                   "distance_m, speed_kmh, pitch_deg, tilt_deg (`synthua cameras types`).")
@click.option("--out", "out_path", type=click.Path(path_type=Path), required=True,
              help="The cameras layer to write (.usda); the report goes beside it as <name>.report.json.")
@click.option("--min-target-px", type=click.IntRange(0, 10**9), default=1, show_default=True,
              help="Visible pixels a camera's target must cover at every report time code; cameras that cannot are "
                   "reported as rejected and left out of the layer (exit status 1).")
@click.option("--time-code", "--frame", "time_codes", multiple=True, callback=parse_time_codes,
              help="Time codes to report (and to check --min-target-px at): 24, 1,12,24 or 1:48:8 [default: 7 "
                   "evenly spread over the stage's range, first and last included].")
@click.option("--width", type=click.IntRange(16, MAX_SIDE), default=RenderConfig.width, show_default=True,
              help="Image width the pixel counts are for.")
@click.option("--height", type=click.IntRange(16, MAX_SIDE), default=RenderConfig.height, show_default=True,
              help="Image height the pixel counts are for.")
@click.option("--variant", help="Mitsuba variant for the label passes [default: best available].")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--layer", "layers", multiple=True, type=click.Path(path_type=Path),
              help="A layer composed over SCENARIO for the placement only (no file is edited), e.g. an agents layer "
                   "`synthua agents populate` wrote that SCENARIO does not compose yet; repeat for several, "
                   "strongest first.")
@click.option("--allow-external-assets", is_flag=True,
              help="Accept layers outside the stage's folder tree (refused by default).")
def cameras_author(scenario: Path, rigs: tuple[str, ...], out_path: Path, min_target_px: int,
                   time_codes: tuple[float, ...], width: int, height: int, variant: str | None,
                   class_map: Path | None, layers: tuple[Path, ...], allow_external_assets: bool) -> int:
    """Place camera rigs in SCENARIO, aim them, and write them as a cameras layer with a report.

    \b
    Rigs (heights above the ground under the camera):
      cctv            3-8 m on a pole (sidewalk, grass) or a façade, looking down at its target
      dashcam         1.2-1.5 m, driving the centre of the road graph over the animation (moving)
      uav_nadir       20-120 m, looking straight down; uav_oblique: at tilt_deg off nadir
      pedestrian_eye  about 1.6 m; wheelchair_eye: about 1.2 m; standing still, or ride=auto / ride=AGENT
                      to ride with an agent (a walking one, a wheelchair user) over the animation
    \b
    Aims: aid_user (agents whose person uses a mobility aid, wheelchair users first), a device class
    (electric_wheelchair, walker, ...), crossing, curb_ramp, none, or a prim path. Each candidate place is
    scored by the target's visible pixels in the exact label pass (one ray per pixel centre); the best is
    kept and the target's focal length fitted (unless focal_length_mm is given). The report gives, per
    camera and time code, the target's visible pixels, its pixels with everything else removed, the
    occluded fraction, and every aid user in view.
    \b
    Examples:
      synthua cameras author stages/district/scenario.usda --out rigs.usda --min-target-px 2000 \\
          --rig cctv:aim=electric_wheelchair,count=2 --rig dashcam --rig uav_oblique:height_m=30 \\
          --rig pedestrian_eye:ride=auto,aim=crossing --rig wheelchair_eye:k1=-0.2,k2=0.05
      synthua compose with-rigs.usda rigs.usda stages/district/scenario.usda
    A twin scenario without people (synthua twin demo) and an agents layer written for it:
      synthua cameras author my_district/scenario.usda --layer my_district/agents.usdc \\
          --rig cctv:aim=aid_user,name=AidCCTV --out my_district/rigs.usda
    Distortion (k1, k2, k3, p1, p2; OpenCV's convention) is stored on the camera as synthua:distortion:*
    attributes and applied to RGB and labels alike by `synthua render`.
    """
    from synthua_usd.composition.rigs import RigSpec
    from synthua_usd.pipeline.camera_rigs import RigRequest, author_rigs

    specs = tuple(RigSpec.parse(text) for text in rigs)
    result = author_rigs(RigRequest(stage_path=scenario, out_path=out_path, rigs=specs, width=width, height=height,
                                    time_codes=time_codes, min_target_px=min_target_px, variant=variant,
                                    class_map_path=class_map, allow_external_assets=allow_external_assets,
                                    layers=layers),
                         show_progress=sys.stderr.isatty())
    click.echo(format_table(result.report))
    say(f"wrote {result.layer_path} ({result.accepted} camera{'s' if result.accepted != 1 else ''}) and "
               f"{result.report_path}")
    if result.rejected:
        click.echo(f"{result.rejected} camera(s) rejected: their target covers fewer than {min_target_px} visible "
                   f"pixels (see the report)", err=True)
        return EXIT_FINDINGS
    return EXIT_OK


def format_table(report: dict) -> str:
    """One row per camera: rig, target, the target's fewest and most visible pixels over the report's time
    codes, its largest occluded share, status; one line each, control characters escaped."""
    size = report["image"]
    head = (f"{'camera':28s} {'rig':14s} {'target':34s} {'min px':>8s} {'max px':>8s} {'occluded':>9s}  status"
            f"   ({size['width']}x{size['height']}, {len(report['time_codes'])} time codes)")
    lines = [head]
    for cam in report["cameras"]:
        target = cam["target"]
        if target:
            px = [f["target_px"] for f in cam["frames"]]
            occl = [f["occluded_fraction"] for f in cam["frames"] if f["occluded_fraction"] is not None]
            what = f"{target['prim_path'].rsplit('/', 1)[-1]} ({target['label']})"
            numbers = f"{min(px):8d} {max(px):8d} {(f'{100 * max(occl):.1f} %' if occl else '-'):>9s}"
        else:
            what, numbers = "-", f"{'-':>8s} {'-':>8s} {'-':>9s}"
        status = cam["status"] + (" (on road)" if cam.get("on_road") else "")
        lines.append(escape_controls(f"{cam['name']:28s} {cam['rig']:14s} {what:34s} {numbers}  {status}"))
    return "\n".join(lines)
