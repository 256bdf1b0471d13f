#!/usr/bin/env python
"""Benchmark: building the demo district, importing the third-party city data, populating agents.

Usage: python tools/bench_twin.py [--shared ../shared]

Prints seconds per step and the sizes involved. Not a test: numbers depend on the machine.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def timed(label: str, fn):
    t0 = time.perf_counter()
    out = fn()
    print(f"{label:44} {time.perf_counter() - t0:7.2f} s")
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shared", type=Path, default=REPO.parent / "shared")
    args = parser.parse_args()

    from synthua_usd.importers.cityjson import import_cityjson
    from synthua_usd.importers.pointcloud import import_pointcloud
    from synthua_usd.demo.district import build_district
    from synthua_usd.agents.crowd import CrowdParams
    from synthua_usd.pipeline.populate import PopulateRequest, populate

    model = timed("district: build (seed 0)", lambda: build_district(0))
    print(f"  {len(model.objects)} objects, {model.triangle_count()} triangles, {len(model.label_counts())} classes")
    third = args.shared / "data" / "third_party"
    if third.exists():
        delft = timed("import cityjson delft.json", lambda: import_cityjson(third / "cityjson" / "delft.json"))
        print(f"  {len(delft.objects)} objects, {delft.triangle_count()} triangles")
        for name in ("simple.las", "plane.laz"):
            cloud = timed(f"import pointcloud {name}", lambda: import_pointcloud(third / "las" / name))
            for seg in cloud.report["segments"]:
                print(f"  {seg['name']}: {seg['points']} points, {seg['faces_reconstructed']} -> {seg['faces']} faces, "
                      f"simplification deviation {seg['simplification_deviation_m'] * 1000:.3f} mm, residual max "
                      f"{seg['residual_max_m'] * 1000:.1f} mm")
    else:
        print(f"(no {third}: imports skipped)")
    with tempfile.TemporaryDirectory() as tmp:
        crowd, _, _ = timed("agents: populate district (0.03/m², 48 time codes)",
                            lambda: populate(PopulateRequest(REPO / "stages" / "district" / "scenario.usda",
                                                             Path(tmp) / "agents.usdc",
                                                             CrowdParams(density_per_m2=0.03, time_codes=48, seed=0))))
    r = crowd.report
    print(f"  {r['placed']} agents ({r['aid_users']} with aids), {r['dropped']} dropped, minimum gap "
          f"{r['min_separation_m']:.3f} m on {r['walkable_area_m2']:.0f} m² walkable")
    return 0


if __name__ == "__main__":
    sys.exit(main())
