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

from synthua_usd.core.errors import InputError
from synthua_usd.dataset.layout import SPLITS
from synthua_usd.dataset.record import InstanceEntry
from synthua_usd.model.taxonomy import ClassMap

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
    return label_outlines(np.asarray(mask, bool).astype(np.uint8)).get(1, [])


def label_outlines(labels: np.ndarray, wanted: Sequence[int] | None = None) -> dict[int, list[np.ndarray]]:
    """:func:`outer_outlines` of the mask of each nonzero value of an (H, W) integer map (each of ``wanted``
    only, when given), all in one pass over the map: value -> its outlines, for every value present."""
    labels = np.asarray(labels)
    m = np.pad(labels, 1)
    inside = m[1:-1, 1:-1]
    if wanted is None:
        rows, cols = np.nonzero(inside)
    else:
        chosen = np.zeros(int(labels.max(initial=0)) + 1, bool)
        chosen[[v for v in wanted if 0 < v < chosen.size]] = True
        rows, cols = np.nonzero(chosen[inside])
    value = inside[rows, cols]
    # A directed edge per pixel side facing another value; interior on the right of travel (y down).
    sides = [  # neighbour offset, start corner, end corner
        ((-1, 0), (0, 0), (1, 0)),   # top: left to right
        ((0, 1), (1, 0), (1, 1)),    # right: downwards
        ((1, 0), (1, 1), (0, 1)),    # bottom: right to left
        ((0, -1), (0, 1), (0, 0)),   # left: upwards
    ]
    starts, ends, owners = [], [], []
    for (dr, dc), (sx, sy), (ex, ey) in sides:
        open_side = m[1 + rows + dr, 1 + cols + dc] != value
        r, c = rows[open_side], cols[open_side]
        starts.append(np.stack([c + sx, r + sy], axis=1))
        ends.append(np.stack([c + ex, r + ey], axis=1))
        owners.append(value[open_side].astype(np.int64))
    start, end, owner = np.concatenate(starts), np.concatenate(ends), np.concatenate(owners)
    if not len(start):
        return {}
    # corners are keyed by value too: two masks meeting at a corner do not share it
    row_length, plane = labels.shape[1] + 1, (labels.shape[0] + 1) * (labels.shape[1] + 1)
    following = _next_edges(owner * plane + start[:, 1] * row_length + start[:, 0],
                            owner * plane + end[:, 1] * row_length + end[:, 0], end - start)
    # Each outline starts at its first edge in raster order; a value's outlines follow in that order too,
    # which keeps the output deterministic and in order of the parts' first pixels.
    walk, first = _cycles(following, np.lexsort((start[:, 0], start[:, 1], owner)))
    poly = start[walk]
    last = np.append(first[1:], len(walk)) - 1
    after = np.arange(1, len(walk) + 1)
    after[last] = first
    before = np.arange(-1, len(walk) - 1)
    before[first] = last
    nxt, prev = poly[after], poly[before]
    twice_area = np.add.reduceat(poly[:, 0] * nxt[:, 1] - nxt[:, 0] * poly[:, 1], first)
    d_in, d_out = poly - prev, nxt - poly
    corner = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0] != 0  # where the direction changes
    out: dict[int, list[np.ndarray]] = {}
    for a, b, area, v in zip(first.tolist(), last.tolist(), twice_area.tolist(), owner[walk[first]].tolist()):
        loops = out.setdefault(v, [])
        if area > 0:  # clockwise on screen: an outer outline; holes run the other way
            loops.append(poly[a:b + 1][corner[a:b + 1]])
    return out


def _next_edges(key_start: np.ndarray, key_end: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """The edge an outline takes after each edge (edges given by the keys of their start and end corners
    and their (dx, dy)): the one edge leaving the corner it ends at, or, at a pinch corner (two pixels
    touching diagonally: two edges leave it), the one turning left, which keeps diagonal pixels of a part
    together. Each edge is then the next of exactly one edge, so the outlines are the cycles of this map."""
    by_start = np.argsort(key_start, kind="stable")
    first = np.searchsorted(key_start[by_start], key_end, side="left")
    leaving = np.searchsorted(key_start[by_start], key_end, side="right") - first
    following = by_start[first]
    pinch = np.flatnonzero(leaving > 1)
    if pinch.size:
        left = np.stack([direction[pinch, 1], -direction[pinch, 0]], axis=1)
        second = by_start[first[pinch] + 1]
        second_left = np.all(direction[second] == left, axis=1)
        first_left = np.all(direction[following[pinch]] == left, axis=1)
        following[pinch] = np.where(~first_left & second_left, second, following[pinch])
    return following


def _cycles(following: np.ndarray, order: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cycles of the permutation ``following``, each walked from its edge that comes first in ``order``,
    in that order: (n,) edges, and the (k,) positions where each cycle starts. By pointer jumping (log2 n
    whole-array steps) instead of a step per edge in Python."""
    n = len(following)
    rank = np.empty(n, np.int64)
    rank[order] = np.arange(n)
    lowest, hop, reach = rank, following, 1
    while reach < n:  # lowest: the smallest rank within 2**k edges ahead, then on the whole cycle
        lowest, hop, reach = np.minimum(lowest, lowest[hop]), hop[hop], 2 * reach
    # steps from each edge to its cycle's last edge (the one whose next is the cycle's first)
    is_last = lowest[following] == rank[following]
    ahead = np.where(is_last, 0, 1)
    hop, reach = np.where(is_last, np.arange(n), following), 1
    while reach < n:
        ahead, hop, reach = ahead + ahead[hop], hop[hop], 2 * reach
    walk = np.lexsort((-ahead, lowest))
    return walk, np.flatnonzero(np.diff(lowest[walk], prepend=-1))


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
        loop = part[(entry + np.arange(len(part) + 1)) % len(part)]  # closed, from entry to entry
        if k == len(parts) - 1:
            return [loop]
        exit_at = (links[k][0] - entry) % len(part)
        return [loop[:exit_at + 1]] + walk(k + 1, links[k][1]) + [loop[exit_at:]]

    return np.concatenate(walk(0, 0))[:-1]


def instance_polygon(rle: dict) -> np.ndarray:
    """The single YOLO polygon (n, 2) int64 pixel-corner coordinates of a COCO RLE mask."""
    mask = mask_utils.decode(rle).astype(bool)
    # Outline the mask's bounding box only (the RLE's own box, no scan): the same outlines, offset back,
    # without scanning the whole image per instance (0.8 s an image for 222 instances at 1280x960).
    x, y, w, h = (int(round(v)) for v in mask_utils.toBbox(rle))
    return _polygon(mask[y:y + h, x:x + w], x, y, rle.get("size"))


def _polygon(box_mask: np.ndarray, x: int, y: int, size) -> np.ndarray:
    """The YOLO polygon of a mask given as its part inside its bounding box, whose corner is (x, y)."""
    return _merged(outer_outlines(box_mask), np.array([x, y], np.int64), size)


def _merged(parts: list[np.ndarray], offset: np.ndarray | int, size) -> np.ndarray:
    if not parts:
        raise InputError(f"YOLO polygon: empty mask of size {size}; expected at least one pixel")
    return merge_parts([part + offset for part in parts])


def yolo_lines(record_instances: Sequence[InstanceEntry], width: int, height: int, class_index: dict[int, int],
               instance_ids: np.ndarray | None = None) -> str:
    """The label file's text for one image: one line per instance whose class is in ``class_index`` and that is
    not an ignore region (``ignore`` True: too small to annotate; YOLO has no ignore flag, so no line).

    Parameters
    ----------
    record_instances : the record's ``instances`` entries (``category_id``, ``segmentation`` RLE; with
        ``instance_ids``, ``id``)
    width, height : image size in pixels
    class_index : class id -> 0-based YOLO index (:func:`class_index`)
    instance_ids : (H, W) the instance map the entries were made from
        (:func:`synthua_usd.dataset.annotations.annotate`, whose segmentation of an entry is exactly
        ``instance_ids == id``): the outlines are then traced on it, all instances in one pass
        (:func:`label_outlines`), instead of decoding each full-size RLE
    """
    # normalised coordinates are k / width and k / height for pixel corners k: each is formatted once
    columns, rows = ([f"{v:.{DECIMALS}f}".rstrip("0").rstrip(".") for v in (np.arange(n + 1) / np.float64(n)).tolist()]
                     for n in (width, height))
    chosen = [inst for inst in record_instances if inst["category_id"] in class_index and not inst["ignore"]]
    for inst in chosen:
        if list(inst["segmentation"]["size"]) != [height, width]:
            raise InputError(f"instance {inst['id']}: mask size {inst['segmentation']['size']}; "
                             f"expected [{height}, {width}]")
    outlines = None if instance_ids is None else label_outlines(instance_ids, [inst["id"] for inst in chosen])
    lines = []
    for inst in chosen:
        k = class_index[inst["category_id"]]
        if outlines is None:
            poly = instance_polygon(inst["segmentation"])
        else:
            poly = _merged(outlines.get(inst["id"], []), 0, inst["segmentation"]["size"])
        coords = " ".join(f"{columns[px]} {rows[py]}" for px, py in poly.tolist())
        lines.append(f"{k} {coords}")
    return "".join(line + "\n" for line in lines)


def box_lines(boxes: Sequence[tuple[int, float, float, float, float]], width: int, height: int,
              class_index: dict[int, int]) -> str:
    """A detection label file's text: one line ``index cx cy w h`` (normalised by the image's ``width`` and
    ``height``) per box ``(class id, x, y, w, h)`` (pixels, pixel edges) whose class is in ``class_index``, in the
    order given. What a composite's boxes under a box convention are written as (they are boxes, not masks)."""
    def text(v: float) -> str:
        return f"{v:.{DECIMALS}f}".rstrip("0").rstrip(".")

    return "".join(f"{class_index[c]} {text((x + w / 2) / width)} {text((y + h / 2) / height)} {text(w / width)} "
                   f"{text(h / height)}\n" for c, x, y, w, h in boxes if c in class_index)
