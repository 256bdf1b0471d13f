"""Per-image annotations from label maps: the record's ``instances`` and ``panoptic_segments`` entries.

Plain data only (numpy, scipy.ndimage and pycocotools): the renderer hands over a class-id map, an
instance-id map, the scene's instances and, per instance, the flat pixel indices of its amodal (unoccluded)
mask; everything a format writes is computed here once, exactly, from those arrays.

Conventions shared with every format:

* a visible mask is ``instance_ids == instance.id``;
* boxes are COCO's pixel-edge ``[x, y, w, h]`` ints: ``x`` the smallest column, ``w = max column - x + 1``
  (what ``pycocotools.mask.toBbox`` gives for the same mask);
* masks are stored as COCO compressed RLE (``pycocotools.mask.encode`` of a Fortran-ordered uint8 array;
  ``counts`` as an ASCII ``str`` so that the record is JSON);
* panoptic segment ids: a thing instance keeps its instance id (< 2**16); a stuff class is one segment
  ``STUFF_ID_BASE + class id``; class 0 (unlabelled) is void (0), as panopticapi expects.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
from pycocotools import mask as mask_utils
from scipy import ndimage

from synthua_usd.core.errors import InputError
from synthua_usd.dataset.record import InstanceEntry, PanopticSegment
from synthua_usd.model.scene import Instance
from synthua_usd.model.taxonomy import ClassMap

#: Panoptic segment id of stuff class ``c`` is ``STUFF_ID_BASE + c``: above every uint16 instance id, far
#: below panopticapi's 2**24 limit of an RGB-encoded id.
STUFF_ID_BASE = 65536
#: The crowd segment of thing class ``c`` in an image (its instances too small to annotate, merged, as COCO
#: panoptic has one crowd region per category and image) is ``CROWD_ID_BASE + c``.
CROWD_ID_BASE = 2 * STUFF_ID_BASE


def label_extents(labels: np.ndarray) -> tuple[np.ndarray, list]:
    """Pixel count and box of every value of ``labels``, in one pass over the map.

    Parameters
    ----------
    labels : (H, W) non-negative integer array

    Returns
    -------
    counts : (max + 1,) int64, pixels of each value (0 included)
    boxes : list, item ``v - 1`` the (rows, cols) slices of value ``v``'s bounding box, None for an absent
        value (``scipy.ndimage.find_objects``; value 0 has no item)
    """
    counts = np.bincount(labels.reshape(-1))
    return counts, ndimage.find_objects(labels) if counts.size > 1 else []


def box_xywh(box: tuple[slice, slice]) -> list[int]:
    """COCO pixel-edge ``[x, y, w, h]`` (ints) of a (rows, cols) slice pair."""
    rows, cols = box
    return [int(cols.start), int(rows.start), int(cols.stop - cols.start), int(rows.stop - rows.start)]


def column_runs(labels: np.ndarray) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """The runs of each value of ``labels`` in column-major order (COCO RLE's order).

    Returns
    -------
    dict from value to ``(starts, lengths)``: (k,) int64 column-major flat index of each maximal run of the
    value and its length, in increasing order; every value present (0 included).
    """
    flat = np.ascontiguousarray(labels.T).reshape(-1)
    if not flat.size:
        return {}
    starts = np.concatenate([[0], np.flatnonzero(flat[1:] != flat[:-1]) + 1])
    lengths = np.diff(np.append(starts, flat.size))
    values = flat[starts]
    order = np.argsort(values, kind="stable")
    sorted_values = values[order]
    cut = np.flatnonzero(np.diff(sorted_values)) + 1
    return {int(values[group[0]]): (starts[group], lengths[group])
            for group in np.split(order, cut) if group.size}


def rle_from_runs(starts: np.ndarray, lengths: np.ndarray, shape: tuple[int, int]) -> dict:
    """COCO compressed RLE ``{"size": [H, W], "counts": str}`` of the mask made of the column-major runs
    ``starts`` (increasing, separated by at least one pixel) and ``lengths``: the run-length counts
    ``pycocotools.mask.encode`` would find (zeros first, a leading 0 when the mask starts with a pixel, no
    trailing 0), compressed by pycocotools itself (``frPyObjects`` of the uncompressed counts)."""
    h, w = shape
    ends = starts + lengths
    counts = np.empty(2 * starts.size + 1, np.int64)
    counts[0:-1:2] = starts - np.concatenate([[0], ends[:-1]])
    counts[1::2] = lengths
    counts[-1] = h * w - (ends[-1] if ends.size else 0)
    if ends.size and counts[-1] == 0:
        counts = counts[:-1]
    rle = mask_utils.frPyObjects({"size": [h, w], "counts": counts}, h, w)
    return {"size": [int(rle["size"][0]), int(rle["size"][1])], "counts": rle["counts"].decode("ascii")}


def rle_problem(rle, shape: tuple[int, int]) -> str | None:
    """Why ``rle`` is not a COCO compressed RLE mask of ``shape`` (H, W), or None when it is one.

    pycocotools decodes ``counts`` without checking it: characters outside '0'..'o', a last character that
    announces more, a negative run or runs that do not add up to H x W pixels make it read past the string or
    write past the mask. So the string is decoded here first, as pycocotools' ``rleFrString`` does (5 bits a
    character, 0x20 continues, 0x10 the sign of the last; from the third count on, a delta from the count
    two before)."""
    h, w = shape
    if not isinstance(rle, dict) or rle.get("size") != [h, w]:
        return f"{str(rle)[:80]} is not {{'size': [{h}, {w}], 'counts': ...}}, an RLE mask of its image's size"
    text = rle.get("counts")
    if not isinstance(text, str):
        return f"counts is {type(text).__name__}; expected pycocotools' compressed counts (a string)"
    counts: list[int] = []
    x = k = 0
    for p, char in enumerate(text):
        c = ord(char) - 48
        if not 0 <= c < 64:
            return f"counts[{p}] is {char!r}; expected characters '0' to 'o' (compressed counts)"
        x |= (c & 0x1F) << (5 * k)
        k += 1
        if c & 0x20:
            continue
        if c & 0x10:
            x -= 1 << (5 * k)
        if len(counts) > 2:
            x += counts[-2]
        if x < 0:
            return f"counts decode to a negative run ({x}) at character {p}; expected run lengths >= 0"
        counts.append(x)
        x = k = 0
    if k:
        return "counts end inside a run length (the last character continues); expected complete counts"
    if sum(counts) != h * w:
        return f"counts decode to runs of {sum(counts)} pixels in all; expected {h} x {w} = {h * w}"
    return None


def runs_of_indices(column_major: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(starts, lengths)`` of the maximal runs of sorted, unique column-major flat indices."""
    if not column_major.size:
        return column_major, column_major
    cut = np.flatnonzero(np.diff(column_major) != 1) + 1
    starts = column_major[np.concatenate([[0], cut])]
    lengths = np.diff(np.concatenate([[0], cut, [column_major.size]]))
    return starts, lengths


def indices_of_runs(starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Every flat index the runs cover, in order."""
    total = int(lengths.sum())
    return np.arange(total) + np.repeat(starts - (np.cumsum(lengths) - lengths), lengths)


def instance_class_table(instances: Sequence[Instance], size: int) -> np.ndarray:
    """(size,) int32: the class id of each instance id below ``size``, -1 for ids with no instance."""
    table = np.full(size, -1, np.int32)
    for inst in instances:
        if 0 <= inst.id < size:
            table[inst.id] = inst.class_id
    return table


def annotate(class_ids: np.ndarray, instance_ids: np.ndarray, instances: Sequence[Instance],
             amodal: dict[int, np.ndarray] | None = None,
             truncation: dict[int, float] | None = None) -> list[InstanceEntry]:
    """The record's ``instances`` entries: one per instance with at least one visible pixel, in the order
    of ``instances``.

    Parameters
    ----------
    class_ids : (H, W) uint8, class id per pixel (0 unlabelled)
    instance_ids : (H, W) uint16, instance id per pixel (0 none)
    instances : the scene's instances; every nonzero id of ``instance_ids`` must be among them
    amodal : instance id -> sorted flat indices (row-major, ``y * W + x``) of the instance's unoccluded
        pixels inside the frame. The amodal mask is this set united with the visible pixels (a ray
        machinery that misses a visible pixel must not make the amodal mask smaller than the visible one).
        ``None``, or an instance missing from it: amodal = visible.
    truncation : instance id -> share 0..1 of the instance cut off by the frame (default 0)

    Returns
    -------
    list of dicts with keys id, category_id, class_name, isthing, prim_path, area, bbox, segmentation,
    amodal_area, amodal_bbox, amodal_segmentation, occlusion (1 - area / amodal_area), truncation,
    relations (:func:`relation_entries`).

    The whole map is read a few times (counts and boxes, column-major runs, one class check), never once
    per instance: a full-size mask per instance cost more than a second an image for 230 instances at
    1280x960.
    """
    shape = _check_maps(class_ids, instance_ids)
    height, width = shape
    by_id = {inst.id: inst for inst in instances}
    counts, boxes = label_extents(instance_ids)
    present = np.flatnonzero(counts).tolist()
    unknown = sorted(set(present) - set(by_id) - {0})
    if unknown:
        raise InputError(f"instance map: ids {unknown[:5]} have no instance; expected every nonzero id to be "
                         f"one of the scene's {len(by_id)} instances")
    classes = instance_class_table(instances, counts.size)
    wrong_class = (class_ids != classes[instance_ids]) & (instance_ids != 0)
    mixed = set(np.unique(instance_ids[wrong_class]).tolist()) if wrong_class.any() else set()
    runs = column_runs(instance_ids)
    class_of = {inst.prim_path: inst.class_name for inst in instances}
    out = []
    for inst in instances:
        if not 0 < inst.id < counts.size or not counts[inst.id]:
            continue
        if inst.id in mixed:
            found = np.unique(class_ids[instance_ids == inst.id])
            raise InputError(f"instance {inst.id} ({inst.prim_path}): class ids {found.tolist()[:5]} under its "
                             f"pixels; expected only its class {inst.class_id}")
        starts, lengths = runs[inst.id]
        area, bbox = int(counts[inst.id]), box_xywh(boxes[inst.id - 1])
        segmentation = rle_from_runs(starts, lengths, shape)
        amodal_area, amodal_bbox, amodal_segmentation = area, list(bbox), dict(segmentation)
        if amodal is not None and inst.id in amodal:
            given = np.asarray(amodal[inst.id], np.int64).reshape(-1)
            if given.size and (given.min() < 0 or given.max() >= height * width):
                raise InputError(f"amodal pixels of instance {inst.id}: indices {int(given.min())}..{int(given.max())}; "
                                 f"expected flat indices in 0..{height * width - 1}")
            rows, cols = np.divmod(given, width)
            given = np.sort(cols * height + rows)
            # both sorted: a stable sort of the two merges them in one pass
            united = np.sort(np.concatenate([given, indices_of_runs(starts, lengths)]), kind="stable")
            united = united[np.concatenate([[True], united[1:] != united[:-1]])]
            cols, rows = np.divmod(united, height)
            x0, y0 = int(cols.min()), int(rows.min())
            amodal_area = int(united.size)
            amodal_bbox = [x0, y0, int(cols.max()) - x0 + 1, int(rows.max()) - y0 + 1]
            amodal_segmentation = rle_from_runs(*runs_of_indices(united), shape)
        trunc = 0.0 if truncation is None else float(truncation.get(inst.id, 0.0))
        if not 0.0 <= trunc <= 1.0:
            raise InputError(f"truncation of instance {inst.id}: {trunc}; expected a share in 0..1")
        out.append(InstanceEntry(
            id=inst.id, category_id=inst.class_id, class_name=inst.class_name,
            isthing=bool(inst.isthing), prim_path=inst.prim_path,
            area=area, bbox=bbox, segmentation=segmentation,
            amodal_area=amodal_area, amodal_bbox=amodal_bbox, amodal_segmentation=amodal_segmentation,
            occlusion=1.0 - area / amodal_area, truncation=trunc,
            relations=relation_entries(inst.relations, class_of),
        ))
    return out


def relation_entries(relations, class_of: dict[str, str]) -> dict[str, str]:
    """An instance's ``synthua:*`` relations ((name, target prim path) pairs) as a record holds them: ``name`` ->
    the target's path, and ``name_class`` -> the target's class where ``class_of`` (labelled prim path -> class
    name, in view or not) has it: the class of what a person uses or pushes, of the person it accompanies."""
    out = {name: target for name, target in relations}
    for name, target in relations:
        if target in class_of:
            out[f"{name}_class"] = class_of[target]
    return out


def panoptic_ids(class_ids: np.ndarray, instance_ids: np.ndarray, class_map: ClassMap,
                 ignored: set[int] = frozenset()) -> np.ndarray:
    """(H, W) uint32 panoptic segment id per pixel: instance id on thing-class pixels with an instance,
    ``CROWD_ID_BASE + class`` instead on those of an ``ignored`` instance, ``STUFF_ID_BASE + class`` on
    stuff-class pixels, 0 (void) on class 0 and on thing pixels without an instance."""
    _check_maps(class_ids, instance_ids)
    thing = np.zeros(256, bool)
    known = np.zeros(256, bool)
    for c in class_map.classes:
        known[c.id] = True
        thing[c.id] = c.isthing
    present = np.flatnonzero(np.bincount(class_ids.reshape(-1), minlength=256))
    missing = [int(c) for c in present if c != 0 and not known[c]]
    if missing:
        raise InputError(f"class-id map: class ids {missing[:5]} are not in class map {class_map.source}; "
                         f"expected every labelled pixel's class in the class map")
    cls = class_ids.astype(np.uint32)
    is_thing = thing[class_ids]
    stuff = (cls != 0) & ~is_thing
    ids = np.where(is_thing & (instance_ids != 0), instance_ids.astype(np.uint32),
                   np.where(stuff, STUFF_ID_BASE + cls, 0)).astype(np.uint32)
    if ignored:
        crowd = np.isin(instance_ids, np.fromiter(ignored, np.int64)) & is_thing
        ids[crowd] = CROWD_ID_BASE + cls[crowd]
    return ids


def mark_ignored(entries: list[InstanceEntry], min_instance_px: int) -> set[int]:
    """Set ``ignore`` on every record entry (of :func:`annotate`): True for a thing instance with fewer than
    ``min_instance_px`` visible pixels, too small to learn from, which every format then writes as an ignore
    region (``schemas/generate.schema.json``, ``min_instance_px``). Returns the ids of the ignored instances."""
    ignored = set()
    for entry in entries:
        entry["ignore"] = bool(entry["isthing"] and entry["area"] < min_instance_px)
        if entry["ignore"]:
            ignored.add(int(entry["id"]))
    return ignored


def ids_to_rgb(ids: np.ndarray) -> np.ndarray:
    """(H, W) segment ids -> (H, W, 3) uint8 with id = R + 256 G + 256² B (panopticapi's ``id2rgb``)."""
    ids = ids.astype(np.uint32)
    return np.stack([ids & 255, (ids >> 8) & 255, (ids >> 16) & 255], axis=-1).astype(np.uint8)


def panoptic(class_ids: np.ndarray, instance_ids: np.ndarray, instances: Sequence[Instance],
             class_map: ClassMap, ignored: set[int] = frozenset()) -> tuple[np.ndarray, list[PanopticSegment]]:
    """The COCO-panoptic PNG pixels and the record's ``panoptic_segments``.

    Thing classes (``isthing`` in ``class_map``) give one segment per instance (segment id = instance id),
    stuff classes one segment per class (id ``STUFF_ID_BASE + class id``), class 0 is void. The ``ignored``
    instances (:func:`mark_ignored`) of a class make one crowd segment (``iscrowd`` 1, id ``CROWD_ID_BASE +
    class id``): panopticapi keeps one crowd region per category and image, and neither counts a prediction
    on it nor misses it.

    Returns
    -------
    rgb : (H, W, 3) uint8, segment id = R + 256 G + 256² B
    segments : list of {"id", "category_id", "area", "bbox", "iscrowd"} sorted by id; areas and boxes
        exact (pixel-edge ``[x, y, w, h]`` ints)
    """
    ids = panoptic_ids(class_ids, instance_ids, class_map, ignored)
    by_id = {inst.id: inst for inst in instances}
    counts, boxes = label_extents(ids)
    # a thing segment's id is its instance's id: every class under it must be that instance's class
    things = (ids != 0) & (ids < STUFF_ID_BASE)
    classes = instance_class_table(instances, STUFF_ID_BASE)
    wrong = things & (class_ids != classes[np.where(things, ids, 0)])
    mixed = set(np.unique(ids[wrong]).tolist()) if wrong.any() else set()
    segments = []
    for seg_id in np.flatnonzero(counts).tolist():
        if seg_id == 0:
            continue
        if seg_id >= CROWD_ID_BASE:
            category = seg_id - CROWD_ID_BASE
        elif seg_id >= STUFF_ID_BASE:
            category = seg_id - STUFF_ID_BASE
        else:
            inst = by_id.get(seg_id)
            if inst is None:
                raise InputError(f"instance map: id {seg_id} has no instance; expected one of the scene's "
                                 f"{len(by_id)} instances")
            if seg_id in mixed:
                found = np.unique(class_ids[ids == seg_id]).tolist()
                raise InputError(f"instance {seg_id} ({inst.prim_path}): class ids {found[:5]} under its pixels; "
                                 f"expected only its class {inst.class_id}")
            category = inst.class_id
        segments.append(PanopticSegment(id=int(seg_id), category_id=int(category), area=int(counts[seg_id]),
                                        bbox=box_xywh(boxes[seg_id - 1]), iscrowd=int(seg_id >= CROWD_ID_BASE)))
    return ids_to_rgb(ids), segments


def _check_maps(class_ids: np.ndarray, instance_ids: np.ndarray) -> tuple[int, int]:
    if class_ids.ndim != 2 or class_ids.dtype != np.uint8:
        raise InputError(f"class map image: {class_ids.dtype} array of shape {class_ids.shape}; expected (H, W) uint8")
    if instance_ids.shape != class_ids.shape or instance_ids.dtype != np.uint16:
        raise InputError(f"instance map image: {instance_ids.dtype} array of shape {instance_ids.shape}; "
                         f"expected (H, W) uint16 of shape {class_ids.shape}")
    return int(class_ids.shape[0]), int(class_ids.shape[1])
