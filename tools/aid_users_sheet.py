#!/usr/bin/env python
"""A contact sheet of mobility-aid users as a detector sees them in randomised scenes (docs/images/aid_users.jpg in
the README): crops of the aid users of randomised images, each beside its class overlay, with the companions who
push them or walk with them.

Usage: python tools/aid_users_sheet.py [--scenario stages/district/scenario.usda] [--seeds 12] [--width 960
       --height 720] [--spp 32] [--cells 16] [--out docs/images/aid_users.jpg]

Each seed is one randomised image (the `randomise` block below: every aid, many companions, aid users placed where
the camera sees them large; the camera, light and materials randomised as `generate` does), rendered through a
render session with OIDN at --spp, at time code 24 under clear_day, from a camera of the scenario chosen per seed.
From each image, every aid user whose person and device cover at least 1,500 pixels is cut out with the pusher or
companions beside it (the union of their boxes, 15 % margin, squared), scaled to a cell, and put beside the same
crop of the class map over the RGB. The caption names the aid and who is with it.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from randomised_sheet import save_grid  # tools/ is the script's own folder on sys.path

REPO = Path(__file__).resolve().parents[1]
#: The randomise block of the sheet (a generation config's; its schema documents each part).
RANDOMISE = {"seed": 5, "crowd": {"density_per_m2": [0.03, 0.05], "aid_share": [0.4, 0.6], "aid_users_in_view": [2, 3],
                                  "view_height_share": [0.25, 0.55], "pushed_share": [0.5, 0.7],
                                  "accompanied_share": [0.4, 0.6]}}
CELL = 240
MIN_PIXELS = 1500


def _box(mask: np.ndarray) -> tuple[int, int, int, int] | None:
    ys, xs = np.nonzero(mask)
    return None if not len(xs) else (int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1)


def _crop(image: np.ndarray, box, size: int) -> np.ndarray:
    """``box`` (x0, y0, x1, y1) grown by 15 % and squared, cut from ``image`` (padded with grey where it leaves the
    image) and scaled to ``size`` square (nearest neighbour: a class overlay keeps its colours)."""
    x0, y0, x1, y1 = box
    side = int(max(x1 - x0, y1 - y0) * 1.15) + 2
    cx, cy = (x0 + x1) // 2, (y0 + y1) // 2
    h, w = image.shape[:2]
    out = np.full((side, side, 3), 40, np.uint8)
    sx0, sy0 = cx - side // 2, cy - side // 2
    a0, b0 = max(sx0, 0), max(sy0, 0)
    a1, b1 = min(sx0 + side, w), min(sy0 + side, h)
    out[b0 - sy0:b1 - sy0, a0 - sx0:a1 - sx0] = image[b0:b1, a0:a1]
    index = (np.arange(size) * side / size).astype(int)
    return out[index][:, index]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--seeds", type=int, default=12)
    parser.add_argument("--width", type=int, default=960)
    parser.add_argument("--height", type=int, default=720)
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--cells", type=int, default=16)
    parser.add_argument("--columns", type=int, default=4)
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "images" / "aid_users.jpg")
    args = parser.parse_args()

    from synthua_usd.core import images
    from synthua_usd.backends.contact_sheet import class_overlay
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline.randomiser import Randomiser
    from synthua_usd.randomisation.config import RandomisationConfig
    from synthua_usd.usd.cameras import camera_paths, read_camera
    from synthua_usd.usd.conditions import read_condition
    from synthua_usd.usd.randomisation_layer import CROWD_ROOT
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    class_map = ClassMap.default()
    palette = np.zeros((256, 3), np.uint8)
    for c in class_map.classes:
        palette[c.id] = c.color
    stage = open_stage(args.scenario)
    reader = StageReader(stage, class_map)
    randomiser = Randomiser(stage, RandomisationConfig.from_document(RANDOMISE), class_map, (args.width, args.height))
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=args.spp, denoise=True))
    cameras = [p for p in camera_paths(stage) if "UAV" not in p and "Drone" not in p]
    cells, captions = [], []
    for seed in range(args.seeds):
        if len(cells) >= args.cells:
            break
        camera_path = cameras[seed % len(cameras)]
        drawn = randomiser.apply(seed, camera_path, 24.0, "clear_day")
        snapshot = reader.snapshot(24.0)
        frame = session.render(snapshot, read_camera(stage, camera_path, 24.0),
                               condition=read_condition(stage, "clear_day"), seed=seed)
        rgb = images.linear_to_display(frame.rgb * np.float32(frame.exposure.scale))
        overlay = class_overlay(rgb, frame.class_ids, palette)
        by_path = {i.prim_path: i.id for i in snapshot.instances}
        cast = drawn.scene.cast
        for k, member in enumerate(cast):
            if member.aid is None or len(cells) >= args.cells:
                continue
            agent = f"{CROWD_ROOT}/Agent_{k:04d}"
            ids = [i for p, i in by_path.items() if p.startswith(agent + "/")]
            mask = np.isin(frame.instance_ids, ids)
            if mask.sum() < MIN_PIXELS:
                continue
            with_it = [j for j, m in enumerate(cast) if m.pushes == k or m.accompanies == k]
            group = np.isin(frame.instance_ids, [i for j in with_it for p, i in by_path.items()
                                                 if p.startswith(f"{CROWD_ROOT}/Agent_{j:04d}/")])
            box = _box(mask | group)
            cells.append(np.concatenate([_crop(rgb, box, CELL), _crop(overlay, box, CELL)], axis=1))
            who = ("pushed" if member.pushed_by is not None else
                   f"with {len(with_it)} companion{'s' * (len(with_it) > 1)}" if with_it else "alone")
            captions.append(f"{member.aid.replace('_', ' ')}, {who} (seed {seed})")
            print(captions[-1], flush=True)

    save_grid(cells, captions, args.columns, 2.2, 7, f"Mobility-aid users in randomised images of "
              f"{args.scenario.parent.name}/{args.scenario.name}: RGB ({args.width}x{args.height}, {args.spp} spp + "
              f"OIDN) beside the class overlay", args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
