"""COCO instances (``annotations/instances_{split}.json``) from the per-image records.

pycocotools reads it as it is: RLE masks, ``bbox`` as floats ``[x, y, w, h]`` (pixel-edge box), ``area`` in
pixels, ``iscrowd`` 0, or 1 for an instance too small to learn from (fewer visible pixels than the config's
``min_instance_px``): COCOeval then neither rewards nor penalises detections on it, and detectron2 and
MMDetection leave it out of training. Only thing classes are annotated (COCO's instances task has no stuff); stuff is in
the panoptic and Cityscapes formats. Extra fields per annotation, which COCO readers ignore:
``amodal_segmentation``, ``amodal_bbox``, ``amodal_area``, ``occlusion``, ``truncation``, ``prim_path``,
``instance_id`` (the pixel value in the image's instance map) and ``relations``: each ``synthua:*`` relation of
the instance's prim (``uses``: the device a person uses; ``pushes``: the wheelchair a companion pushes;
``accompanies``: the aid user a companion walks beside) as its target's prim path, ``<relation>_class`` its
class, and ``<relation>_annotation_id`` the target's annotation id when it is annotated in the same image.

Keypoints (COCO's person-keypoints fields): a category with keypoints (:mod:`synthua_usd.model.keypoint_classes`:
the person's 17 COCO body keypoints, a mobility aid's contact points) lists their ``keypoints`` names and
``skeleton``; each of its annotations has ``keypoints`` (flat ``[x, y, v, ...]``, pixel coordinates of the
written image, v 0/1/2 as :mod:`synthua_usd.dataset.keypoints` defines them) and ``num_keypoints`` (how
many have v > 0). An instance of such a category whose stage authors no keypoints gets all ``0, 0, 0``.
Every other annotation has ``num_keypoints`` 0: pycocotools' ``COCOeval(gt, dt, "keypoints")`` reads it
from every annotation of the categories it evaluates (all of them by default), and ignores those at 0.

``person_keypoints_{split}.json`` is COCO's keypoints file: the person category and its annotations only
(:func:`person_keypoints`), so that COCOeval's default call, with its default (COCO person) OKS sigmas,
evaluates person keypoints as on COCO. A device's contact points have other counts and sigmas: they are
evaluated per category on the instances file (``params.catIds``, ``params.kpt_oks_sigmas``).
"""

from __future__ import annotations

from typing import Iterable

from synthua_usd.core.errors import InputError
from synthua_usd.dataset.formats.records import image_entry, ordered
from synthua_usd.dataset.record import DatasetRecord, InstanceEntry, is_rejected
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES
from synthua_usd.model.taxonomy import ClassMap


def categories(class_map: ClassMap) -> list[dict]:
    """COCO ``categories``: every thing class with id >= 1; ``supercategory`` is the class's group; classes
    with keypoints add their ``keypoints`` names and ``skeleton``."""
    out = []
    for c in class_map.classes:
        if c.isthing and c.id >= 1:
            entry = {"id": c.id, "name": c.name, "supercategory": c.group}
            if c.name in KEYPOINT_CLASSES:
                entry.update(KEYPOINT_CLASSES[c.name].coco_category_fields())
            out.append(entry)
    return out


def _keypoint_fields(record: DatasetRecord, inst: InstanceEntry, class_name: str) -> dict:
    """``keypoints`` and ``num_keypoints`` of an instance of ``class_name``, a class with keypoints (module
    docstring)."""
    names = KEYPOINT_CLASSES[class_name].names
    found = inst.get("keypoints")
    if found is None:
        return {"keypoints": [0] * (3 * len(names)), "num_keypoints": 0}
    if tuple(found["names"]) != names or len(found["keypoints"]) != 3 * len(names):
        raise InputError(f"record {record['name']!r}: instance {inst['id']} has keypoints {found['names']} "
                         f"({len(found['keypoints'])} values); expected {list(names)}, 3 values each")
    return {"keypoints": list(found["keypoints"]), "num_keypoints": int(found["num_keypoints"])}


def annotation_ids(records: Iterable[DatasetRecord], class_map: ClassMap) -> dict[tuple[int, int], int]:
    """(image id, instance id) -> annotation id, unique across the whole dataset (all splits): 1, 2, ... in
    image-id order, then in each record's instance order. Rejected images take no ids."""
    things = {c.id for c in class_map.classes if c.isthing and c.id >= 1}
    out: dict[tuple[int, int], int] = {}
    for record in ordered(records):
        if is_rejected(record):
            continue
        for inst in record["instances"]:
            if inst["category_id"] in things:
                out[(record["id"], inst["id"])] = len(out) + 1
    return out


def coco_instances(records: Iterable[DatasetRecord], class_map: ClassMap, split: str) -> dict:
    """The COCO instances document of ``split``.

    Parameters
    ----------
    records : every record of the dataset (all splits: annotation ids are unique across them)
    class_map : the dataset's classes
    split : ``train``, ``val`` or ``test``

    Returns
    -------
    dict with ``info``, ``licenses``, ``images`` (``file_name`` = ``{name}.png``, relative to
    ``images/{split}/``), ``annotations`` and ``categories``; JSON-serialisable.
    """
    records = ordered(records)
    known = {c.id for c in class_map.classes}
    ids = annotation_ids(records, class_map)
    images, annotations = [], []
    for record in records:
        if record["split"] != split or is_rejected(record):
            continue
        images.append(image_entry(record))
        by_path = {inst["prim_path"]: ids.get((record["id"], inst["id"])) for inst in record["instances"]}
        for inst in record["instances"]:
            if inst["category_id"] not in known:
                raise InputError(f"record {record['name']!r}: instance {inst['id']} has class id "
                                 f"{inst['category_id']}; expected a class of {class_map.source}")
            ann_id = ids.get((record["id"], inst["id"]))
            if ann_id is None:
                continue
            name = class_map.by_id(int(inst["category_id"])).name
            relations: dict[str, str | int] = dict(inst["relations"])
            for relation, target in sorted(inst["relations"].items()):  # uses, pushes, accompanies -> annotated target
                annotated = None if relation.endswith("_class") else by_path.get(target)
                if annotated is not None:
                    relations[f"{relation}_annotation_id"] = annotated
            annotations.append({
                "id": ann_id, "image_id": int(record["id"]), "category_id": int(inst["category_id"]),
                "segmentation": inst["segmentation"], "area": int(inst["area"]),
                "bbox": [float(v) for v in inst["bbox"]], "iscrowd": int(inst["ignore"]),
                "amodal_segmentation": inst["amodal_segmentation"], "amodal_area": int(inst["amodal_area"]),
                "amodal_bbox": [float(v) for v in inst["amodal_bbox"]],
                "occlusion": float(inst["occlusion"]), "truncation": float(inst["truncation"]),
                "prim_path": inst["prim_path"], "instance_id": int(inst["id"]), "relations": relations,
                **(_keypoint_fields(record, inst, name) if name in KEYPOINT_CLASSES else {"num_keypoints": 0}),
            })
    return {"info": {"description": f"synthua-usd synthetic street scenes, {split} split",
                     "version": "1.0"},
            "licenses": [], "images": images, "annotations": annotations, "categories": categories(class_map)}


#: The class of COCO's keypoints task (its file holds this category only).
PERSON = "person"


def person_keypoints(instances: dict) -> dict:
    """COCO's ``person_keypoints_{split}`` document from the instances document of the same split: its info,
    licenses and images, the person category and the person annotations (module docstring)."""
    cats = [c for c in instances["categories"] if c["name"] == PERSON]
    ids = {c["id"] for c in cats}
    return {"info": instances["info"], "licenses": instances["licenses"], "images": instances["images"],
            "annotations": [a for a in instances["annotations"] if a["category_id"] in ids], "categories": cats}
