#!/usr/bin/env python
"""A contact sheet of the procedural settings (``randomise.settings``) with distractors (``randomise.distractors``):
a few randomised images of each setting, each beside its class overlay (docs/images/settings_sheet.jpg).

Usage: python tools/settings_sheet.py [--scenario stages/district/scenario.usda] [--config configs/settings_random.json]
       [--kinds corridor hall ...] [--variant 0] [--camera /World/Cameras/CCTV_AidUser_1 ...] [--condition clear_day]
       [--width 320 --height 240] [--spp 32] [--out docs/images/settings_sheet.jpg]

Each row is one setting (``--variant``'s layout) written for the scenario as ``synthua generate`` writes it into a
dataset's ``scenes/``, with the scenario's own twin (the district) as the last row; each column one of the cameras,
the scene of seed = column index, randomised by the config's ``randomise`` block (its crowd, looks, materials,
light, camera jitter and distractors) as a dataset image of that seed in that setting is. Class colours are the
class map's, blended at 50 % over the RGB; unlabelled pixels (void: the sky, primitive distractors, strollers and
trolleys) keep their RGB.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
CAMERAS = ("/World/Cameras/CCTV_AidUser_1", "/World/Cameras/PedestrianEye_AidUser", "/World/Cameras/WheelchairEye_AidUser")


def main() -> int:
    from synthua_usd.randomisation.settings import SETTING_KINDS

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--config", type=Path, default=REPO / "configs" / "settings_random.json")
    parser.add_argument("--kinds", nargs="+", default=list(SETTING_KINDS), choices=SETTING_KINDS)
    parser.add_argument("--variant", type=int, default=0)
    parser.add_argument("--camera", nargs="+", default=list(CAMERAS))
    parser.add_argument("--time-code", type=float, default=24.0)
    parser.add_argument("--condition", default="clear_day")
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "images" / "settings_sheet.jpg")
    args = parser.parse_args()

    from dataclasses import replace

    from PIL import Image

    from synthua_usd.backends import images
    from synthua_usd.backends.contact_sheet import class_overlay, compose
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.dataset.config import GenerationConfig
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline.randomiser import Randomiser
    from synthua_usd.pipeline.scenes import SceneKey, write_scene
    from synthua_usd.randomisation.config import DistrictRandomisation
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.conditions import read_condition
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    # the scene of each row is its own: the draw of which setting a seed is in is the sheet's, not the config's
    randomise = replace(GenerationConfig.load(args.config).randomise, district=DistrictRandomisation(enabled=False))
    class_map = ClassMap.default()
    palette = class_map.palette()
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=args.spp))
    cells, rows = {}, []
    with tempfile.TemporaryDirectory() as tmp:
        scenarios = [(f"{kind} (variant {args.variant})", SceneKey(kind, args.variant)) for kind in args.kinds]
        for row, (label, key) in enumerate(scenarios + [("the district", None)]):
            scenario = args.scenario if key is None else write_scene(args.scenario, key, Path(tmp) / key.name, class_map)
            stage = open_stage(scenario, allow_external_assets=True)
            reader = StageReader(stage, class_map)
            randomiser = Randomiser(stage, randomise, class_map, (args.width, args.height))
            rows.append(label)
            for col, camera in enumerate(args.camera):
                drawn = randomiser.apply(col, camera, args.time_code, args.condition, key)
                frame = session.render(reader.snapshot(args.time_code), read_camera(stage, camera, args.time_code),
                                       condition=read_condition(stage, args.condition), seed=col)
                rgb8 = images.linear_to_display(frame.rgb * np.float32(frame.exposure.scale))
                cells[(row, col)] = (rgb8, class_overlay(rgb8, frame.class_ids, palette))
                aid = sum(1 for m in drawn.scene.cast if m.aid is not None)
                count = 0 if drawn.distractors is None else len(drawn.distractors.items)
                print(f"{label}, {camera}: {len(drawn.scene.cast)} people ({aid} with aids), {count} distractors",
                      flush=True)
            randomiser.close()
    title = (f"Procedural settings with distractors ({args.config.name}, {args.condition}, {args.spp} spp + OIDN): "
             f"a scene per seed, RGB and classes")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(compose(cells, rows, [c.rsplit("/", 1)[-1] for c in args.camera], title)).save(args.out, quality=85)
    return 0


if __name__ == "__main__":
    sys.exit(main())
