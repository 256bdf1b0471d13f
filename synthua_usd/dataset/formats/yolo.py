"""YOLO segmentation labels (Ultralytics convention): ``labels/{split}/{name}.txt`` beside
``images/{split}/{name}.png``, and ``data.yaml``.

One line per instance: ``index x1 y1 x2 y2 ...``, the class's 0-based index and the outline polygon in
coordinates normalised by the image's width and height. The polygon runs along **pixel edges** (its
vertices are pixel corners), so its bounding box is exactly the COCO pixel-edge box of the mask: a reader
that boxes the polygon (Ultralytics' ``segments2boxes``, supervision's ``polygon_to_xyxy``) gets ``x, y,
x + w, y + h`` up to the float rounding of normalisation.

Only outer outlines are written (a YOLO polygon has no holes; holes do not change the box). A mask in
several parts (an occluded person split in two) becomes **one** line, the parts joined the way Ultralytics'
``merge_multi_segment`` does: each part is linked to the next at their closest vertices by a bridge that
the outline walks out and back, so the bridge adds no area and the box is the union of the parts' boxes.
"""

from __future__ import annotations

import json
from typing import Iterable, Sequence

import numpy as np
from pycocotools import mask as mask_utils

from synthua_usd.dataset.layout import SPLITS
from synthua_usd.errors import InputError
from synthua_usd.taxonomy import ClassMap

#: Decimals of normalised coordinates: 1e-9 of the image size, far below a pixel at any resolution.
DECIMALS = 9


def class_index(class_map: ClassMap, class_ids: Iterable[int] | None = None) -> dict[int, int]:
    """Class id -> 0-based YOLO index. By default the thing classes with id >= 1 (what COCO instances
    annotates too), in class-id order; ``class_ids`` picks another set."""
    chosen = ([c.id for c in class_map.classes if c.isthing and c.id >= 1] if class_ids is None
              else sorted({int(i) for i in class_ids}))
    known = {c.id for c in class_map.classes}
    unknown = [i for i in chosen if i not in known]
    if unknown:
        raise InputError(f"YOLO classes: ids {unknown[:5]} are not in class map {class_map.source}; expected ids of "
                         f"its classes")
    return {cid: k for k, cid in enumerate(chosen)}


def data_yaml(class_map: ClassMap, index: dict[int, int] | None = None, path: str | None = None,
              splits: Sequence[str] = SPLITS) -> str:
    """Text of ``data.yaml``.

    Parameters
    ----------
    class_map : the dataset's classes
    index : class id -> YOLO index (default :func:`class_index`, the thing classes)
    path : the dataset root to write as ``path``. Default: left out, and Ultralytics then takes the folder
        of ``data.yaml`` itself (a relative ``path`` would be resolved against Ultralytics' own datasets
        folder, and an absolute one would make the file differ between two output folders).
    splits : the splits to list, each as ``images/{split}``
    """
    index = class_index(class_map) if index is None else index
    names = {k: class_map.by_id(cid).name for cid, k in index.items()}
    lines = ["# YOLO dataset (Ultralytics convention), written by synthua-usd"]
    if path is not None:
        lines.append(f"path: {json.dumps(str(path))}")
    lines += [f"{split}: images/{split}" for split in splits]
    lines.append(f"nc: {len(names)}")
    lines.append("names:")
    lines += [f"  {k}: {json.dumps(names[k])}" for k in sorted(names)]
    return "\n".join(lines) + "\n"


def outer_outlines(mask: np.ndarray) -> list[np.ndarray]:
    """Outer outlines of an (H, W) bool mask along pixel edges.

    Returns
    -------
    list of (n, 2) int64 polygons of pixel-corner coordinates (x, y), one per 8-connected part, clockwise on
    screen, corners only (no collinear vertices), in order of each part's first pixel in raster order.
    """
    m = np.pad(np.asarray(mask, bool), 1)
    inside = m[1:-1, 1:-1]
    rows, cols = np.nonzero(inside)
    # A directed edge per pixel side facing outside; interior on the right of travel (y down).
    sides = [  # neighbour offset, start corner, end corner
        ((-1, 0), (0, 0), (1, 0)),   # top: left to right
        ((0, 1), (1, 0), (1, 1)),    # right: downwards
        ((1, 0), (1, 1), (0, 1)),    # bottom: right to left
        ((0, -1), (0, 1), (0, 0)),   # left: upwards
    ]
    starts, ends = [], []
    for (dr, dc), (sx, sy), (ex, ey) in sides:
        open_side = ~m[1 + rows + dr, 1 + cols + dc]
        r, c = rows[open_side], cols[open_side]
        starts.append(np.stack([c + sx, r + sy], axis=1))
        ends.append(np.stack([c + ex, r + ey], axis=1))
    start = np.concatenate(starts)
    end = np.concatenate(ends)
    outgoing: dict[tuple[int, int], list[int]] = {}
    for e, (x, y) in enumerate(start.tolist()):
        outgoing.setdefault((x, y), []).append(e)
    used = np.zeros(len(start), bool)
    end_list, start_list = end.tolist(), start.tolist()
    loops = []
    # Raster order of first edges keeps the output deterministic and in order of the parts' first pixels.
    for first in np.lexsort((start[:, 0], start[:, 1])).tolist():
        if used[first]:
            continue
        loop, e = [], first
        while not used[e]:
            used[e] = True
            loop.append(start_list[e])
            x, y = end_list[e]
            options = [o for o in outgoing[(x, y)] if not used[o]]
            if not options:
                break
            if len(options) > 1:  # a pinch corner: turn left, which keeps diagonal pixels of a part together
                dx, dy = x - start_list[e][0], y - start_list[e][1]
                left = (dy, -dx)
                options = [o for o in options
                           if (end_list[o][0] - x, end_list[o][1] - y) == left] or options
            e = options[0]
        poly = np.array(loop, np.int64)
        twice_area = np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
        if twice_area > 0:  # clockwise on screen: an outer outline; holes run the other way
            loops.append(_corners(poly))
    return loops


def _corners(poly: np.ndarray) -> np.ndarray:
    """The vertices of a closed axis-aligned polygon where the direction changes."""
    prev = np.roll(poly, 1, axis=0)
    nxt = np.roll(poly, -1, axis=0)
    d_in, d_out = poly - prev, nxt - poly
    turn = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    return poly[turn != 0]


def merge_parts(parts: Sequence[np.ndarray]) -> np.ndarray:
    """One polygon through all ``parts``: part i+1 hangs off part i by a bridge between their closest
    vertices, walked out and back (Ultralytics' ``merge_multi_segment`` idea). Returns (n, 2), not closed."""
    if len(parts) == 1:
        return parts[0]
    links = []  # (vertex in part i, vertex in part i+1)
    for a, b in zip(parts, parts[1:]):
        d = ((a[:, None, :] - b[None, :, :]) ** 2).sum(-1)
        i, j = np.unravel_index(int(np.argmin(d)), d.shape)
        links.append((int(i), int(j)))

    def walk(k: int, entry: int) -> list[np.ndarray]:
        part = parts[k]
        loop = [part[(entry + s) % len(part)] for s in range(len(part) + 1)]  # closed, from entry to entry
        if k == len(parts) - 1:
            return loop
        exit_at = (links[k][0] - entry) % len(part)
        return loop[:exit_at + 1] + walk(k + 1, links[k][1]) + loop[exit_at:]

    return np.array(walk(0, 0)[:-1])


def instance_polygon(rle: dict) -> np.ndarray:
    """The single YOLO polygon (n, 2) int64 pixel-corner coordinates of a COCO RLE mask."""
    mask = mask_utils.decode(rle).astype(bool)
    # Outline the mask's bounding box only (the RLE's own box, no scan): the same outlines, offset back,
    # without scanning the whole image per instance (0.8 s an image for 222 instances at 1280x960).
    x, y, w, h = (int(round(v)) for v in mask_utils.toBbox(rle))
    parts = outer_outlines(mask[y:y + h, x:x + w])
    if not parts:
        raise InputError(f"YOLO polygon: empty mask of size {rle.get('size')}; expected at least one pixel")
    return merge_parts([part + np.array([x, y], np.int64) for part in parts])


def yolo_lines(record_instances: Sequence[dict], width: int, height: int, class_index: dict[int, int]) -> str:
    """The label file's text for one image: one line per instance whose class is in ``class_index``.

    Parameters
    ----------
    record_instances : the record's ``instances`` entries (``category_id``, ``segmentation`` RLE)
    width, height : image size in pixels
    class_index : class id -> 0-based YOLO index (:func:`class_index`)
    """
    lines = []
    for inst in record_instances:
        k = class_index.get(inst["category_id"])
        if k is None:
            continue
        if list(inst["segmentation"]["size"]) != [height, width]:
            raise InputError(f"instance {inst.get('id')}: mask size {inst['segmentation']['size']}; "
                             f"expected [{height}, {width}]")
        poly = instance_polygon(inst["segmentation"]).astype(np.float64) / np.array([width, height], np.float64)
        coords = " ".join(f"{v:.{DECIMALS}f}".rstrip("0").rstrip(".") for v in poly.reshape(-1))
        lines.append(f"{k} {coords}")
    return "".join(line + "\n" for line in lines)
