#!/usr/bin/env python
"""The paste probe's control: real instances of one class, cut from labelled photos by their boxes, pasted into other
photos of the same set. A detector that finds these pastes as often as the photos' own instances finds real objects
whatever their new surroundings, so a probe that misses the renders' pastes (`synthua evaluate-real --boxes pasted`)
measures how the renders look, not that they were pasted.

Usage: python tools/paste_control.py PHOTOS --class wheelchair --out CONTROL [--split test] [--seed 0]

PHOTOS: a labelled set (Ultralytics YOLO folder or COCO instances .json), read in place, each photo at least 32x32
pixels. Each image gets one donor: a box of --class from another image (not ignored, at least 40x60 pixels, under
98 % of its image's height), cut as a rectangle with its own surroundings, scaled to the donor's share of its image's
height times U(0.7, 1) (at most 90 % of the height and width), placed with its bottom edge in the frame's lower 45 %
where it covers the photo's boxes least (the best of 20 draws), its edge feathered over 4 pixels. Photos are read as
`synthua composite` reads them (8-bit RGB, 16-bit scaled; a grey photo's control image made grey).

CONTROL (a new folder) gets images/ (PNG), control.json (the seed, the set read and each paste: background, donor
image, donor box, paste box) and two COCO instances files for `synthua evaluate-real`, the other group as crowd
regions of every class (neither found nor missed, as `--boxes` does for a composite):
  pasted.json  the pastes scored; the photo's boxes, and any other box of the donor its cut reaches, crowd regions;
  photo.json   the photo's boxes scored (ignored ones crowd regions of their class); the paste, and any photo box
               it covers more than half, crowd regions.

Example (the probe's control of docs/statistics.md, on the photos that no model of the 50 saw):
  python tools/paste_control.py out/s2r_45/held_back --class wheelchair --out out/control
  synthua evaluate-real out/s2r_45/runs/b_n0050_s7 out/control/pasted.json --map wheelchair=wheelchair --out out/c7p
  synthua evaluate-real out/s2r_45/runs/b_n0050_s7 out/control/photo.json --map wheelchair=wheelchair --out out/c7o
Never publish a control made of photos whose licence does not allow it.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from synthua_usd.analytics.detection_sets import Box, DetectionSet  # noqa: E402
from synthua_usd.analytics.detection_sources import read_detection_set  # noqa: E402
from synthua_usd.cli.failures import tool_main  # noqa: E402
from synthua_usd.core.atomic import output_set  # noqa: E402
from synthua_usd.core.errors import InputError  # noqa: E402

MIN_W, MIN_H = 40, 60          # a donor box big enough to show what it is, pixels
MIN_SIDE = 32                  # the smallest photo pasted into, pixels
LOW_SHARE = 0.55               # a paste's bottom edge lies below this share of the frame height
MAX_SHARE = 0.9                # a paste's most of the frame's height and width
FEATHER_PX = 4                 # the paste's edge blends over this many pixels
COVERED = 0.5                  # a photo box more than this share covered by the paste is ignored
EPS = 1e-6                     # a YOLO box's pixel edge read back as 9.9999999 is pixel 10
TRIES = 20                     # placements drawn; the one covering the photo's boxes least is kept


@dataclass(frozen=True)
class Paste:
    """One image's paste: the donor image's index in the set and its box, where the crop lands (x, y, w, h)."""

    donor: int
    source: Box
    x: int
    y: int
    w: int
    h: int


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line and exit 2 (main), the house's way
        raise InputError(f"{message}; expected the options of `python tools/paste_control.py --help`")


def donors(photos: DetectionSet, label: str) -> list[tuple[int, Box]]:
    """(image index, box) of every box of ``label`` fit to paste: scored, at least MIN_W x MIN_H, under 98 % of its
    image's height (a box as tall as its frame is cut off, not a whole instance)."""
    return [(i, b) for i, im in enumerate(photos.images) for b in im.boxes
            if b.label == label and not b.ignore and b.w >= MIN_W and b.h >= MIN_H and b.h < 0.98 * im.height]


def cover(box: Box, x: float, y: float, w: float, h: float) -> float:
    """The share of ``box``'s area inside the rectangle (x, y, w, h)."""
    ix = max(0.0, min(box.x + box.w, x + w) - max(box.x, x))
    iy = max(0.0, min(box.y + box.h, y + h) - max(box.y, y))
    return ix * iy / max(box.area, 1e-9)


def crop_box(box: Box) -> tuple[int, int, int, int]:
    """(x0, y0, x1, y1): the pixels a donor box is cut as, its edges rounded outwards."""
    return (math.floor(box.x + EPS), math.floor(box.y + EPS), math.ceil(box.x + box.w - EPS),
            math.ceil(box.y + box.h - EPS))


def plan(photos: DetectionSet, label: str, seed: int) -> list[Paste]:
    """One paste per image, drawn from ``seed`` alone: the same set and seed give the same pastes."""
    for image in photos.images:
        if image.width < MIN_SIDE or image.height < MIN_SIDE:
            raise InputError(f"{image.path}: {image.width}x{image.height} pixels; expected at least "
                             f"{MIN_SIDE}x{MIN_SIDE} to paste into")
    pool = donors(photos, label)
    holding = len({i for i, _ in pool})
    if holding < 2:
        raise InputError(f"{photos.source}: boxes of class {label!r} fit to paste (at least {MIN_W}x{MIN_H} pixels, "
                         f"under 98 % of the image height): {len(pool)}, in {holding} of the images; expected such "
                         f"boxes in two images or more (each image's donor comes from another)")
    rng = np.random.default_rng(seed)
    out = []
    for k, image in enumerate(photos.images):
        while True:
            donor, source = pool[int(rng.integers(len(pool)))]
            if donor != k:
                break
        share = source.h / photos.images[donor].height
        most_w, most_h = int(MAX_SHARE * image.width), int(MAX_SHARE * image.height)
        h = min(max(round(share * image.height * rng.uniform(0.7, 1.0)), 1), most_h)
        w = max(round(source.w * h / source.h), 1)
        if w > most_w:
            w, h = most_w, max(round(source.h * most_w / source.w), 1)
        best = None
        for _ in range(TRIES):
            x = int(rng.integers(0, image.width - w + 1))
            bottom = int(rng.integers(max(h, math.ceil(LOW_SHARE * image.height)), image.height + 1))
            worst = max((cover(b, x, bottom - h, w, h) for b in image.boxes), default=0.0)
            if best is None or worst < best[0]:
                best = (worst, x, bottom - h)
        out.append(Paste(donor, source, best[1], best[2], w, h))
    return out


def feather(w: int, h: int) -> np.ndarray:
    """The paste's alpha, (h, w) in (0, 1]: 1 inside, falling linearly over the FEATHER_PX pixels of each edge
    (pixel centres: 0.875, 0.625, 0.375 and 0.125 at the outermost)."""
    ramp = lambda n: np.clip((np.minimum(np.arange(n), np.arange(n)[::-1]) + 0.5) / FEATHER_PX, 0, 1)  # noqa: E731
    return np.minimum(ramp(h)[:, None], ramp(w)[None, :])


def composite(photos: DetectionSet, k: int, paste: Paste) -> np.ndarray:
    """Image ``k`` with its paste, uint8 RGB: both photos read as `synthua composite` reads one (8-bit RGB, 16-bit
    scaled), the donor's :func:`crop_box` resized by PIL's bilinear filter and blended by :func:`feather`; made
    grey where the photo is grey, as a composite into it is."""
    from PIL import Image

    from synthua_usd.backends.photos import read_photo, to_monochrome

    photo = read_photo(photos.images[k].path, None)
    base = photo.pixels.astype(np.float32)
    x0, y0, x1, y1 = crop_box(paste.source)
    crop = Image.fromarray(read_photo(photos.images[paste.donor].path, None).pixels[y0:y1, x0:x1])
    crop_px = np.asarray(crop.resize((paste.w, paste.h), Image.Resampling.BILINEAR)).astype(np.float32)
    alpha = feather(paste.w, paste.h)[..., None]
    site = base[paste.y:paste.y + paste.h, paste.x:paste.x + paste.w]
    base[paste.y:paste.y + paste.h, paste.x:paste.x + paste.w] = alpha * crop_px + (1 - alpha) * site
    made = np.clip(np.round(base), 0, 255).astype(np.uint8)
    return to_monochrome(made) if photo.monochrome else made


def carried(photos: DetectionSet, paste: Paste) -> list[tuple[float, float, float, float]]:
    """(x, y, w, h) in the control image of the donor's other boxes that its cut reaches (a neighbour, a pusher):
    pasted along, labelled by nobody there, so crowd regions of every class where the pastes are scored."""
    x0, y0, x1, y1 = crop_box(paste.source)
    sx, sy = paste.w / (x1 - x0), paste.h / (y1 - y0)
    out = []
    for box in photos.images[paste.donor].boxes:
        if box == paste.source:
            continue
        bx0, by0 = max(box.x, x0), max(box.y, y0)
        bx1, by1 = min(box.x + box.w, x1), min(box.y + box.h, y1)
        if bx1 > bx0 and by1 > by0:
            out.append((paste.x + (bx0 - x0) * sx, paste.y + (by0 - y0) * sy, (bx1 - bx0) * sx, (by1 - by0) * sy))
    return out


def coco(photos: DetectionSet, label: str, pastes: list[Paste], scored: str) -> dict:
    """A COCO instances document of the control's images, ``scored`` "pasted" or "photo". Pasted: each paste scored,
    every photo box and what the paste carried along (:func:`carried`) crowd regions of every class. Photo: the
    photo's boxes scored, an ignored one a crowd region of its class, the paste and any box it covers more than
    COVERED crowd regions of every class."""
    categories = [{"id": n + 1, "name": name} for n, name in enumerate(photos.names)]
    ids = {name: n + 1 for n, name in enumerate(photos.names)}
    images, annotations = [], []

    def add(image_id: int, name: str | None, rect, crowd: bool) -> None:
        x, y, w, h = rect
        for cat in ([ids[name]] if name is not None else list(ids.values())):
            annotations.append({"id": len(annotations) + 1, "image_id": image_id, "category_id": cat,
                                "bbox": [round(v, 3) for v in (x, y, w, h)], "area": round(w * h, 3),
                                "iscrowd": int(crowd)})

    for k, (image, paste) in enumerate(zip(photos.images, pastes), 1):
        images.append({"id": k, "file_name": f"images/{k:06d}.png", "width": image.width, "height": image.height})
        rect = (paste.x, paste.y, paste.w, paste.h)
        if scored == "pasted":
            add(k, label, rect, False)
            for box in image.boxes:
                add(k, None, (box.x, box.y, box.w, box.h), True)
            for along in carried(photos, paste):
                add(k, None, along, True)
            continue
        add(k, None, rect, True)
        for box in image.boxes:
            covered = cover(box, *rect) > COVERED
            add(k, None if covered else box.label, (box.x, box.y, box.w, box.h), covered or box.ignore)
    return {"info": {"description": f"tools/paste_control.py: the {scored} boxes scored, the others crowd regions"},
            "images": images, "annotations": annotations, "categories": categories}


def run(argv: list[str] | None = None) -> int:
    parser = _Parser(prog="tools/paste_control.py", description=__doc__.split("\n\n")[0],
                     formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__.split("\n\n", 1)[1])
    parser.add_argument("photos", type=Path, help="labelled photos: a YOLO folder or a COCO instances .json")
    parser.add_argument("--class", dest="label", required=True, help="the class whose boxes are pasted")
    parser.add_argument("--out", type=Path, required=True,
                        help="a new folder for the control (written whole or not at all)")
    parser.add_argument("--split", help="split of a YOLO set [its data.yaml's test split, else val; a folder without "
                                        "data.yaml: every image]")
    parser.add_argument("--images", type=Path, help="folder of a COCO set's images [the .json's folder]")
    parser.add_argument("--seed", type=int, default=0, help="draws of donors, sizes and places, >= 0 [0]")
    args = parser.parse_args(argv)
    if args.seed < 0:
        raise InputError(f"--seed: {args.seed}; expected a whole number >= 0")
    if args.out.exists():
        raise InputError(f"{args.out}: exists; expected a new folder (a control is written whole, never merged)")
    photos = read_detection_set(args.photos, split=args.split, images_dir=args.images)
    if photos.layout == "synthua":
        raise InputError(f"{args.photos}: a dataset synthua wrote; expected real labelled photos (YOLO or COCO)")
    if args.label not in photos.names:
        raise InputError(f"--class: {args.label!r}; expected a class of {args.photos}: {', '.join(photos.names)}")
    pastes = plan(photos, args.label, args.seed)
    from PIL import Image
    from tqdm import tqdm

    with output_set(args.out) as stage:
        (stage / "images").mkdir()
        for k, paste in enumerate(tqdm(pastes, desc="paste_control", unit="image", disable=not sys.stderr.isatty())):
            Image.fromarray(composite(photos, k, paste)).save(stage / "images" / f"{k + 1:06d}.png")
        for scored in ("pasted", "photo"):
            (stage / f"{scored}.json").write_text(json.dumps(coco(photos, args.label, pastes, scored)) + "\n")
        record = {"photos": str(args.photos), "layout": photos.layout, "split": photos.split, "class": args.label,
                  "seed": args.seed, "pastes": [{"image": f"images/{k + 1:06d}.png",
                                                 "background": str(photos.images[k].path),
                                                 "donor": str(photos.images[p.donor].path),
                                                 "donor_box": [p.source.x, p.source.y, p.source.w, p.source.h],
                                                 "box": [p.x, p.y, p.w, p.h]} for k, p in enumerate(pastes)]}
        (stage / "control.json").write_text(json.dumps(record, indent=1) + "\n")
    print(f"paste_control: {len(pastes)} images, one {args.label} pasted into each -> {args.out} "
          f"(pasted.json, photo.json)")
    return 0


def main(argv: list[str] | None = None) -> int:
    return tool_main(run, argv)


if __name__ == "__main__":
    sys.exit(main())
