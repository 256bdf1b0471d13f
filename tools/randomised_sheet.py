#!/usr/bin/env python
"""A contact sheet of randomised images of one camera at one time code: what every image being a new scene
looks like (docs/randomised_sheet.jpg in the README).

Usage: python tools/randomised_sheet.py [--scenario stages/district/scenario.usda] [--camera /World/Cameras/CCTV_Largo]
       [--time-code 24] [--condition clear_day] [--seeds 16] [--width 480 --height 360] [--spp 16]
       [--config configs/district_random.json] [--out docs/randomised_sheet.jpg]

Each cell is the seed's scene as `synthua generate` renders it (the config's randomise block, here without
its district seeds unless --districts: one scenario, one camera), captioned with the seed, the people in the
scene, the sun's elevation and the exposure compensation.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def save_grid(cells, captions, columns: int, row_inches: float, caption_size: float, title: str, out: Path) -> None:
    """``cells`` (images) in a grid of ``columns``, each under its caption, with ``title`` above, saved to ``out``
    (JPEG quality 85 or PNG by its suffix); also used by tools/aid_users_sheet.py."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    rows = -(-len(cells) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(columns * 4.0, rows * row_inches))
    for ax, cell, caption in zip(np.ravel(axes), cells, captions):
        ax.imshow(cell)
        ax.set_title(caption, fontsize=caption_size)
        ax.axis("off")
    for ax in np.ravel(axes)[len(cells):]:
        ax.axis("off")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110, pil_kwargs={"quality": 85})


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--camera", default="/World/Cameras/CCTV_Largo")
    parser.add_argument("--time-code", type=float, default=24.0)
    parser.add_argument("--condition", default="clear_day")
    parser.add_argument("--seeds", type=int, default=16)
    parser.add_argument("--columns", type=int, default=4)
    parser.add_argument("--width", type=int, default=480)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--config", type=Path, default=REPO / "configs" / "district_random.json")
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "randomised_sheet.jpg")
    args = parser.parse_args()

    from dataclasses import replace

    from synthua_usd.core import images
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.dataset.config import GenerationConfig
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline.randomiser import Randomiser
    from synthua_usd.randomisation.config import DistrictRandomisation
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.conditions import read_condition
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    randomise = replace(GenerationConfig.load(args.config).randomise, district=DistrictRandomisation(enabled=False))
    class_map = ClassMap.default()
    stage = open_stage(args.scenario)
    reader = StageReader(stage, class_map)
    randomiser = Randomiser(stage, randomise, class_map, (args.width, args.height))
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=args.spp))
    cells, captions = [], []
    for seed in range(args.seeds):
        drawn = randomiser.apply(seed, args.camera, args.time_code, args.condition)
        frame = session.render(reader.snapshot(args.time_code), read_camera(stage, args.camera, args.time_code),
                               condition=read_condition(stage, args.condition), seed=seed)
        cells.append(images.linear_to_display(frame.rgb * np.float32(frame.exposure.scale)))
        aid = sum(1 for m in drawn.scene.cast if m.aid is not None)
        captions.append(f"seed {seed}: {len(drawn.scene.cast)} people ({aid} with aids), sun "
                        f"{drawn.light.sun_elevation_deg:.0f}° at {drawn.light.sun_azimuth_deg:.0f}°, "
                        f"{drawn.light.exposure_ev:+.1f} EV")
        print(captions[-1], flush=True)

    save_grid(cells, captions, args.columns, 3.25, 6.5, f"{args.camera} at time code {args.time_code:g}, "
              f"{args.condition}: one scene per seed ({args.config.name} randomise block)", args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
