"""COCO panoptic (``annotations/panoptic_{split}.json`` + ``annotations/panoptic_{split}/{name}.png``).

panopticapi's conventions: one PNG per image whose pixel id is ``R + 256 G + 256² B`` (0 = void), and per
image a ``segments_info`` list whose ids are exactly the ids in the PNG, with exact ``area``, ``bbox`` and
``iscrowd``; categories carry ``isthing`` (0/1) and ``color``. ``pq_compute`` finds the PNG folder by
dropping ``.json`` from the JSON's path, which is :class:`~synthua_usd.dataset.layout.Layout`'s layout.
The segments themselves are made once per image by :func:`synthua_usd.dataset.annotations.panoptic`.
"""

from __future__ import annotations

from typing import Iterable

from synthua_usd.dataset.formats.records import image_entry, in_split
from synthua_usd.dataset.record import DatasetRecord
from synthua_usd.model.taxonomy import ClassMap


def panoptic_categories(class_map: ClassMap) -> list[dict]:
    """Every class with id >= 1 (things and stuff; 0 is void)."""
    return [{"id": c.id, "name": c.name, "supercategory": c.group, "isthing": int(c.isthing),
             "color": list(c.color)} for c in class_map.classes if c.id >= 1]


def coco_panoptic(records: Iterable[DatasetRecord], class_map: ClassMap, split: str) -> dict:
    """The COCO panoptic document of ``split`` (rejected images left out).

    Returns
    -------
    dict with ``info``, ``licenses``, ``images``, ``annotations`` (``image_id``, ``file_name`` =
    ``{name}.png`` inside ``annotations/panoptic_{split}/``, ``segments_info``) and ``categories``.
    """
    images, annotations = [], []
    for record in in_split(records, split):
        images.append(image_entry(record))
        annotations.append({"image_id": int(record["id"]), "file_name": f"{record['name']}.png",
                            "segments_info": [dict(s) for s in record["panoptic_segments"]]})
    return {"info": {"description": f"synthua-usd synthetic street scenes, {split} split (panoptic)",
                     "version": "1.0"},
            "licenses": [], "images": images, "annotations": annotations,
            "categories": panoptic_categories(class_map)}
