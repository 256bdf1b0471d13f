"""``synthua``: one command, a subcommand per step. Thin: parse, call the library, print, return a status.

Exit status: 0 success (or a clean validation), 1 validation findings or an unexpected failure,
2 unusable input (missing or malformed file, unknown camera, frame out of range, bad option).
"""

from __future__ import annotations

import json
import logging
import sys
import time
from pathlib import Path

import click

from synthua_usd import __version__
from synthua_usd.errors import SynthuaError
from synthua_usd.findings import Finding, Severity

log = logging.getLogger("synthua")

EXIT_OK, EXIT_FINDINGS, EXIT_INPUT = 0, 1, 2


def _report(findings: list[Finding], as_json: bool, strict: bool) -> int:
    """Print findings; 1 when any is a warning or error (or any at all with --strict), else 0."""
    if as_json:
        click.echo(json.dumps([f.to_dict() for f in findings], indent=2))
    else:
        for f in findings:
            click.echo(f.format())
        counts = {s: sum(1 for f in findings if f.severity is s) for s in Severity}
        click.echo(f"{counts[Severity.ERROR]} errors, {counts[Severity.WARNING]} warnings, {counts[Severity.INFO]} notes",
                   err=True)
    threshold = Severity.INFO if strict else Severity.WARNING
    return EXIT_FINDINGS if any(f.severity >= threshold for f in findings) else EXIT_OK


def _class_map(path: Path | None):
    from synthua_usd.taxonomy import ClassMap

    return ClassMap.load(path) if path else ClassMap.default()


@click.group(context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.version_option(__version__, prog_name="synthua")
@click.option("-v", "--verbose", count=True, help="More log output (-v info, -vv debug).")
def cli(verbose: int) -> None:
    """Turn layered OpenUSD street scenes into exactly labelled images.

    \b
    Typical session:
      synthua create street stages/            # write the demo layers and scenario.usda
      synthua validate stage stages/scenario.usda
      synthua inspect stages/scenario.usda
      synthua render stages/scenario.usda --camera /World/Cameras/CCTV --out out/cctv
    """
    level = logging.WARNING - 10 * verbose
    logging.basicConfig(level=max(level, logging.DEBUG), format="synthua: %(levelname)s: %(message)s", force=True)


# --- validate ---------------------------------------------------------------------------------------------

@cli.group()
def validate() -> None:
    """Check class maps and stages; print findings (exit 0 clean, 1 findings, 2 unusable input)."""


@validate.command("classes")
@click.argument("file", type=click.Path(path_type=Path), required=False)
@click.option("--json", "as_json", is_flag=True, help="Print findings as JSON.")
@click.option("--strict", is_flag=True, help="Exit 1 on notes too.")
def validate_classes(file: Path | None, as_json: bool, strict: bool) -> int:
    """Validate a class map FILE (default: the bundled schemas/classmap.json).

    Runs the JSON Schema first, then rules it cannot express: unique ids, names, aliases and colours,
    id 0 = black 'unlabelled', and a minimum CIEDE2000 distance between class colours.
    """
    from synthua_usd.classmap_rules import check_classmap
    from synthua_usd.schemas import bundled_path, read_json

    path = file or bundled_path("classmap.json")
    return _report(check_classmap(read_json(path)), as_json, strict)


@validate.command("stage")
@click.argument("stage", type=click.Path(path_type=Path))
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map to check labels against.")
@click.option("--json", "as_json", is_flag=True, help="Print findings as JSON.")
@click.option("--strict", is_flag=True, help="Exit 1 on notes too.")
def validate_stage(stage: Path, class_map: Path | None, as_json: bool, strict: bool) -> int:
    """Validate a USD STAGE: OpenUSD's UsdValidation validators plus synthua's rules.

    synthua's rules: every renderable gprim has exactly one class (directly or from one ancestor), every
    label is in the class map, cameras have valid physical lens values, stage metadata is stated, and
    render settings name a real camera.
    """
    from synthua_usd.usd.rules import validate_stage as run_rules
    from synthua_usd.usd.stage_io import open_stage

    cmap = _class_map(class_map)
    return _report(run_rules(open_stage(stage), cmap), as_json, strict)


# --- compose / inspect / create ----------------------------------------------------------------------------

@cli.command()
@click.argument("out", type=click.Path(path_type=Path))
@click.argument("layers", nargs=-1, required=True, type=click.Path(path_type=Path))
def compose(out: Path, layers: tuple[Path, ...]) -> int:
    """Write scenario root OUT that sublayers LAYERS (strongest first).

    The root states upAxis, metersPerUnit and timeCodesPerSecond (the layers must agree), the union of
    their time ranges and the first defaultPrim. Paths are stored relative to OUT.

    \b
    Example:
      synthua compose my.usda stages/render.usda stages/environment.usda stages/cameras.usda \\
          stages/agents.usda stages/semantics.usda stages/twin.usda
    """
    from synthua_usd.usd.compose import compose_layers

    path = compose_layers(out, list(layers))
    click.echo(f"wrote {path} ({len(layers)} sublayers)")
    return EXIT_OK


@cli.command()
@click.argument("stage", type=click.Path(path_type=Path))
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map used to read labels.")
def inspect(stage: Path, class_map: Path | None) -> int:
    """Print what STAGE holds: layer stack, prims per class, cameras, lights and time range."""
    from synthua_usd.usd.inspect import summarize
    from synthua_usd.usd.stage_io import open_stage

    click.echo(summarize(open_stage(stage), _class_map(class_map)).format())
    return EXIT_OK


@cli.group()
def create() -> None:
    """Generate shipped scenes as USD layers."""


@create.command("street")
@click.argument("out_dir", type=click.Path(path_type=Path))
def create_street(out_dir: Path) -> int:
    """Write the demo street (twin, semantics, agents, cameras, environment, render layers and
    scenario.usda) into OUT_DIR. Deterministic: the same version writes the same bytes."""
    from synthua_usd.usd.street_demo import write_street_demo

    for path in write_street_demo(out_dir):
        click.echo(f"wrote {path}")
    return EXIT_OK


# --- twin -------------------------------------------------------------------------------------------------

@cli.group()
def twin() -> None:
    """Build twin layers: the procedural demo district, or imports of real city data."""


@twin.command("import")
@click.argument("kind", type=click.Choice(["mesh", "cityjson", "pointcloud", "footprints"]))
@click.argument("input_path", metavar="INPUT", type=click.Path(path_type=Path))
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Folder for twin.usda, semantics.usda, cameras/environment/render layers, scenario.usda "
                   "and import_report.json.")
@click.option("--rules", type=click.Path(path_type=Path),
              help="Semantic rules JSON (schemas/semantic_rules.schema.json): (field, regex) -> class. "
                   "Required for meshes; optional overrides for the others.")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--up-axis", type=click.Choice(["Y", "Z"]), help="mesh: the file's up axis [default: Y for glTF, Z otherwise].")
@click.option("--scale", type=float, default=1.0, show_default=True, help="mesh: file units to metres.")
@click.option("--lod", help="cityjson: level of detail to import [default: the highest each object has].")
@click.option("--max-deviation-m", type=float, default=0.005, show_default=True,
              help="pointcloud: largest Hausdorff distance simplification may introduce (metres).")
@click.option("--plane-threshold-m", type=float, default=0.02, show_default=True,
              help="pointcloud: RANSAC inlier distance (metres).")
@click.option("--storey-height-m", type=float, default=3.0, show_default=True,
              help="footprints: metres per level when a footprint gives levels, not height.")
def twin_import(kind: str, input_path: Path, out_dir: Path, rules: Path | None, class_map: Path | None,
                up_axis: str | None, scale: float, lod: str | None, max_deviation_m: float,
                plane_threshold_m: float, storey_height_m: float) -> int:
    """Import real city data of KIND from INPUT as labelled twin layers plus a renderable scenario.

    \b
    KIND       INPUT
    mesh       .obj .ply .glb .gltf .stl (trimesh); classes from --rules (object/material/group regex)
    cityjson   CityJSON 1.1 or 2.0 (needs metadata.referenceSystem in metres)
    pointcloud .las .laz .ply; LAS classes, RANSAC planes, TIN, simplification within --max-deviation-m
    footprints GeoJSON polygons with 'height' or 'levels' -> extruded LoD1 buildings

    Geometry no rule matches is labelled 'unlabelled' (class 0) and listed in import_report.json.
    """
    from synthua_usd.backends.frame_files import write_json_atomic
    from synthua_usd.errors import InputError
    from synthua_usd.importers import importers
    from synthua_usd.semantic_rules import SemanticRules
    from synthua_usd.usd.twin_writer import write_twin_scenario

    cmap = _class_map(class_map)
    loaded_rules = SemanticRules.load(rules, cmap) if rules else None
    if kind == "mesh" and loaded_rules is None:
        raise InputError("mesh import needs --rules FILE: meshes carry no classes of their own "
                         "(see schemas/semantic_rules.schema.json)")
    t0 = time.perf_counter()
    model = importers()[kind](input_path, rules=loaded_rules, up_axis=up_axis, scale=scale, lod=lod,
                              max_deviation_m=max_deviation_m, plane_threshold_m=plane_threshold_m,
                              storey_height_m=storey_height_m, show_progress=sys.stderr.isatty())
    seconds = time.perf_counter() - t0
    written = write_twin_scenario(model, out_dir, cmap)
    report = {"kind": kind, "input": str(input_path), "seconds": round(seconds, 3), "objects": len(model.objects),
              "triangles": model.triangle_count(), "classes": model.label_counts(), "crs": model.crs,
              "origin_offset_m": list(model.origin_offset_m), **model.report}
    written.append(write_json_atomic(out_dir / "import_report.json", report))
    click.echo(f"imported {input_path} ({kind}) in {seconds:.1f} s: {len(model.objects)} objects, "
               f"{model.triangle_count()} triangles, classes {model.label_counts()}")
    for seg in model.report.get("segments", []):
        if not seg.get("skipped"):
            click.echo(f"  {seg['name']}: {seg['points']} points -> {seg['faces']} faces, simplification deviation "
                       f"{seg['simplification_deviation_m'] * 1000:.3f} mm, point residual max "
                       f"{seg['residual_max_m'] * 1000:.1f} mm / rms {seg['residual_rms_m'] * 1000:.1f} mm")
    unmatched = model.report.get("unmatched") or model.report.get("unlabelled_types")
    if unmatched:
        click.echo(f"  labelled 'unlabelled' (no rule matched): {unmatched}")
    click.echo(f"wrote {len(written)} files to {out_dir}; render with: synthua render {out_dir / 'scenario.usda'} "
               f"--out OUT")
    return EXIT_OK


@twin.command("demo")
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="Layout seed.")
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True, help="Output folder.")
def twin_demo(seed: int, out_dir: Path) -> int:
    """Write the procedural Largo da Ordem demo district (twin.usda, semantics.usda) for SEED.

    The same seed writes byte-identical layers; another seed another plausible layout.
    """
    from synthua_usd.pipeline.district import write_district

    result = write_district(out_dir, seed=seed)
    click.echo(f"district seed {seed}: {result['objects']} objects, {result['triangles']} triangles, "
               f"{len(result['classes'])} classes")
    for path in result["files"]:
        click.echo(f"wrote {path}")
    return EXIT_OK


# --- agents -----------------------------------------------------------------------------------------------

@cli.group()
def agents() -> None:
    """Crowds with mobility-aid users on the walkable graph of a twin."""


@agents.command("populate")
@click.argument("stage", metavar="TWIN_OR_SCENARIO", type=click.Path(path_type=Path))
@click.option("--density", type=float, default=0.03, show_default=True,
              help="Persons per m² of walkable area (Poisson mean = density x area). Refused above 5 (crowd "
                   "crush); warned above 0.7 (level of service E).")
@click.option("--aid-share", type=float, default=0.3, show_default=True,
              help="Fraction of agents using a mobility aid (wheelchairs, walker, crutches, canes).")
@click.option("--frames", type=click.IntRange(1), default=48, show_default=True, help="Time samples to author.")
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="Seed: same seed, same bytes.")
@click.option("--cell-m", type=float, default=0.5, show_default=True, help="Walkable grid cell size (metres).")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--out", "out_path", type=click.Path(path_type=Path), required=True, help="The agents layer to write (.usda).")
def agents_populate(stage: Path, density: float, aid_share: float, frames: int, seed: int, cell_m: float,
                    class_map: Path | None, out_path: Path) -> int:
    """Populate TWIN_OR_SCENARIO with walking people and mobility-aid users; write them as a layer.

    \b
    The walkable graph covers sidewalks, crosswalks, curb ramps and cobbled streets (the road only on
    crosswalks). Wheelchair and walker users never step a kerb: they cross at curb ramps. Agents pause
    before crosswalks and never come within 0.1 m of each other (disc to disc) at any frame.
    Compose the layer into a scenario with `synthua compose`, e.g.
      synthua compose my.usda agents.usda stages/district/render.usda ... stages/district/twin.usda
    """
    from synthua_usd.pipeline.populate import PopulateRequest, populate

    if not (cell_m > 0):
        from synthua_usd.errors import InputError

        raise InputError(f"--cell-m should be > 0, but was {cell_m}")
    report = populate(PopulateRequest(stage, out_path, density, aid_share, frames, seed, cell_m, class_map))
    click.echo(f"walkable area {report.walkable_area_m2:.0f} m², expected {report.expected:.1f} agents, sampled "
               f"{report.sampled}, placed {report.placed} ({report.aid_users} with mobility aids), dropped "
               f"{report.dropped} (no collision-free start)")
    click.echo(f"profiles {report.by_profile}")
    click.echo(f"minimum gap between agents over {frames} frames: {report.min_separation_m:.3f} m; {report.seconds:.1f} s")
    click.echo(f"wrote {out_path}")
    return EXIT_OK


# --- survey -----------------------------------------------------------------------------------------------

@cli.group()
def survey() -> None:
    """Photogrammetry helpers: UAV flight plans and ground-control-point accuracy."""


@survey.command("flight-plan")
@click.option("--altitude-m", type=float, required=True, help="Flight height above ground, h (m).")
@click.option("--fov-deg", type=float, required=True, help="Camera field of view across the footprint, theta.")
@click.option("--frontal-overlap", type=float, default=0.7, show_default=True, help="Fraction along a line.")
@click.option("--lateral-overlap", type=float, default=0.8, show_default=True, help="Fraction between lines.")
@click.option("--area-width-m", type=float, required=True, help="Area extent across flight lines (m).")
@click.option("--area-length-m", type=float, required=True, help="Area extent along flight lines (m).")
@click.option("--sensor-width-mm", type=float, help="For GSD: sensor width (mm).")
@click.option("--focal-length-mm", type=float, help="For GSD: focal length (mm).")
@click.option("--image-width-px", type=int, help="For GSD: image width (pixels).")
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
def survey_flight_plan(as_json: bool, **kwargs) -> int:
    """Footprint W = 2 h tan(theta/2), spacing D = (1 - overlap) W, image count, and GSD.

    \b
    The paper's survey: synthua survey flight-plan --altitude-m 150 --fov-deg 84 \\
        --area-width-m 1225 --area-length-m 1225 --sensor-width-mm 13.2 --focal-length-mm 10.26 \\
        --image-width-px 5472
    """
    from synthua_usd.survey import FlightPlanInput, plan_flight

    plan = plan_flight(FlightPlanInput(**kwargs))
    if as_json:
        click.echo(json.dumps(plan.to_dict(), indent=2))
    else:
        click.echo(f"footprint W        {plan.footprint_m:.1f} m")
        click.echo(f"frontal spacing    {plan.frontal_spacing_m:.1f} m")
        click.echo(f"lateral spacing    {plan.lateral_spacing_m:.1f} m")
        click.echo(f"flight lines       {plan.flight_lines}")
        click.echo(f"images per line    {plan.images_per_line}")
        click.echo(f"images             {plan.images}")
        if plan.gsd_m is not None:
            click.echo(f"GSD                {plan.gsd_m * 100:.2f} cm/px")
    return EXIT_OK


@survey.command("gcp")
@click.argument("surveyed", type=click.Path(path_type=Path))
@click.argument("model", type=click.Path(path_type=Path))
@click.option("--threshold-m", type=float, default=0.05, show_default=True, help="Accepted RMSE (m).")
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
def survey_gcp(surveyed: Path, model: Path, threshold_m: float, as_json: bool) -> int:
    """Per-point 3-D error and RMSE = sqrt(mean(dX^2 + dY^2 + dZ^2)) between SURVEYED and MODEL GCPs.

    Both are CSV files with a header id,x,y,z (metres). Exit 1 when the RMSE exceeds --threshold-m.
    """
    from synthua_usd.survey import gcp_report, read_points_csv

    report = gcp_report(read_points_csv(surveyed), read_points_csv(model), threshold_m,
                        names=(str(surveyed), str(model)))
    if as_json:
        click.echo(json.dumps(report.to_dict(), indent=2))
    else:
        click.echo(f"{'id':>10} {'dX m':>9} {'dY m':>9} {'dZ m':>9} {'error m':>9}")
        for i, d, e in zip(report.ids, report.delta_m, report.errors_m):
            click.echo(f"{i:>10} {d[0]:9.4f} {d[1]:9.4f} {d[2]:9.4f} {e:9.4f}")
        x, y, z = report.rmse_xyz_m
        click.echo(f"RMSE {report.rmse_m:.4f} m (X {x:.4f}, Y {y:.4f}, Z {z:.4f}); threshold {threshold_m:g} m: "
                   f"{'pass' if report.passed else 'FAIL'}")
    return EXIT_OK if report.passed else EXIT_FINDINGS


@create.command("district")
@click.argument("out_dir", type=click.Path(path_type=Path))
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="Layout seed.")
def create_district(out_dir: Path, seed: int) -> int:
    """Write the Largo da Ordem demo district as a full scenario into OUT_DIR: twin, semantics, cameras
    (CCTV, pedestrian and wheelchair eye level, UAV), environment, render settings and scenario.usda."""
    from synthua_usd.pipeline.district import write_district_scenario

    for path in write_district_scenario(out_dir, seed):
        click.echo(f"wrote {path}")
    return EXIT_OK


# --- render --------------------------------------------------------------------------------------------------

@cli.command()
@click.argument("scenario", type=click.Path(path_type=Path))
@click.option("--camera", help="Camera prim path, e.g. /World/Cameras/CCTV [default: the render settings' camera].")
@click.option("--frame", type=float, help="Time code to render [default: the stage's start time code].")
@click.option("--width", type=click.IntRange(1, 16384), help="Image width in pixels [default: render settings, else 1280].")
@click.option("--height", type=click.IntRange(1, 16384), help="Image height in pixels [default: render settings, else 960].")
@click.option("--spp", type=click.IntRange(1, 65536), help="RGB samples per pixel [default: render settings, else 64]. "
                                                          "Labels always use one ray per pixel centre.")
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="Sampler seed of the RGB pass.")
@click.option("--variant", help="Mitsuba variant (cuda_ad_rgb, llvm_ad_rgb, scalar_rgb) [default: best available].")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True, help="Output folder (created).")
def render(scenario: Path, camera: str | None, frame: float | None, width: int | None, height: int | None,
           spp: int | None, seed: int, variant: str | None, class_map: Path | None, out_dir: Path) -> int:
    """Render one frame of SCENARIO into --out.

    \b
    Writes rgb.exr (scene-linear Rec.709), rgb.png (display sRGB), class.png (8-bit class ids),
    semantic.png (class colours), instance.png (16-bit instance ids, 0 = none), depth.exr (z-depth in
    metres, 0 = no hit) and frame.json (camera intrinsics/extrinsics, class map, instances with pixel
    counts). Nothing is written unless every input checks out.
    """
    from synthua_usd.pipeline.frame import FrameRequest, run_frame

    t0 = time.perf_counter()
    result = run_frame(FrameRequest(stage_path=scenario, out_dir=out_dir, camera_path=camera, frame=frame,
                                    width=width, height=height, spp=spp, seed=seed, variant=variant,
                                    class_map_path=class_map), show_progress=sys.stderr.isatty())
    doc = result.document
    visible = sum(1 for i in doc["instances"] if i["pixel_count"])
    click.echo(f"rendered {doc['camera']['prim_path']} at frame {doc['time_code']:g}: "
               f"{doc['image']['width']}x{doc['image']['height']}, {doc['render']['spp']} spp, "
               f"{doc['render']['variant']}, {visible} visible instances, {time.perf_counter() - t0:.1f} s")
    click.echo(f"wrote {len(result.files)} files to {out_dir}")
    return EXIT_OK


# --- entry point ---------------------------------------------------------------------------------------------

def main(argv: list[str] | None = None) -> int:
    """Run the CLI and return the exit status (the console script passes it to ``sys.exit``)."""
    try:
        result = cli.main(args=argv, prog_name="synthua", standalone_mode=False)
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except click.ClickException as exc:
        exc.show()
        return EXIT_INPUT
    except click.Abort:
        click.echo("synthua: aborted", err=True)
        return EXIT_FINDINGS
    except SynthuaError as exc:
        click.echo(f"synthua: error: {exc}", err=True)
        return EXIT_INPUT
    return result if isinstance(result, int) else EXIT_OK


def run() -> None:
    sys.exit(main())
