"""``synthua``: one command, a subcommand per step. Thin: parse, call the library, print, return a status.

Exit status: 0 success (or a clean validation), 1 validation findings, 2 unusable input (missing or
malformed file, unknown camera, time code out of range, bad option, an output that cannot be written),
3 an unexpected failure (a bug; ``--debug`` shows the traceback).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from synthua_usd import __version__
from synthua_usd.cli.agents_commands import agents
from synthua_usd.cli.analytics_commands import evaluate, stats
from synthua_usd.cli.cameras_commands import cameras
from synthua_usd.cli.common import EXIT_FINDINGS, EXIT_INPUT, EXIT_OK, say
from synthua_usd.cli.cutout_commands import cutouts
from synthua_usd.cli.composite_commands import composite
from synthua_usd.cli.common import parse_time_codes as _time_codes
from synthua_usd.cli.dataset_commands import generate, replay, verify
from synthua_usd.cli.failures import configure_logging, guarded
from synthua_usd.cli.options import seed_option
from synthua_usd.cli.randomise_commands import randomise
from synthua_usd.cli.sheet_commands import contact_sheet
from synthua_usd.cli.survey_commands import survey
from synthua_usd.cli.train_commands import evaluate_real, train
from synthua_usd.cli.twin_commands import twin
from synthua_usd.core import json_text
from synthua_usd.core.findings import Finding, Severity
from synthua_usd.model.render_config import MAX_SIDE, MAX_SPP, RenderConfig


def _report(findings: list[Finding], as_json: bool, strict: bool) -> int:
    """Print findings; 1 when any is a warning or error (or any at all with --strict), else 0."""
    if as_json:
        click.echo(json_text.dumps([f.to_dict() for f in findings], indent=2, ascii_only=True))
    else:
        for f in findings:
            say(f.format())
        counts = {s: sum(1 for f in findings if f.severity is s) for s in Severity}
        click.echo(f"{counts[Severity.ERROR]} errors, {counts[Severity.WARNING]} warnings, {counts[Severity.INFO]} notes",
                   err=True)
    threshold = Severity.INFO if strict else Severity.WARNING
    return EXIT_FINDINGS if any(f.severity >= threshold for f in findings) else EXIT_OK


@click.group(context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.version_option(__version__, prog_name="synthua")
@click.option("-v", "--verbose", count=True, help="More log output (-v info, -vv debug).")
@click.option("--debug", is_flag=True, help="Show the Python traceback of an unexpected failure.")
def cli(verbose: int, debug: bool) -> None:
    """Turn layered OpenUSD street scenes into exactly labelled images.

    \b
    Typical session:
      synthua create street stages/            # write the demo layers and scenario.usda
      synthua validate stage stages/scenario.usda
      synthua inspect stages/scenario.usda
      synthua render stages/scenario.usda --camera /World/Cameras/CCTV --out out/cctv
    \b
    Your own city:
      synthua twin import cityjson city.json --out city/     # or mesh, pointcloud, footprints
      synthua agents populate city/scenario.usda --walk-on sidewalk,road --out city/agents.usdc
      synthua compose city/with_people.usda city/agents.usdc city/render.usda city/environment.usda \\
          city/cameras.usda city/semantics.usda city/twin.usdc
      synthua render city/with_people.usda --camera /World/Cameras/Street --out out/city
    """
    configure_logging(verbose)


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
    from synthua_usd.core.schemas import bundled_path, read_json
    from synthua_usd.model.classmap_checks import check_classmap

    path = file or bundled_path("classmap.json")
    return _report(check_classmap(read_json(path)), as_json, strict)


@validate.command("stage")
@click.argument("stage", type=click.Path(path_type=Path))
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map to check labels against.")
@click.option("--json", "as_json", is_flag=True, help="Print findings as JSON.")
@click.option("--strict", is_flag=True, help="Exit 1 on notes too.")
@click.option("--allow-external-assets", is_flag=True,
              help="Accept layers outside the stage's folder tree (refused by default).")
def validate_stage(stage: Path, class_map: Path | None, as_json: bool, strict: bool, allow_external_assets: bool) -> int:
    """Validate a USD STAGE: OpenUSD's UsdValidation validators plus synthua's rules.

    synthua's rules: every renderable gprim has exactly one class (directly or from one ancestor), every
    label is in the class map, cameras have valid physical lens values, stage metadata is stated, render
    settings name a real camera, every authored number is finite, Cube/Sphere/Cylinder/Cone/Capsule sizes
    are > 0; when none finds an error, the stage is read as render reads it.
    """
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.stage_checks import validate_stage as run_rules
    from synthua_usd.usd.stage_io import open_stage

    cmap = ClassMap.load_or_bundled(class_map)
    return _report(run_rules(open_stage(stage, allow_external_assets), cmap), as_json, strict)


# --- compose / inspect / create ----------------------------------------------------------------------------

@cli.command()
@click.argument("out", type=click.Path(path_type=Path))
@click.argument("layers", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--allow-external-assets", is_flag=True,
              help="Compose layers outside OUT's folder tree (refused by default: validate, render and generate "
                   "then need the same flag).")
def compose(out: Path, layers: tuple[Path, ...], allow_external_assets: bool) -> int:
    """Write scenario root OUT that sublayers LAYERS (strongest first).

    The root states upAxis, metersPerUnit and timeCodesPerSecond (the layers must agree), the union of
    their time ranges and the first defaultPrim. Paths are stored relative to OUT. LAYERS lie in OUT's
    folder tree (a scenario that reaches outside its folder is refused by the commands that open it).

    \b
    Example:
      synthua compose stages/my.usda stages/render.usda stages/environment.usda stages/cameras.usda \\
          stages/agents.usdc stages/semantics.usda stages/twin.usdc
    """
    from synthua_usd.usd.compose import compose_layers

    path = compose_layers(out, list(layers), allow_external_assets=allow_external_assets)
    say(f"wrote {path} ({len(layers)} sublayers)")
    return EXIT_OK


@cli.command()
@click.argument("stage", type=click.Path(path_type=Path))
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map used to read labels.")
@click.option("--allow-external-assets", is_flag=True,
              help="Accept layers outside the stage's folder tree (refused by default).")
def inspect(stage: Path, class_map: Path | None, allow_external_assets: bool) -> int:
    """Print what STAGE holds: layer stack, prims per class, cameras, lights, conditions and time range."""
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.stage_io import open_stage
    from synthua_usd.usd.summary import summarize

    click.echo(summarize(open_stage(stage, allow_external_assets), ClassMap.load_or_bundled(class_map)).format())
    return EXIT_OK


@cli.group()
def create() -> None:
    """Generate shipped scenes as USD layers."""


@create.command("street")
@click.argument("out_dir", type=click.Path(path_type=Path))
def create_street(out_dir: Path) -> int:
    """Write the demo street (twin.usdc, semantics, agents.usdc, cameras, environment and render layers and
    scenario.usda) into OUT_DIR. Deterministic: the same version writes the same bytes."""
    from synthua_usd.demo.street import street_scenario
    from synthua_usd.usd.scenario_writer import write_scenario

    for path in write_scenario(street_scenario(), out_dir):
        say(f"wrote {path}")
    return EXIT_OK


@create.command("district")
@click.argument("out_dir", type=click.Path(path_type=Path))
@seed_option(help="Layout and crowd seed.")
def create_district(out_dir: Path, seed: int) -> int:
    """Write the Largo da Ordem demo district as a full scenario into OUT_DIR: twin, semantics, a populated
    agents layer, cameras (CCTV, pedestrian and wheelchair eye level, UAV), camera rigs aimed at the crowd's
    mobility-aid users (rigs.usda, with rigs.report.json: see `synthua cameras author`), environment,
    render settings (through the first aimed CCTV) and scenario.usda."""
    from synthua_usd.cli.cameras_commands import format_table
    from synthua_usd.demo import district
    from synthua_usd.pipeline.aimed_scenario import write_scenario_with_rigs

    paths, rigs = write_scenario_with_rigs(district.district_scenario(seed), district.district_aimed_rigs(), out_dir)
    click.echo(format_table(rigs.report))
    for path in paths:
        say(f"wrote {path}")
    return EXIT_OK


# --- render --------------------------------------------------------------------------------------------------

@cli.command()
@click.argument("scenario", type=click.Path(path_type=Path))
@click.option("--camera", "cameras", multiple=True,
              help="Camera prim path, e.g. /World/Cameras/CCTV; repeat for several; 'auto': a camera framing the "
                   "stage's bounds, authored in its session layer only (for stages without one) [default: the "
                   "render settings' camera].")
@click.option("--time-code", "--frame", "time_codes", multiple=True, callback=_time_codes,
              help="Time code(s) to render: 24, 1,12,24 or 1:48:8 (START:END:STEP); repeatable; --frame is "
                   "the same option [default: the stage's start time code].")
@click.option("--width", type=click.IntRange(1, MAX_SIDE),
              help=f"Image width in pixels [default: render settings, else {RenderConfig.width}].")
@click.option("--height", type=click.IntRange(1, MAX_SIDE),
              help=f"Image height in pixels [default: render settings, else {RenderConfig.height}].")
@click.option("--spp", type=click.IntRange(1, MAX_SPP), help=f"RGB samples per pixel [default: render settings, else "
                                                          f"{RenderConfig.spp}]. Labels always use one ray per pixel centre.")
@seed_option(help="Sampler seed of the RGB pass.")
@click.option("--denoise/--no-denoise", default=None,
              help="Denoise RGB: a firefly filter, then Intel Open Image Denoise guided by albedo and normal from the "
                   "same samples, before fog, rain and exposure (box pixel filter either way) [default: on; see the "
                   "docs/rendering.md's Denoising for what each sample count reaches].")
@click.option("--max-depth", type=click.IntRange(1, 1024),
              help=f"Path length of the RGB pass [default: {RenderConfig.max_depth}; 4 matches Cycles' max_bounces 2].")
@click.option("--layer", "layers", multiple=True, type=click.Path(path_type=Path),
              help="A layer composed over SCENARIO for this render only (through its session layer; no file is "
                   "edited), e.g. the randomisation layer `synthua randomise` writes; repeat for several, strongest "
                   "first.")
@click.option("--variant", help="Mitsuba variant (cuda_ad_rgb, llvm_ad_rgb, scalar_rgb) [default: best available].")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--condition", help="Weather and light condition, one the stage offers (see `synthua inspect`), e.g. "
                                  "clear_night; chosen for this render only, no layer is edited [default: the "
                                  "stage's selection].")
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True, help="Output folder (created).")
@click.option("--allow-external-assets", is_flag=True,
              help="Accept layers outside the stage's folder tree (refused by default).")
def render(scenario: Path, cameras: tuple[str, ...], time_codes: tuple[float, ...], width: int | None,
           height: int | None, spp: int | None, seed: int, denoise: bool | None, max_depth: int | None,
           layers: tuple[Path, ...], variant: str | None, class_map: Path | None, condition: str | None, out_dir: Path,
           allow_external_assets: bool) -> int:
    """Render SCENARIO from each --camera at each time code into --out.

    \b
    One frame writes its files into --out; several write --out/<camera name>/<time code>/, e.g.
      synthua render stages/scenario.usda --camera /World/Cameras/CCTV \\
          --camera /World/Cameras/PedestrianEye --time-code 1:48:8 --out out/sweep
    renders 12 frames from one loaded scene (only the camera and what moves are updated between them).
    --condition day_fog renders them under another of the stage's conditions (labels do not change).
    --layer L.usda composes a layer over SCENARIO for this render, e.g. the randomisation layer of one dataset
    image (synthua randomise prints the render command that reproduces that image).
    \b
    Files per frame (the stage's UsdRender vars choose; all when it names none): rgb.exr
    (scene-linear Rec.709) and rgb.png (display sRGB), class.png (8-bit class ids) and semantic.png
    (class colours), instance.png (16-bit instance ids, 0 = none) and instance_preview.png (a colour per
    id), depth.exr (z-depth in metres, 0 = no hit), and always frame.json (camera intrinsics/extrinsics, class map, instances with pixel
    counts, the condition and the exposure rgb.png was made with). Nothing is written unless every input checks out, and nothing is replaced unless every
    frame rendered.
    """
    from synthua_usd.pipeline.frame import FrameRequest, run_frames

    t0 = time.perf_counter()
    run = run_frames(FrameRequest(stage_path=scenario, out_dir=out_dir, camera_paths=cameras, time_codes=time_codes,
                                  width=width, height=height, spp=spp, seed=seed, variant=variant,
                                  class_map_path=class_map, allow_external_assets=allow_external_assets,
                                  condition=condition, denoise=denoise, max_depth=max_depth, layers=layers),
                     show_progress=sys.stderr.isatty())
    for frame in run.frames:
        doc = frame.document
        visible = sum(1 for i in doc["instances"] if i["pixel_count"])
        condition = f"condition {doc['condition']['name']}, " if doc["condition"] else ""
        say(f"rendered {doc['camera']['prim_path']} at time code {doc['time_code']:g}: "
                   f"{doc['image']['width']}x{doc['image']['height']}, {doc['render']['spp']} spp"
                   f"{' denoised' if doc['render'].get('denoise') else ''}, "
                   f"{doc['render']['variant']}, {condition}{visible} visible instances -> {frame.out_dir}")
    files = sum(len(f.files) for f in run.frames)
    say(f"wrote {files} files for {len(run.frames)} frames to {out_dir} in {time.perf_counter() - t0:.1f} s "
               f"({run.loads} scene load{'s' if run.loads != 1 else ''})")
    return EXIT_OK


for _group in (twin, agents, cameras, survey, contact_sheet, generate, cutouts, composite, verify, replay, randomise, stats,
               evaluate, train, evaluate_real):
    cli.add_command(_group)


# --- entry point ---------------------------------------------------------------------------------------------

def main(argv: list[str] | None = None) -> int:
    """Run the CLI and return the exit status (the console script passes it to ``sys.exit``).

    Every failure is reported as one line by :func:`synthua_usd.cli.failures.guarded`."""
    args = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args
    if debug:
        args.remove("--debug")
    status = guarded(lambda: cli.main(args=args, prog_name="synthua", standalone_mode=False), debug)
    return status if isinstance(status, int) else EXIT_OK


def run() -> None:
    sys.exit(main())
