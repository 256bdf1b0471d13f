#!/usr/bin/env python
"""Benchmark: where the Mitsuba label pass and an independent Embree ray cast disagree, per camera.

Usage: python tools/bench_label_agreement.py [--scenario stages/district/scenario.usda] [--cameras NAME ...]
                                            [--width 1280 --height 960 --time-code 24 --pairs 12]

Prints, per camera, the number of pixels whose instance id (and class id) differs between the two
first-hit casts, then the most frequent disagreeing pairs: pixel count, Mitsuba's instance [class], the reference's instance
[class], the median gap between the two first hits along the ray (Mitsuba's minus Embree's, metres), and
the median distance from the ray to the nearest triangle edge of either instance (metres).

A ray that passes within a few micrometres of an edge (a silhouette, or the seam where two instances
touch) is a float edge case: the two casts trace rays that differ by float32 rounding, and either answer
is right. Anything else (an edge distance of millimetres or more with a gap near 0) means two instances'
surfaces lie on top of each other there (coplanar faces, or a face inside another solid): a real
ambiguity to fix in the geometry. Needs the test extra ``embreex``. Not a test.
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))


def _reference_distances(snapshot, camera, width: int, height: int, pixels: np.ndarray) -> np.ndarray:
    """(k,) float64 metres: Embree's first-hit distance for the flat pixel indices ``pixels`` (inf on a miss)."""
    import trimesh
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    verts, faces, _ = snapshot.world_triangles()
    mesh = trimesh.Trimesh(verts, faces, process=False, validate=False)
    origins, dirs = camera.pixel_center_rays(width, height)
    origins, dirs = origins[pixels], dirs[pixels]
    tri, ray, loc = RayMeshIntersector(mesh).intersects_id(origins, dirs, multiple_hits=False, return_locations=True)
    out = np.full(len(pixels), np.inf)
    out[ray] = np.linalg.norm(loc - origins[ray], axis=1)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--cameras", nargs="+", default=None, help="camera prim names (default: every district camera)")
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=960)
    parser.add_argument("--time-code", "--frame", dest="time_code", type=float, default=24.0)
    parser.add_argument("--pairs", type=int, default=12, help="how many disagreeing pairs to list per camera")
    parser.add_argument("--variant", default=None)
    args = parser.parse_args()

    from reference_raycast import edge_distance, reference_labels
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.demo.district import DISTRICT_CAMERAS
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(args.scenario)
    snapshot = StageReader(stage, ClassMap.default()).snapshot(args.time_code)
    names = {0: "(none)"} | {i.id: f"{i.prim_path.rsplit('/Twin/', 1)[-1]} [{i.class_name}]" for i in snapshot.instances}
    session = RenderSession(RenderConfig(width=args.width, height=args.height, spp=1, variant=args.variant))
    cameras = args.cameras or [c.name for c in DISTRICT_CAMERAS]
    w, h = args.width, args.height
    print(f"{args.scenario} at time code {args.time_code:g}, {w}x{h}, {snapshot.triangle_count()} triangles")
    total = 0
    for name in cameras:
        camera = read_camera(stage, f"/World/Cameras/{name}", args.time_code)
        frame = session.render(snapshot, camera, rgb=False)
        ref_class, ref_inst = reference_labels(snapshot, camera, w, h)
        bad = np.flatnonzero(frame.instance_ids.ravel() != ref_inst.ravel())
        bad_class = int(np.count_nonzero(frame.class_ids != ref_class))
        total += len(bad)
        print(f"\n{name}: {len(bad)} of {w * h} pixels disagree on the instance ({1 - len(bad) / (w * h):.6%} agree), "
              f"{bad_class} on the class")
        if not len(bad):
            continue
        ours = frame.instance_ids.ravel()[bad].astype(np.int64)
        theirs = ref_inst.ravel()[bad].astype(np.int64)
        # Mitsuba's perspective sensor starts its rays on the near clipping plane: add that stretch back.
        _, dirs = camera.pixel_center_rays(w, h)
        near = camera.clip_near_m / (dirs[bad] @ camera.axes()[2])
        d_ours = np.where(ours > 0, frame.hits.distance_m.ravel()[bad] + near, np.inf)
        d_ref = _reference_distances(snapshot, camera, w, h, bad)
        gap = d_ours - d_ref
        origins, _ = camera.pixel_center_rays(w, h)
        for (a, b), n in Counter(zip(ours.tolist(), theirs.tolist())).most_common(args.pairs):
            sel = np.flatnonzero((ours == a) & (theirs == b))
            edge = [min(edge_distance(snapshot, a, origins[bad[k]], dirs[bad[k]]),
                        edge_distance(snapshot, b, origins[bad[k]], dirs[bad[k]])) for k in sel]
            print(f"  {n:6d}  {names[a]}  vs  {names[b]}  gap {np.median(gap[sel]):+.4f} m, "
                  f"edge {np.median(edge):.1e} m")
    print(f"\ntotal disagreeing pixels: {total}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
