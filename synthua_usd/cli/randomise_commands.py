"""``synthua randomise``: the randomisation layers one image of a randomised dataset gets, written out."""

from __future__ import annotations

import shlex
from pathlib import Path

import click

from synthua_usd.cli.common import EXIT_OK
from synthua_usd.cli.options import InRange, seed_option
from synthua_usd.model.ranges import Range


@click.command()
@click.argument("scenario", type=click.Path(path_type=Path))
@click.option("--config", "config_path", type=click.Path(path_type=Path),
              help="Generation config whose randomise block draws the layers (schemas/generate.schema.json).")
@click.option("--record", "record_path", type=click.Path(path_type=Path),
              help="Or an image record of a randomised dataset (DATASET/records/NAME.json): its seed, camera, time "
                   "code, condition and render size, and the dataset's config (so --config, --seed, --camera, "
                   "--time-code and --condition are refused with it).")
@seed_option(help="The image's seed: images of one seed share a scene (crowd, looks, materials) [default: 0].",
             default=None)
@click.option("--camera", help="Camera prim path [default: the render settings' camera].")
@click.option("--time-code", "--frame", "time_code", type=InRange(Range(-1e9, 1e9)),
              help="Time code of the image [default: the stage's start time code].")
@click.option("--condition", help="Condition the image is rendered under (its light is drawn within it) [default: "
                                  "none: the stage's own lights, nothing of the light drawn].")
@click.option("--out", "out", type=click.Path(path_type=Path), required=True,
              help="The image's layer, e.g. layer.usda; layer.scene.usda and layer.prototypes.usdc go beside it.")
@click.option("--class-map", type=click.Path(path_type=Path), help="Class map [default: bundled].")
@click.option("--allow-external-assets", is_flag=True,
              help="Accept layers outside the stage's folder tree (refused by default).")
def randomise(scenario: Path, config_path: Path | None, record_path: Path | None, seed: int | None, camera: str | None,
              time_code: float | None, condition: str | None, out: Path, class_map: Path | None,
              allow_external_assets: bool) -> int:
    """Write the randomisation layers of one image over SCENARIO.

    \b
    Example (the layers of image 3 of a randomised dataset, then the image again):
      synthua randomise stages/district/scenario.usda --record out/ds/records/000003_....json --out r/layer.usda
      synthua render stages/district/scenario.usda --layer r/layer.usda ...   (the command printed)
    \b
    Three files, each sublayering the next: OUT (this view: where every person stands and how, the camera's
    pose, focal length and exposure, the condition's sun and sky), OUT's stem + .scene.usda (this seed's
    scene: the new crowd with its clothes and devices, the twin's objects rebound to material variants, the
    scenario's own crowd deactivated) and + .prototypes.usdc (the crowd's meshes); with looks on, the images the
    people wear (fabrics, shoes, faces) copied into OUT's stem + .looks/ beside them. Open OUT over the scenario
    in any USD tool (synthua compose view.usda OUT SCENARIO), or render it with synthua render --layer OUT;
    with the printed settings the render reproduces the dataset's image.
    """
    from synthua_usd.pipeline.randomiser import RandomiseRequest, randomise_image

    result = randomise_image(RandomiseRequest(scenario=scenario, out=out, config_path=config_path,
                                              record_path=record_path, seed=seed, camera=camera, time_code=time_code,
                                              condition=condition, class_map_path=class_map,
                                              allow_external_assets=allow_external_assets))
    scene = result.randomisation.scene
    aid = sum(1 for m in scene.cast if m.aid is not None)
    click.echo(f"scene {scene.scene_seed}: {len(scene.cast)} people ({aid} using mobility aids), "
               f"{len(scene.recolours)} objects recoloured; wrote {', '.join(str(p) for p in result.files)}")
    click.echo("render it with: " + " ".join(shlex.quote(a) for a in result.render_args))
    return EXIT_OK
