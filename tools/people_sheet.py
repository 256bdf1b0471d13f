#!/usr/bin/env python
"""Contact sheet of 20 people: every mobility aid, several ages and builds, as the agents layer renders them.

Usage: python tools/people_sheet.py [--out docs/people_sheet.png] [--time-code 12] [--width 800 --height 450]
       [--spp 32]

Writes a small scenario (a concrete ground, the shipped clear-day environment) into a temporary folder: four
rows of five agents 1.4 m apart, each walking (or rolling) along +X at its profile's mean speed (one sits on
a bench), and one camera per row looking at it three-quarters from the front; then renders it with
``synthua contact-sheet``'s pipeline (:func:`synthua_usd.pipeline.contact_sheet.make_contact_sheet`): per
row, the RGB beside the class overlay. The agents, by row and from the left, are listed in :data:`ROWS`
(body index, age, sex, height and BMI are printed).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

#: Per row (camera name, agents from left to right as (profile name, body index of the bank, look colours)).
ROWS = (
    ("Young", [("pedestrian", 15, "Skin1", "Shirt3", "Trousers2"), ("pedestrian", 6, "Skin8", "Shirt5", "Trousers0"),
                                 ("pedestrian", 9, "Skin4", "Shirt1", "Trousers4"), ("pedestrian", 3, "Skin9", "Shirt6", "Trousers3"),
                                 ("pedestrian", 32, "Skin2", "Shirt0", "Trousers1")]),
    ("Adults_bench", [("pedestrian", 45, "Skin6", "Shirt2", "Trousers5"), ("pedestrian", 36, "Skin3", "Shirt7", "Trousers0"),
                                    ("pedestrian", 37, "Skin7", "Shirt4", "Trousers6"), ("bench", 2, "Skin0", "Shirt1", "Trousers2"),
                                    ("pedestrian", 40, "Skin5", "Shirt3", "Trousers1")]),
    ("Elders_chairs", [("pedestrian", 20, "Skin2", "Shirt5", "Trousers3"), ("pedestrian", 22, "Skin9", "Shirt0", "Trousers4"),
                                     ("manual_wheelchair", 61, "Skin4", "Shirt6", "Trousers0"),
                                     ("electric_wheelchair", 67, "Skin1", "Shirt2", "Trousers5"),
                                     ("walker", 63, "Skin6", "Shirt4", "Trousers1")]),
    ("Crutch_canes", [("crutches", 58, "Skin8", "Shirt7", "Trousers2"), ("smart_cane", 59, "Skin3", "Shirt1", "Trousers6"),
                                 ("wooden_cane", 53, "Skin0", "Shirt3", "Trousers3"), ("orthopedic_cane", 65, "Skin7", "Shirt5", "Trousers0"),
                                 ("tripod_cane", 60, "Skin5", "Shirt0", "Trousers4")]),
)
SPACING_M = 1.4
ROW_GAP_M = 40.0


def people_scenario():
    """The scenario spec of the sheet (see the module's docstring)."""
    from synthua_usd.agents.crowd import CrowdParams, scripted_crowd
    from synthua_usd.agents.motion import simulate
    from synthua_usd.agents.population import Plan
    from synthua_usd.agents.profiles import PROFILES
    from synthua_usd.agents.seats import ORIGIN_FROM_BACK_M, SeatPlace
    from synthua_usd.assets import street
    from synthua_usd.assets.people import PersonLook
    from synthua_usd.composition.scenario import ScenarioSpec, StageMetadata
    from synthua_usd.model import meshes as geo
    from synthua_usd.model.cameras import CameraSpec
    from synthua_usd.model.materials import subset
    from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart

    meta = StageMetadata(time_codes_per_second=24.0, start_time_code=1.0, end_time_code=24.0)
    grounds, benches, plans, looks, cameras = [], [], [], [], []
    for r, (camera, agents) in enumerate(ROWS):
        x0 = y0 = r * ROW_GAP_M  # rows on a diagonal: no camera sees another row
        grounds.append(TwinPart.of(f"Mesh{r}", geo.box((x0 - 12.0, y0 - 12.0, -0.2), (x0 + 12.0, y0 + 12.0, 0.0)), "Concrete"))
        for k, (profile, body, skin, shirt, trousers) in enumerate(agents):
            y = y0 + (k - 2) * SPACING_M
            if profile == "bench":  # seated on a bench facing +X, where the walkers are now
                bx = x0 - 1.4
                benches.append(TwinPart.of(f"Bench{r}", geo.merge(*[(p.points + [bx, y, 0.0], p.triangles)
                                                                   for p in street.bench()]), "Wood"))
                place = SeatPlace((bx - 0.22 + ORIGIN_FROM_BACK_M, y, 0.0), 0.0, 0.47)
                plans.append(Plan(PROFILES["pedestrian"], 1.0, np.array([place.origin] * 2), ("seat", "seat"), 0.0, 0.0,
                                  rests=True, seat=place))
            else:
                p = PROFILES[profile]
                plans.append(Plan(p, p.speed_mps, np.array([(x0 - 2.0, y, 0.0), (x0 + 6.0, y, 0.0)]),
                                  ("sidewalk", "sidewalk"), 0.0, 0.0))
            looks.append(PersonLook(body, skin, shirt, trousers, f"Shoes{(r + k) % 4}", long_sleeves=k % 2 == 0,
                                    long_legs=k != 1))
        cameras.append(CameraSpec(camera, (x0 + 2.6, y0 - 3.4, 1.4), (x0 - 1.6, y0 - 0.2, 0.75), 24.0, 36.0, 20.25,
                                  "three-quarter view of the row"))
    ground = TwinObject("Ground", "sidewalk", tuple(grounds))
    bench = TwinObject("Bench", "furniture", tuple(benches))
    params = CrowdParams(density_per_m2=0.01, time_codes=meta.time_code_count, time_codes_per_second=24.0)
    trajectories, dropped = simulate(plans, params.time_codes, params.time_codes_per_second)
    if dropped:
        raise RuntimeError(f"people sheet: {dropped} agents collided")
    twin = TwinModel(objects=(ground, bench), materials=subset({"Concrete", "Wood"}), source="synthua people sheet")
    return ScenarioSpec(doc="synthua people sheet", metadata=meta, twin=twin, cameras=tuple(cameras),
                        render_camera=ROWS[0][0], crowd=scripted_crowd(trajectories, looks, params))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "people_sheet.png")
    parser.add_argument("--time-code", type=float, default=12.0)
    parser.add_argument("--width", type=int, default=800)
    parser.add_argument("--height", type=int, default=450)
    parser.add_argument("--spp", type=int, default=32)
    args = parser.parse_args()

    from synthua_usd.assets.bodies import load_bank
    from synthua_usd.pipeline.contact_sheet import SheetRequest, make_contact_sheet
    from synthua_usd.usd.scenario_writer import write_scenario

    bank = load_bank()
    for camera, agents in ROWS:
        print(camera + ": " + "; ".join(
            f"{profile} body {b} ({bank.years[b]:.0f} y, {'F' if bank.female[b] else 'M'}, {bank.height_m[b]:.2f} m, "
            f"BMI {bank.mass_kg[b] / bank.height_m[b] ** 2:.0f})" for profile, b, *_ in agents))
    with tempfile.TemporaryDirectory() as tmp:
        write_scenario(people_scenario(), tmp)
        run = make_contact_sheet(SheetRequest(stage_path=Path(tmp) / "scenario.usda", out_path=args.out,
                                              time_code=args.time_code, conditions=("clear_day",), width=args.width,
                                              height=args.height, spp=args.spp))
    print(f"wrote {run.path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
