"""A hand-made dataset folder of three 8x6 images for the analytics tests, written with PIL and
pycocotools (not with synthua's writers), holding what analytics reads: manifest, class map, records,
RGB images, class maps and COCO instances. Image 3 is rejected by QA and must be left out everywhere.

Image 1 (train, clear_day, cctv)        Image 2 (val, day_fog, pedestrian_eye)
  rows 0-2, cols 0-3: building #1 (12)    rows 0-1, cols 0-2: building #1 (6)
  row 3, cols 0-1: person #2 (2),         rows 0-1, cols 4-5: building #2 (4)
     uses the wheelchair #3               row 3, cols 6-7: walker #3 (2), standing alone
  row 3, cols 2-4: manual_wheelchair #3   row 5: road (8)
     (3 visible of 4 amodal pixels)       unlabelled: 28
  rows 4-5: road (16); unlabelled: 15
Image 3 (test, rejected): road everywhere.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from PIL import Image
from pycocotools import mask as mask_utils
from scipy import ndimage

from synthua_usd.model.conditions import shipped
from synthua_usd.model.taxonomy import ClassMap

H, W = 6, 8
ROAD, BUILDING, PERSON, WHEELCHAIR, WALKER = 1, 6, 18, 29, 31
NAMES = ("000001_CCTV_t0001_clear-day_s0", "000002_Ped_t0001_day-fog_s0", "000003_CCTV_t0002_clear-day_s0")


def label_maps() -> list[tuple[np.ndarray, np.ndarray]]:
    """(class ids, instance ids) per image, (H, W) each."""
    c1, i1 = np.zeros((H, W), np.uint8), np.zeros((H, W), np.uint16)
    c1[4:6, :] = ROAD
    c1[0:3, 0:4], i1[0:3, 0:4] = BUILDING, 1
    c1[3, 0:2], i1[3, 0:2] = PERSON, 2
    c1[3, 2:5], i1[3, 2:5] = WHEELCHAIR, 3
    c2, i2 = np.zeros((H, W), np.uint8), np.zeros((H, W), np.uint16)
    c2[5, :] = ROAD
    c2[0:2, 0:3], i2[0:2, 0:3] = BUILDING, 1
    c2[0:2, 4:6], i2[0:2, 4:6] = BUILDING, 2
    c2[3, 6:8], i2[3, 6:8] = WALKER, 3
    c3, i3 = np.full((H, W), ROAD, np.uint8), np.zeros((H, W), np.uint16)
    return [(c1, i1), (c2, i2), (c3, i3)]


def _rle(mask: np.ndarray) -> dict:
    rle = mask_utils.encode(np.asfortranarray(mask.astype(np.uint8)))
    return {"size": [int(v) for v in rle["size"]], "counts": rle["counts"].decode("ascii")}


def _bbox(mask: np.ndarray) -> list[int]:
    ys, xs = np.nonzero(mask)
    return [int(xs.min()), int(ys.min()), int(xs.max() - xs.min() + 1), int(ys.max() - ys.min() + 1)]


#: What a record says the images were rendered with (read by none of the analytics: the schema requires it).
_RENDER = {"variant": "scalar_rgb", "spp": 1, "pixel_filter": "box", "max_depth": 4, "width": W, "height": H,
           "denoise": None}


def _camera(name: str, rig_type: str) -> dict:
    """A record's camera block (``$defs/camera``): a pinhole looking down -Z at the origin."""
    return {"prim_path": f"/World/Cameras/{name}", "name": name, "rig_type": rig_type,
            "K": [[10.0, 0.0, W / 2], [0.0, 10.0, H / 2], [0.0, 0.0, 1.0]], "camera_to_world": np.eye(4).tolist(),
            "world_to_camera_opencv": np.diag([1.0, -1.0, -1.0, 1.0]).tolist(), "focal_length_mm": 35.0,
            "horizontal_aperture_mm": 36.0, "vertical_aperture_mm": 27.0, "clipping_range_m": [0.1, 1000.0],
            "distortion": None}


def _files(name: str, split: str) -> dict:
    """The files a record lists (the ones the schema requires; only rgb_png and class are written here)."""
    return {"rgb_png": f"images/{split}/{name}.png", "class": f"frames/{name}/class.png",
            "semantic": f"frames/{name}/semantic.png", "instance": f"frames/{name}/instance.png",
            "instance_preview": f"frames/{name}/instance_preview.png"}


def write(root: Path) -> Path:
    cmap = ClassMap.default()
    splits = ("train", "val", "test")
    conditions = ("clear_day", "day_fog", "clear_day")
    rigs = ("cctv", "pedestrian_eye", "cctv")
    verdicts = ("accepted", "flagged", "rejected")
    (root / "records").mkdir(parents=True)
    (root / "annotations").mkdir()
    (root / "class_map.json").write_text(json.dumps(cmap.document()))
    manifest = {"$schema": "manifest", "provenance": {}, "images": [], "dataset_files": []}
    coco = {s: {"images": [], "annotations": [], "categories": [
        {"id": c.id, "name": c.name, "supercategory": c.group} for c in cmap.classes if c.isthing]} for s in splits}
    ann_id = 0
    for k, ((cls, inst), name, split) in enumerate(zip(label_maps(), NAMES, splits)):
        image_id = k + 1
        for folder in (root / "images" / split, root / "frames" / name):
            folder.mkdir(parents=True, exist_ok=True)
        c16 = cls.astype(np.int64)
        rgb = np.stack([(c16 * 7) % 256, (c16 * 3) % 256, np.full_like(c16, 90)], axis=-1).astype(np.uint8)
        Image.fromarray(rgb).save(root / "images" / split / f"{name}.png")
        Image.fromarray(cls).save(root / "frames" / name / "class.png")
        instances, segments = [], []
        for iid in sorted(set(np.unique(inst).tolist()) - {0}):
            mask = inst == iid
            cid = int(cls[mask][0])
            c = cmap.by_id(cid)
            amodal = int(mask.sum()) + (1 if cid == WHEELCHAIR else 0)
            relations = {"uses": "/World/Agents/A1/Wheelchair", "uses_class": "manual_wheelchair"} \
                if cid == PERSON else {}
            prim = {PERSON: "/World/Agents/A1/Person", WHEELCHAIR: "/World/Agents/A1/Wheelchair"}.get(
                cid, f"/World/Twin/Thing_{image_id}_{iid}")
            entry = {"id": iid, "category_id": cid, "class_name": c.name, "isthing": True, "area": int(mask.sum()),
                     "amodal_area": amodal, "occlusion": 1 - int(mask.sum()) / amodal, "bbox": _bbox(mask),
                     "segmentation": _rle(mask), "amodal_bbox": _bbox(mask), "amodal_segmentation": _rle(mask),
                     "truncation": 0.0, "prim_path": prim, "relations": relations, "ignore": False}
            instances.append(entry)
            segments.append({"id": iid, "category_id": cid, "area": int(mask.sum()), "bbox": _bbox(mask), "iscrowd": 0})
            ann_id += 1
            coco[split]["annotations"].append({"id": ann_id, "image_id": image_id, "category_id": cid,
                                               "segmentation": _rle(mask), "area": int(mask.sum()),
                                               "bbox": [float(v) for v in _bbox(mask)], "iscrowd": 0})
        for cid in sorted(set(np.unique(cls).tolist()) - {0}):
            if not cmap.by_id(cid).isthing:
                mask = cls == cid
                segments.append({"id": 65536 + cid, "category_id": cid, "area": int(mask.sum()),
                                 "bbox": _bbox(mask), "iscrowd": 0})
        pixels = {cmap.by_id(int(v)).name: int((cls == v).sum()) for v in np.unique(cls)}
        record = {"id": image_id, "name": name, "split": split, "width": W, "height": H, "seed": 0,
                  "time_code": 1.0, "camera": _camera(name.split("_")[1], rigs[k]),
                  "condition": shipped(conditions[k]).to_dict(), "exposure": None, "render": _RENDER,
                  "layer_stack": "0" * 64, "files": _files(name, split), "class_pixel_counts": pixels,
                  "instances": instances, "panoptic_segments": segments,
                  "qa": {"verdict": verdicts[k], "reasons": [], "measures": {}}, "checksums": {}}
        (root / "records" / f"{name}.json").write_text(json.dumps(record))
        manifest["images"].append({"id": image_id, "name": name, "split": split, "seed": 0, "qa": verdicts[k],
                                   "files": []})
        if verdicts[k] != "rejected":
            coco[split]["images"].append({"id": image_id, "file_name": f"{name}.png", "width": W, "height": H})
        else:
            coco[split]["annotations"] = [a for a in coco[split]["annotations"] if a["image_id"] != image_id]
    for split in splits:
        (root / "annotations" / f"instances_{split}.json").write_text(json.dumps(coco[split]))
    (root / "manifest.json").write_text(json.dumps(manifest))
    return root


def contrast_and_edges(png: Path) -> tuple[float, float]:
    """(RMS contrast, edge density) of an RGB PNG as the statistics define them, computed without analytics
    code: read with PIL, the luma written out, the edges through scipy."""
    px = np.asarray(Image.open(png), np.float64)
    y = (0.2126 * px[..., 0] + 0.7152 * px[..., 1] + 0.0722 * px[..., 2]) / 255
    g = np.hypot(ndimage.sobel(y, axis=1), ndimage.sobel(y, axis=0)) / 4
    return float(np.std(y)), float(np.mean(g > 0.1))


def kept_contrast_and_edges(root: Path) -> dict[int, tuple[float, float]]:
    """:func:`contrast_and_edges` by image id of the images kept (1 and 2; 3 is rejected)."""
    return {k + 1: contrast_and_edges(root / "images" / split / f"{name}.png")
            for k, (name, split) in enumerate(zip(NAMES[:2], ("train", "val")))}
