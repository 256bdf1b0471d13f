#!/usr/bin/env python
"""What height a labelled set's own photos give its wheelchair users, for `synthua composite`'s
`camera.wheelchair_height_m`: in each photo that holds a person box and a wheelchair box whole (the rule of
`camera.person_height_m`: top and bottom edges at least 1 % of the photo's height inside it, at least 16 px tall,
here in the photo's own pixels where a composite counts them after scaling the photo to its output),
the people on foot place the horizon (`synthua_usd.model.photo_camera.horizon_from_people`, standing at
--person-height, the camera at --camera-height), and each whole wheelchair box, read as a chair with its seated user
standing on the same ground, is then p H / (y_b - y_h) metres tall. Printed: the median and quartiles of those
heights, and how far the horizon of the wheelchair boxes alone (at --wheelchair-height) lies from the people's, as a
share of the photo's height (median and quartiles; positive: the wheelchair users' horizon lower).

Usage: python tools/people_heights.py PHOTOS [--split all] [--person person] [--wheelchair wheelchair]
           [--person-height 1.7] [--wheelchair-height 1.35] [--camera-height 1.4]

PHOTOS: a labelled set (Ultralytics YOLO folder or COCO instances .json), read in place; its boxes in the
wheelchair-sets convention (a wheelchair's box covers its seated user, who has no person box).

Example (docs/compositing.md): python tools/people_heights.py ../shared/data/real_photos/wheelchair_dev --split all
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from synthua_usd.analytics.detection_sources import read_detection_set  # noqa: E402
from synthua_usd.cli.failures import tool_main  # noqa: E402
from synthua_usd.core.errors import InputError  # noqa: E402
from synthua_usd.model.photo_camera import horizon_from_people, whole_in_photo  # noqa: E402


def measure(path: Path, split: str, person: str, wheelchair: str, person_m: float, wheelchair_m: float,
            camera_m: float) -> tuple[int, list[float], list[float]]:
    """The photos holding both kinds of box whole, the height each of their whole wheelchair boxes implies (m),
    and per photo (wheelchair users' horizon - people's) / the photo's height."""
    photos, heights, gaps = 0, [], []
    found = read_detection_set(path, split=split)
    for name in (person, wheelchair):
        if name not in found.names:
            raise InputError(f"{path}: no class {name!r}; expected one of {', '.join(found.names)}")
    for image in found.images:
        rows = (0.0, float(image.height))

        def whole(label: str) -> list[tuple[float, float, float, float]]:
            boxes = [(b.x, b.y, b.x + b.w, b.y + b.h) for b in image.boxes if b.label == label and not b.ignore]
            return [b for b in boxes if whole_in_photo(b, rows)]

        people, chairs = whole(person), whole(wheelchair)
        if not people or not chairs:
            continue
        photos += 1
        horizon = horizon_from_people([(b, person_m) for b in people], rows, camera_m)
        seated = horizon_from_people([(b, wheelchair_m) for b in chairs], rows, camera_m)
        assert horizon is not None and seated is not None   # whole boxes, each placing a row
        gaps.append((seated[0] - horizon[0]) / image.height)
        heights += [(y1 - y0) * camera_m / (y1 - horizon[0]) for _, y0, _, y1 in chairs if y1 - horizon[0] > 1.0]
    return photos, heights, gaps


def run(argv: list[str] | None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("photos", type=Path, metavar="PHOTOS", help="a labelled YOLO folder or COCO .json")
    p.add_argument("--split", default="all", help="of a YOLO set [all]")
    p.add_argument("--person", default="person", help="the class of people on foot [person]")
    p.add_argument("--wheelchair", default="wheelchair", help="the class of wheelchairs with their users [wheelchair]")
    p.add_argument("--person-height", type=float, default=1.7, help="metres, as camera.person_height_m [1.7]")
    p.add_argument("--wheelchair-height", type=float, default=1.35,
                   help="metres, as camera.wheelchair_height_m, for the horizons' gap [1.35]")
    p.add_argument("--camera-height", type=float, default=1.4, help="metres, the middle of the default range [1.4]")
    a = p.parse_args(argv)
    for name in ("person_height", "wheelchair_height", "camera_height"):
        if not 0.1 <= getattr(a, name) <= 100:
            raise InputError(f"--{name.replace('_', '-')}: {getattr(a, name)}; expected metres in [0.1, 100]")
    photos, heights, gaps = measure(a.photos, a.split, a.person, a.wheelchair, a.person_height, a.wheelchair_height,
                                    a.camera_height)
    if not heights:
        raise InputError(f"{a.photos}: no photo holds a {a.person} box and a {a.wheelchair} box whole; expected some")
    q = np.percentile(heights, [25, 50, 75])
    g = np.percentile(gaps, [25, 50, 75]) * 100
    print(f"{photos} photos hold both whole; their {len(heights)} wheelchair boxes are {q[1]:.3f} m tall "
          f"(quartiles {q[0]:.3f} and {q[2]:.3f}) beside people on foot of {a.person_height} m")
    print(f"the horizon of the wheelchair boxes at {a.wheelchair_height} m lies {g[1]:+.1f} % of the photo's height "
          f"from the people's (quartiles {g[0]:+.1f} and {g[2]:+.1f} %)")
    return 0


def main(argv: list[str] | None = None) -> int:
    return tool_main(run, argv)


if __name__ == "__main__":
    sys.exit(main())
