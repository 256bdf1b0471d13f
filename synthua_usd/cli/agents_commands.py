"""``synthua agents``: crowds with mobility-aid users."""

from __future__ import annotations

from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_OK, say
from synthua_usd.cli.options import AID_SHARE, DENSITY, InRange, seed_option
from synthua_usd.model.ranges import Range

# --- agents -----------------------------------------------------------------------------------------------

@click.group()
def agents() -> None:
    """Crowds with mobility-aid users on the walkable graph of a twin."""


@agents.command("populate")
@click.argument("stage", metavar="TWIN_OR_SCENARIO", type=click.Path(path_type=Path))
@click.option("--density", type=InRange(DENSITY), default=0.03, show_default=True,
              help="Persons per m² of walkable area (Poisson mean = density x area). Refused above 5 (crowd "
                   "crush); warned above 0.7 (level of service E).")
@click.option("--aid-share", type=InRange(AID_SHARE), default=0.3, show_default=True,
              help="Fraction of agents using a mobility aid (wheelchairs, walker, crutches, canes).")
@click.option("--time-codes", "--frames", "time_codes", type=click.IntRange(1, 10_000), default=48, show_default=True,
              help="Time codes to author, one sample each, from the stage's start time code (--frames is the same).")
@seed_option(help="Seed: same seed, same bytes.")
@click.option("--cell-m", type=InRange(Range(0.05, 10.0, "m")), default=0.5, show_default=True,
              help="Walkable grid cell size (metres, 0.05-10).")
@click.option("--walk-on", default="sidewalk,crosswalk,curb_ramp,street_road", show_default=True,
              help="Comma-separated classes people walk on; the road always counts inside crosswalks. Add 'road' "
                   "for imported twins whose roads include their sidewalks (CityJSON often).")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--out", "out_path", type=click.Path(path_type=Path), required=True, help="The agents layer to write (.usdc binary, or .usda text).")
@click.option("--allow-external-assets", is_flag=True,
              help="Accept layers outside the stage's folder tree (refused by default).")
def agents_populate(stage: Path, density: float, aid_share: float, time_codes: int, seed: int, cell_m: float,
                    walk_on: str, class_map: Path | None, out_path: Path, allow_external_assets: bool) -> int:
    """Populate TWIN_OR_SCENARIO with walking people and mobility-aid users; write them as a layer.

    \b
    The walkable graph covers sidewalks, crosswalks, curb ramps and cobbled streets (the road only on
    crosswalks). Wheelchair and walker users never step a kerb: they cross at curb ramps. Agents pause
    before crosswalks and never come within 0.1 m of each other (disc to disc) at any time code.
    Compose the layer into a scenario with `synthua compose`, e.g.
      synthua compose my.usda agents.usdc stages/district/render.usda ... stages/district/twin.usdc
    """
    from synthua_usd.agents.crowd import CrowdParams
    from synthua_usd.pipeline.populate import PopulateRequest, populate

    walkable = tuple(c.strip() for c in walk_on.split(",") if c.strip())
    params = CrowdParams(density_per_m2=density, aid_share=aid_share, time_codes=time_codes, seed=seed, cell_m=cell_m,
                         walkable=walkable)
    crowd, path, seconds = populate(PopulateRequest(stage, out_path, params, class_map, allow_external_assets))
    r = crowd.report
    say(f"walkable area {r['walkable_area_m2']:.0f} m², expected {r['expected']:.1f} agents, sampled "
               f"{r['sampled']}, placed {r['placed']} ({r['aid_users']} with mobility aids), dropped "
               f"{r['dropped']} (no collision-free start)")
    say(f"profiles {r['by_profile']}")
    say(f"minimum gap between agents over {time_codes} time codes: {r['min_separation_m']:.3f} m; {seconds:.1f} s")
    say(f"wrote {path}")
    return EXIT_OK
