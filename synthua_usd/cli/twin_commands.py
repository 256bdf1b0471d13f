"""``synthua twin``: the demo district and importers of real city data."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_FINDINGS, EXIT_OK, say
from synthua_usd.cli.options import AID_SHARE, DENSITY, InRange, seed_option
from synthua_usd.core.errors import echo
from synthua_usd.importers import limits as importer_limits

# --- twin -------------------------------------------------------------------------------------------------

@click.group()
def twin() -> None:
    """Build twin layers: the procedural demo district, or imports of real city data."""


#: Options that belong to one kind of import (or to a few): given for another kind they are refused, not
#: silently ignored.
KIND_OPTIONS = {
    "rules": ("mesh", "cityjson", "pointcloud"),
    "up_axis": ("mesh",), "scale": ("mesh",),
    "lod": ("cityjson",), "crs": ("cityjson", "pointcloud"), "units": ("cityjson", "pointcloud"),
    "max_deviation_m": ("pointcloud",), "plane_threshold_m": ("pointcloud",), "max_residual_m": ("pointcloud",),
    "max_hull_residual_m": ("pointcloud",),
    "storey_height_m": ("footprints", "osm"), "default_height_m": ("footprints", "osm"),
}


def _refuse_foreign_options(ctx: click.Context, kind: str) -> None:
    from click.core import ParameterSource

    for name, kinds in KIND_OPTIONS.items():
        if kind not in kinds and ctx.get_parameter_source(name) is ParameterSource.COMMANDLINE:
            option = "--" + name.replace("_", "-")
            raise click.UsageError(f"{option}: given for a {kind} import; expected only with "
                                   f"{' or '.join(kinds)} imports", ctx)


def _refuse_population_options(ctx: click.Context, populate: bool) -> None:
    from click.core import ParameterSource

    for name in ("density", "aid_share", "frames"):
        if not populate and ctx.get_parameter_source(name) is ParameterSource.COMMANDLINE:
            raise click.UsageError(f"--{name.replace('_', '-')}: given without --populate; expected only with it",
                                   ctx)


@twin.command("import")
@click.argument("kind", type=click.Choice(["mesh", "cityjson", "pointcloud", "footprints", "osm"]))
@click.argument("input_path", metavar="INPUT", type=click.Path(path_type=Path))
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Folder for twin.usdc, semantics.usda, cameras/environment/render layers, scenario.usda "
                   "and import_report.json.")
@click.option("--rules", type=click.Path(path_type=Path),
              help="Semantic rules JSON (schemas/semantic_rules.schema.json): (field, RE2 regex) -> class. "
                   "Required for meshes; optional overrides for cityjson and pointcloud.")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--up-axis", type=click.Choice(["Y", "Z"]), help="mesh: the file's up axis [default: Y for glTF, Z otherwise].")
@click.option("--scale", type=InRange(importer_limits.SCALE), default=1.0, show_default=True,
              help="mesh: file units to metres.")
@click.option("--lod", help="cityjson: level of detail to import, one the file has [default: the highest each object "
                            "has].")
@click.option("--crs", help="cityjson, pointcloud: the CRS of the coordinates (EPSG:2263, 2263, a CRS URL or WKT); "
                            "replaces the file's own, and serves files that have none. Its linear units convert "
                            "the coordinates to metres.")
@click.option("--units", type=click.Choice(["m", "ft", "us-ft"]),
              help="cityjson, pointcloud: the linear unit of a file without a CRS (us-ft: US survey foot, "
                   "1200/3937 m). Files whose unit is unknown are refused without --crs or --units.")
@click.option("--max-deviation-m", type=InRange(importer_limits.MAX_DEVIATION), default=0.005, show_default=True,
              help="pointcloud: largest Hausdorff distance simplification may introduce (metres).")
@click.option("--plane-threshold-m", type=InRange(importer_limits.PLANE_THRESHOLD), default=0.02, show_default=True,
              help="pointcloud: RANSAC inlier distance (metres).")
@click.option("--max-residual-m", type=InRange(importer_limits.MAX_RESIDUAL), default=0.10, show_default=True,
              help="pointcloud: a segment whose 95th-percentile point-to-surface distance exceeds this (metres) is "
                   "reported as a finding.")
@click.option("--max-hull-residual-m", type=InRange(importer_limits.MAX_HULL_RESIDUAL), default=1.0,
              show_default=True,
              help="pointcloud: the same bound for a tree's convex hull (metres). A hull encloses its points (trunk, "
                   "branches, the far side of the crown lie inside it), so its bound is looser; past it the hull "
                   "wraps mostly empty space (trees merged into one cluster, or a cluster that is no tree).")
@click.option("--strict", is_flag=True, help="Exit 1 when the import has findings (residuals over their bound, "
                                             "automatic cameras that see too few labelled pixels or stand where no "
                                             "free view was found, buildings without a height). footprints, osm: "
                                             "refuse (exit 2) a building without a usable height instead of taking "
                                             "the next source or --default-height-m.")
@click.option("--populate", is_flag=True,
              help="Also write an agents layer: people walking (and using mobility aids) on the twin's roads, "
                   "sidewalks, crosswalks and curb ramps, composed into the scenario.")
@click.option("--density", type=InRange(DENSITY), default=0.03,
              show_default=True, help="With --populate: persons per m² of walkable area (realistic: up to ~1).")
@click.option("--aid-share", type=InRange(AID_SHARE), default=0.3, show_default=True,
              help="With --populate: share of people using a mobility aid.")
@click.option("--frames", type=click.IntRange(1, 10_000), default=48, show_default=True,
              help="With --populate: time codes of the animation (24 per second).")
@click.option("--storey-height-m", type=InRange(importer_limits.STOREY_HEIGHT),
              default=importer_limits.DEFAULT_STOREY_HEIGHT_M, show_default=True,
              help="footprints, osm: metres per level when a building gives levels (building:levels), not a height.")
@click.option("--default-height-m", type=InRange(importer_limits.DEFAULT_HEIGHT),
              default=importer_limits.DEFAULT_HEIGHT_M, show_default=True,
              help="footprints, osm: the height of a building with no height, levels or roof height (recorded as "
                   "source 'default' in import_report.json; refused with --strict).")
@click.pass_context
def twin_import(ctx: click.Context, kind: str, input_path: Path, out_dir: Path, rules: Path | None,
                class_map: Path | None, up_axis: str | None, scale: float, lod: str | None, crs: str | None,
                units: str | None, max_deviation_m: float, plane_threshold_m: float, max_residual_m: float,
                max_hull_residual_m: float,
                strict: bool, populate: bool, density: float, aid_share: float, frames: int,
                storey_height_m: float, default_height_m: float) -> int:
    """Import real city data of KIND from INPUT as labelled twin layers plus a renderable scenario.

    \b
    KIND       INPUT
    mesh       .obj .ply .glb .gltf .stl (trimesh); classes from --rules (object/material/group regex)
    cityjson   CityJSON 1.1 or 2.0 (units from metadata.referenceSystem, --crs or --units)
    pointcloud .las .laz .ply; units from the LAS CRS (WKT or GeoTIFF keys), --crs or --units;
               ground, connected planes, tree hulls; simplification within --max-deviation-m
    footprints GeoJSON polygons -> extruded LoD1 buildings (heights as for osm)
    osm        OpenStreetMap .osm or .osm.pbf (pyosmium): building and building:part areas -> extruded
               LoD1 buildings, lon/lat projected to a local transverse Mercator (metres)

    \b
    Building heights (footprints, osm), each building's source in import_report.json (heights):
    'height' (metres, or with a unit: '12.13 m', '12,5', '40 ft'), else building:levels x
    --storey-height-m (plus roof:height or roof:levels), else roof:height, else --default-height-m.
    Values that are not lengths are skipped for the next source (refused with --strict).

    Geometry no rule matches is labelled 'unlabelled' (class 0) and listed in import_report.json.
    The scenario stands on a generated ground (unlabelled, 20 km out) and has automatic Overview (densest
    cluster) and Street (1.6 m above a road) cameras, placed in free space outdoors (rays from the eye: not
    inside a closed surface, open sky above, a free view of 5 m ahead); a camera that finds no such spot,
    or whose label pass shows the twin in under 10 % of its pixels, is a finding (exit 1 with --strict).
    Options of one kind (--lod, --scale, ...) are refused for the others. Nothing in --out changes
    unless the whole import is written.
    """
    from synthua_usd.importers import importers
    from synthua_usd.model.class_assignment import AssignmentRules
    from synthua_usd.model.taxonomy import ClassMap

    _refuse_foreign_options(ctx, kind)
    _refuse_population_options(ctx, populate)
    if kind == "mesh" and rules is None:
        raise click.UsageError("--rules: missing; mesh import needs --rules FILE (meshes carry no classes of their "
                               "own; see schemas/semantic_rules.schema.json)", ctx)
    cmap = ClassMap.load_or_bundled(class_map)
    loaded_rules = AssignmentRules.load(rules, cmap) if rules else None
    t0 = time.perf_counter()
    model = importers()[kind](input_path, rules=loaded_rules, up_axis=up_axis, scale=scale, lod=lod, crs=crs,
                              units=units, max_deviation_m=max_deviation_m, plane_threshold_m=plane_threshold_m,
                              max_residual_m=max_residual_m, max_hull_residual_m=max_hull_residual_m,
                              storey_height_m=storey_height_m, default_height_m=default_height_m, strict=strict,
                              show_progress=sys.stderr.isatty())
    seconds = time.perf_counter() - t0
    from synthua_usd.pipeline.twin_import import write_import  # USD and the writers: only once the input is good

    report = {"kind": kind, "input": str(input_path), "seconds": round(seconds, 3), "objects": len(model.objects),
              "triangles": model.triangle_count(), "classes": model.label_counts(), "crs": model.crs,
              "origin_offset_m": list(model.origin_offset_m), **model.report}
    crowd = None
    if populate:
        from synthua_usd.agents.crowd import CrowdParams
        from synthua_usd.pipeline.twin_import import IMPORT_WALKABLE

        crowd = CrowdParams(density_per_m2=density, aid_share=aid_share, time_codes=frames, walkable=IMPORT_WALKABLE)
    written, report = write_import(model, out_dir, cmap, report, crowd,
                                   inputs={"INPUT": input_path, "--rules": rules, "--class-map": class_map})
    say(f"imported {input_path} ({kind}) in {seconds:.1f} s: {len(model.objects)} objects, "
               f"{model.triangle_count()} triangles, classes {model.label_counts()}")
    for seg in model.report.get("segments", []):
        if not seg.get("skipped"):
            say(f"  {seg['name']}: {seg['points']} points -> {seg['faces']} faces, simplification deviation "
                       f"{seg['simplification_deviation_m'] * 1000:.3f} mm, point-to-surface distance p50 "
                       f"{seg['residual_p50_m'] * 1000:.1f} / p95 {seg['residual_p95_m'] * 1000:.1f} / max "
                       f"{seg['residual_max_m'] * 1000:.1f} mm")
    if "heights" in model.report:
        sources = ", ".join(f"{n} from {s}" for s, n in model.report["heights"]["sources"].items() if n)
        click.echo(f"  building heights: {sources}")
    unmatched = model.report.get("unmatched") or model.report.get("unlabelled_types")
    if unmatched:
        say(f"  labelled 'unlabelled' (no rule matched): {echo(unmatched)}")
    if "population" in report:
        p = report["population"]
        say(f"  people: {p['placed']} placed ({p['aid_users']} with mobility aids) on "
                   f"{p['walkable_area_m2']:.0f} m² walkable, {frames} time codes")
    for name, cam in report["cameras"].items():
        say(f"  camera {name}: label pass shows the twin in {cam['labelled_share']:.1%} of its pixels")
    say(f"wrote {len(written)} files to {out_dir}; render with: synthua render {out_dir / 'scenario.usda'} "
               f"--out OUT")
    findings = report.get("findings", [])
    for f in findings:
        click.echo(f"{f['severity']}: {f['where']}: {f['message']} ({f['rule']})", err=True)
    return EXIT_FINDINGS if strict and findings else EXIT_OK


@twin.command("demo")
@seed_option(help="Layout seed.")
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True, help="Output folder.")
def twin_demo(seed: int, out_dir: Path) -> int:
    """Write the procedural Largo da Ordem demo district for SEED as a renderable scenario, without people.

    \b
    Files: twin.usdc (geometry, materials, textures/), semantics.usda (labels), cameras.usda (CCTV_Largo,
    CCTV_Street, PedestrianEye_Street, WheelchairEye_Largo, UAV_Oblique), environment.usda (the conditions,
    clear day selected), render.usda (through CCTV_Largo) and scenario.usda, which composes them.
    The same seed writes byte-identical layers; another seed another plausible layout.

    \b
    From here to a dataset (the README's quickstart):
      synthua agents populate my_district/scenario.usda --out my_district/agents.usdc
      synthua cameras author my_district/scenario.usda --layer my_district/agents.usdc \\
          --rig cctv:aim=aid_user,name=AidCCTV --out my_district/rigs.usda
      synthua compose my_district/with_people.usda my_district/rigs.usda my_district/agents.usdc \\
          my_district/scenario.usda
      synthua render my_district/with_people.usda --camera /World/Cameras/AidCCTV --out out/frame
    (`synthua create district` writes all of it, people and aimed rigs included, in one step.)
    """
    from synthua_usd.demo.district import district_scenario
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.scenario_writer import write_scenario

    spec = district_scenario(seed, agents=False)
    files = write_scenario(spec, out_dir, ClassMap.default())
    say(f"district seed {seed}: {len(spec.twin.objects)} objects, {spec.twin.triangle_count()} triangles, "
        f"{len(spec.twin.label_counts())} classes, {len(spec.cameras)} cameras")
    for path in files:
        say(f"wrote {path}")
    say(f"render with: synthua render {out_dir / 'scenario.usda'} --out OUT; add people with: synthua agents "
        f"populate {out_dir / 'scenario.usda'} --out {out_dir / 'agents.usdc'}")
    return EXIT_OK
