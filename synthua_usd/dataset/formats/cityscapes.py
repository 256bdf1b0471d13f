"""Cityscapes ``gtFine`` images: ``*_gtFine_labelIds.png``, ``*_gtFine_instanceIds.png``, ``*_gtFine_color.png``.

The label ids are **synthua's class ids** (the class map's taxonomy), not Cityscapes' 34 ids: the classes
differ (mobility aids, furniture, ...). cityscapesScripts reads the files once its label table is replaced
by :func:`cityscapes_labels` (its tools import ``labels``, ``id2label``, ``name2label``, ``category2labels``
from ``cityscapesscripts.helpers.labels``; patch those, as the tests do).

``instanceIds`` follows Cityscapes: a pixel of a thing class that belongs to an instance is
``class * 1000 + k`` with ``k = 0, 1, ...`` numbering that class's instances in the image in instance-id
order; any other pixel (stuff, void, thing without instance) is its class id. A class with more than 1000
instances in one image, or an encoded id above 65535 (class ids >= 66), cannot be written in this scheme and
raises :class:`OutputError` instead of wrapping into another class's ids.

File names come from :class:`synthua_usd.dataset.layout.CityscapesName`: ``{city}_{seq:06d}_{frame:06d}``,
the three underscore-separated fields ``getCsFileInfo`` expects.
"""

from __future__ import annotations

from typing import AbstractSet, Sequence

import numpy as np

from synthua_usd.core.errors import InputError, OutputError
from synthua_usd.model.scene import Instance
from synthua_usd.model.taxonomy import ClassMap

#: Instances of one class that ``class * 1000 + k`` can number in one image.
MAX_INSTANCES_PER_CLASS = 1000


def cityscapes_arrays(class_ids: np.ndarray, instance_ids: np.ndarray, instances: Sequence[Instance],
                      class_map: ClassMap, ignored: AbstractSet[int] = frozenset()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The three gtFine images of one frame.

    Parameters
    ----------
    class_ids : (H, W) uint8 class ids
    instance_ids : (H, W) uint16 instance ids (0 none)
    instances : the scene's instances (their ``class_id`` is their class)
    class_map : thing/stuff and colours of the classes
    ignored : instance ids too small to annotate (:func:`synthua_usd.dataset.annotations.mark_ignored`): their
        pixels keep the class id without an instance number, Cityscapes' group region, which its instance
        evaluation ignores

    Returns
    -------
    label_ids : (H, W) uint8, the class ids as they are
    cs_instance_ids : (H, W) uint16, ``class * 1000 + k`` on thing instances (k counting the instances not
        ignored), the class id elsewhere
    color : (H, W, 3) uint8 sRGB class colours
    """
    if class_ids.ndim != 2 or class_ids.dtype != np.uint8 or instance_ids.shape != class_ids.shape:
        raise InputError(f"label maps: {class_ids.dtype}{class_ids.shape} and {instance_ids.dtype}{instance_ids.shape}; "
                         f"expected (H, W) uint8 and uint16 of the same shape")
    thing = {c.id for c in class_map.classes if c.isthing}
    by_id = {inst.id: inst for inst in instances}
    counts = np.bincount(instance_ids.reshape(-1))
    # per instance id: its encoded id, on the pixels of its own class (one lookup over the map)
    encoded = np.zeros(counts.size, np.uint16)
    own_class = np.full(counts.size, -1, np.int32)
    counters: dict[int, int] = {}
    for inst_id in np.flatnonzero(counts).tolist():
        if inst_id == 0:
            continue
        inst = by_id.get(inst_id)
        if inst is None:
            raise InputError(f"instance map: id {inst_id} has no instance; expected one of the scene's "
                             f"{len(by_id)} instances")
        if inst.class_id not in thing or inst_id in ignored:
            continue
        k = counters.get(inst.class_id, 0)
        counters[inst.class_id] = k + 1
        if k >= MAX_INSTANCES_PER_CLASS or inst.class_id * 1000 + k > np.iinfo(np.uint16).max:
            raise OutputError(f"Cityscapes instanceIds: instance {inst_id} is number {k} of class {inst.class_id} "
                              f"in this image; expected at most {MAX_INSTANCES_PER_CLASS} instances of a class and "
                              f"class*1000+k within 16 bits")
        encoded[inst_id] = inst.class_id * 1000 + k
        own_class[inst_id] = inst.class_id
    out = np.where(class_ids == own_class[instance_ids], encoded[instance_ids], class_ids.astype(np.uint16))
    return class_ids.copy(), out, class_map.palette()[class_ids]


def cityscapes_labels(class_map: ClassMap) -> list[dict]:
    """The label table for cityscapesScripts, one dict per class with the fields of its ``Label`` namedtuple
    (``name, id, trainId, category, categoryId, hasInstances, ignoreInEval, color``): ``trainId`` = id,
    ``category`` = the class's group, ``categoryId`` = the group's rank of first appearance, class 0 ignored
    in evaluation. Build ``Label(**entry)`` from each to patch cityscapesScripts."""
    groups: dict[str, int] = {}
    out = []
    for c in class_map.classes:
        category_id = groups.setdefault(c.group, len(groups))
        out.append({"name": c.name, "id": c.id, "trainId": c.id, "category": c.group, "categoryId": category_id,
                    "hasInstances": bool(c.isthing), "ignoreInEval": c.id == 0, "color": tuple(c.color)})
    return out


def check_class_map(class_map: ClassMap) -> None:
    """Refuse, before anything renders, a class map whose thing classes cannot take Cityscapes' 16-bit
    ``instanceIds`` (class·1000 + k: thing class ids up to 65)."""
    limit = np.iinfo(np.uint16).max // 1000 - 1
    too_high = [c for c in class_map.classes if c.isthing and c.id > limit]
    if too_high:
        c = too_high[0]
        raise InputError(f"{class_map.source}: thing class '{c.name}' has id {c.id}; expected thing class ids up to "
                         f"{limit}, so that Cityscapes instanceIds (class*1000 + k) fit 16 bits")
