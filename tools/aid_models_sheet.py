#!/usr/bin/env python
"""Contact sheet of every mobility-aid model: per class its standard and its detailed model side by side.

Usage: python tools/aid_models_sheet.py [--out docs/images/aid_models.png] [--width 480 --height 270] [--spp 32]

Writes a small scenario (a concrete ground, the shipped clear-day environment, no people) into a temporary
folder: four rows of four devices (two classes a row, each class's models in :data:`MODELS` order from the
left, fitted to the default :class:`synthua_usd.assets.postures.DeviceFit`), each facing +X, and one camera
per row looking at it three-quarters from the front; then renders it with ``synthua contact-sheet``'s
pipeline (:func:`synthua_usd.pipeline.contact_sheet.make_contact_sheet`): per row, the RGB beside the class
overlay. The triangle count of each model is printed.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

#: Per row: (camera name, its two classes, spacing between the devices and the camera's distance, m).
ROWS = (
    ("Wheelchairs", ("manual_wheelchair", "electric_wheelchair"), 1.1, 5.0),
    ("Walker_crutch", ("walker", "crutch"), 0.75, 3.8),
    ("Smart_wooden", ("smart_cane", "wooden_cane"), 0.3, 2.2),
    ("Orthopedic_tripod", ("orthopedic_cane", "tripod_cane"), 0.3, 2.2),
)
#: The cameras' bearing from the row's centre (degrees from +X) and height above the ground, m.
BEARING_DEG, EYE_Z_M = -35.0, 1.0
MODELS = ("standard", "detailed")
ROW_GAP_M = 40.0


def aid_models_scenario():
    """The scenario spec of the sheet (see the module's docstring)."""
    from synthua_usd.assets import place
    from synthua_usd.assets.devices import DEVICE_MODELS
    from synthua_usd.composition.scenario import ScenarioSpec, StageMetadata
    from synthua_usd.model import meshes as geo
    from synthua_usd.model.cameras import CameraSpec
    from synthua_usd.model.materials import subset
    from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart

    meta = StageMetadata(time_codes_per_second=24.0, start_time_code=1.0, end_time_code=1.0)
    objects, cameras, keys = [], [], {"Concrete"}
    bearing = np.radians(BEARING_DEG)
    for r, (camera, classes, spacing, distance) in enumerate(ROWS):
        x0 = y0 = r * ROW_GAP_M  # rows on a diagonal: no camera sees another row
        ground = TwinPart.of("Mesh", geo.box((x0 - 8.0, y0 - 8.0, -0.2), (x0 + 8.0, y0 + 8.0, 0.0)), "Concrete")
        objects.append(TwinObject(f"Ground{r}", "sidewalk", (ground,)))
        for k, (name, model) in enumerate((c, m) for c in classes for m in MODELS):
            parts = place(DEVICE_MODELS[name][model](), (x0, y0 + (k - 1.5) * spacing, 0.0))
            keys |= {p.material for p in parts}
            objects.append(TwinObject(f"Row{r}/{name.title().replace('_', '')}_{model}", name, tuple(parts)))
        eye = (x0 + distance * np.cos(bearing), y0 + distance * np.sin(bearing), EYE_Z_M)
        cameras.append(CameraSpec(camera, eye, (x0, y0, 0.5), 35.0, 36.0, 20.25, "three-quarter front view of the row"))
    twin = TwinModel(objects=tuple(objects), materials=subset(keys), source="synthua aid models sheet")
    return ScenarioSpec(doc="synthua aid models sheet", metadata=meta, twin=twin, cameras=tuple(cameras),
                        render_camera=ROWS[0][0])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "images" / "aid_models.png")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--spp", type=int, default=32)
    args = parser.parse_args()

    from synthua_usd.assets.devices import DEVICE_MODELS
    from synthua_usd.pipeline.contact_sheet import SheetRequest, make_contact_sheet
    from synthua_usd.usd.scenario_writer import write_scenario

    for name, models in DEVICE_MODELS.items():
        print(name + ": " + ", ".join(f"{m} {sum(len(p.triangles) for p in build())} triangles"
                                      for m, build in sorted(models.items())))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        write_scenario(aid_models_scenario(), tmp)
        run = make_contact_sheet(SheetRequest(stage_path=Path(tmp) / "scenario.usda", out_path=args.out,
                                              time_code=1.0, conditions=("clear_day",), width=args.width,
                                              height=args.height, spp=args.spp))
    print(f"wrote {run.path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
