#!/usr/bin/env python
"""Benchmark: the amodal pass (all hits along each pixel ray) against the label pass, on one view.

Usage: python tools/bench_amodal.py [--scenario stages/district/scenario.usda] [--camera /World/Cameras/CCTV_Largo]
                                    [--width 1280 --height 960 --time-code 24 --variant llvm_ad_rgb --repeat 3]

Renders the labels once (warm-up), then times, best of ``--repeat``: the label pass (``render(rgb=False)``
on a loaded session, i.e. sensor update and first hits), and ``RenderSession.amodal`` for the visible
instances of two sets: the person, vehicle, accessibility and furniture groups, and every visible thing
(buildings included). Each amodal set is timed cold (its scene built) and warm (the same ids again: only
the sensor is updated). Prints the layer counts too. Not a test.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
GROUPS = ("person", "vehicle", "accessibility", "furniture")


def main() -> None:
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.reader import read_snapshot
    from synthua_usd.usd.stage_io import open_stage

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", default=str(REPO / "stages/district/scenario.usda"))
    p.add_argument("--camera", default="/World/Cameras/CCTV_Largo")
    p.add_argument("--width", type=int, default=1280)
    p.add_argument("--height", type=int, default=960)
    p.add_argument("--time-code", type=float, default=24)
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args()

    class_map = ClassMap.default()
    group_of = {c.id: c.group for c in class_map.classes}
    stage = open_stage(args.scenario)
    snap = read_snapshot(stage, args.time_code, class_map)
    cam = read_camera(stage, args.camera, args.time_code)
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=1, variant=args.variant))
    frame = session.render(snap, cam, rgb=False)
    label_s = min(_timed(lambda: session.render(snap, cam, rgb=False)) for _ in range(args.repeat))
    visible = [snap.instance(int(i)) for i in np.unique(frame.instance_ids) if i]
    sets = {"groups": [i.id for i in visible if i.isthing and group_of[i.class_id] in GROUPS],
            "all things": [i.id for i in visible if i.isthing]}
    print(f"{args.scenario} {args.camera} t={args.time_code} {args.width}x{args.height} {session.variant}")
    print(f"label pass: {label_s:.3f} s ({len(visible)} visible instances)")
    for name, ids in sets.items():
        triangles = sum(len(m.triangles) for m in snap.meshes if m.instance_id in set(ids))
        session._amodal = None
        cold = _timed(lambda: session.amodal(snap, cam, ids))
        warm = min(_timed(lambda: session.amodal(snap, cam, ids)) for _ in range(args.repeat))
        masks = session.amodal(snap, cam, ids)
        visible_px = sum(int((frame.instance_ids == i).sum()) for i in ids)
        amodal_px = sum(len(v) for v in masks.values())
        print(f"amodal {name}: {len(ids)} instances, {triangles} triangles; cold {cold:.3f} s, warm {warm:.3f} s "
              f"({warm / label_s:.2f}x label pass); visible {visible_px} px, amodal {amodal_px} px; "
              f"{len(session._amodal.apart)} scenes, layers reached {session._amodal.layers}, "
              f"capped rays {session._amodal.capped_rays}")


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()
