"""``synthua contact-sheet``: every condition of a scenario from each of its cameras, in one PNG."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_OK, say
from synthua_usd.cli.options import seed_option


@click.command("contact-sheet")
@click.argument("scenario", type=click.Path(path_type=Path))
@click.option("--time-code", "--frame", "time_code", type=float,
              help="Time code to render [default: the stage's start time code].")
@click.option("--camera", "cameras", multiple=True, help="Camera prim path; repeat for several [default: every camera].")
@click.option("--condition", "conditions", multiple=True,
              help="Condition name; repeat for several [default: every condition the stage offers].")
@click.option("--width", type=click.IntRange(16, 4096), default=320, show_default=True, help="Width of each cell image.")
@click.option("--height", type=click.IntRange(16, 4096), default=240, show_default=True, help="Height of each cell image.")
@click.option("--spp", type=click.IntRange(1, 65536), default=16, show_default=True, help="RGB samples per pixel.")
@seed_option(help="Sampler and rain seed.")
@click.option("--variant", help="Mitsuba variant [default: best available].")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--out", "out_path", type=click.Path(path_type=Path), required=True, help="The sheet to write (.png).")
@click.option("--allow-external-assets", is_flag=True,
              help="Accept layers outside the stage's folder tree (refused by default).")
def contact_sheet(scenario: Path, time_code: float | None, cameras: tuple[str, ...], conditions: tuple[str, ...],
                  width: int, height: int, spp: int, seed: int, variant: str | None, class_map: Path | None,
                  out_path: Path, allow_external_assets: bool) -> int:
    """Render one time code of SCENARIO under every condition and from every camera into one PNG grid:
    a row per camera, a column per condition, each cell the exposed RGB beside the class colours blended
    over it.

    \b
    Example:
      synthua contact-sheet stages/district/scenario.usda --time-code 24 --out out/sheet.png
    """
    import math

    from synthua_usd.core.errors import InputError
    from synthua_usd.pipeline.contact_sheet import SheetRequest, make_contact_sheet

    if time_code is not None and not math.isfinite(time_code):
        raise InputError(f"synthua contact-sheet: --time-code: {time_code} is not a finite number")
    t0 = time.perf_counter()
    run = make_contact_sheet(SheetRequest(stage_path=scenario, out_path=out_path, time_code=time_code,
                                          camera_paths=cameras, conditions=conditions, width=width, height=height,
                                          spp=spp, seed=seed, variant=variant, class_map_path=class_map,
                                          allow_external_assets=allow_external_assets),
                             show_progress=sys.stderr.isatty())
    say(f"wrote {run.path}: {len(run.cameras)} cameras x {len(run.conditions)} conditions "
               f"({', '.join(run.conditions)}) in {time.perf_counter() - t0:.1f} s "
               f"({run.loads} scene loads)")
    return EXIT_OK
