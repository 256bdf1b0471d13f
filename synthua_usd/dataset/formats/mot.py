"""Tracking sequences in the MOTChallenge layout (MOT17/MOT20), with what MOT cannot say beside it.

Per sequence (from its frames' records alone):

* ``gt/gt.txt``: one line per track and frame, ``frame,id,bb_left,bb_top,bb_width,bb_height,conf,class,visibility``
  as MOT17 defines them: frames from 1; the box is the full (amodal) extent of the object inside the frame, its
  top-left corner in MOTChallenge's 1-based pixel coordinates (our pixel-edge x, y plus 1); ``conf`` 1 (every
  row is to be considered); ``class`` MOT17's id (:data:`MOT_CLASSES`: pedestrian 1 for every person, car 3, bicycle
  4, motorbike 5, non-motorised vehicle 6 for mobility aids); ``visibility`` = 1 - occlusion, the share of the
  amodal mask that is visible (our amodal masks, traced along each pixel-centre ray). Rows are sorted by frame,
  then id.
* ``tracks.csv``: one row per track: its id, our class id and name, its MOT class, its prim path, and the track it
  uses (a person's device) or is used by (a device's user): the link MOT's format has no column for.
* ``seqinfo.ini``: MOTChallenge's sequence header (name, image folder, frame rate, length, size, extension).

Track ids are the instances' ids of the stage, the same in every frame of a sequence (labels do not change over
time). Tracked are the classes of :data:`TRACKED_GROUPS` (people, mobility aids, vehicles).

For the whole dataset, :func:`coco_video` writes every sequence as COCO video annotations (TAO's layout: ``videos``,
``images`` with ``video_id`` and ``frame_index`` from 0, ``annotations`` with ``track_id``, ``tracks``,
``categories``), boxes there being COCO's visible ones, RLE masks included.
"""

from __future__ import annotations

import csv
import io

from synthua_usd.dataset.record import InstanceEntry
from synthua_usd.model.taxonomy import ClassMap

#: Class-map groups whose instances are tracked.
TRACKED_GROUPS = ("person", "accessibility", "vehicle")
#: MOT17's class ids (TrackEval's ``class_name_to_class_id``): pedestrian 1, car 3, bicycle 4, motorbike 5,
#: non_mot_vehicle 6; our classes map to them by name, mobility aids to non-motorised vehicles, other vehicles to car.
MOT_CLASSES = {"person": 1, "car": 3, "bus": 3, "bicycle": 4, "motorcycle": 5}
MOT_AID = 6
MOT_OTHER_VEHICLE = 3
COLUMNS = ("frame", "id", "bb_left", "bb_top", "bb_width", "bb_height", "conf", "class", "visibility")


def tracked(class_map: ClassMap) -> dict[str, int]:
    """Class name -> MOT class id of every tracked class of ``class_map``."""
    out = {}
    for c in class_map.classes:
        if c.group not in TRACKED_GROUPS or not c.isthing:
            continue
        if c.name in MOT_CLASSES:
            out[c.name] = MOT_CLASSES[c.name]
        else:
            out[c.name] = MOT_AID if c.group == "accessibility" else MOT_OTHER_VEHICLE if c.group == "vehicle" else 1
    return out


def visibility(entry: InstanceEntry) -> float:
    """1 - occlusion: the visible share of the amodal mask (0..1)."""
    return max(0.0, min(1.0, 1.0 - float(entry["occlusion"])))


def gt_rows(frames: list[tuple[int, list[InstanceEntry]]], class_map: ClassMap) -> list[tuple]:
    """The rows of ``gt.txt`` from ``(frame, record instances)`` pairs, sorted by frame then id."""
    mot = tracked(class_map)
    rows = []
    for frame, instances in frames:
        for entry in instances:
            if entry["class_name"] not in mot:
                continue
            x, y, w, h = entry["amodal_bbox"]
            rows.append((int(frame), int(entry["id"]), int(x) + 1, int(y) + 1, int(w), int(h), 1,
                         mot[entry["class_name"]], round(visibility(entry), 6)))
    return sorted(rows)


def gt_text(rows: list[tuple]) -> str:
    return "".join(",".join(f"{v:g}" if isinstance(v, float) else str(v) for v in row) + "\n" for row in rows)


def tracks_text(frames: list[tuple[int, list[InstanceEntry]]], class_map: ClassMap) -> str:
    """``tracks.csv``: each tracked instance once, with the tracks it uses and is used by (ids, or empty)."""
    mot = tracked(class_map)
    seen: dict[int, InstanceEntry] = {}
    by_path: dict[str, int] = {}
    for _, instances in frames:
        for entry in instances:
            if entry["class_name"] in mot and int(entry["id"]) not in seen:
                seen[int(entry["id"])] = entry
                by_path[entry["prim_path"]] = int(entry["id"])
    uses = {tid: by_path.get(e["relations"].get("uses", "")) for tid, e in seen.items()}
    used_by = {target: tid for tid, target in uses.items() if target is not None}
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["id", "class_id", "class_name", "mot_class", "prim_path", "uses_id", "used_by_id"])
    for tid in sorted(seen):
        e = seen[tid]
        writer.writerow([tid, e["category_id"], e["class_name"], mot[e["class_name"]], e["prim_path"],
                         uses[tid] if uses[tid] is not None else "", used_by.get(tid, "")])
    return buffer.getvalue()


def seqinfo_text(name: str, fps: float, frames: int, width: int, height: int, extension: str = ".jpg") -> str:
    rate = f"{fps:g}"
    return (f"[Sequence]\nname={name}\nimDir=img1\nframeRate={rate}\nseqLength={frames}\nimWidth={width}\n"
            f"imHeight={height}\nimExt={extension}\n")


def coco_video(sequences: list[dict], class_map: ClassMap) -> dict:
    """COCO video annotations (TAO's layout) of ``sequences``: dicts with ``name``, ``width``, ``height``, ``fps``
    and ``frames``, a list of ``(frame, image file relative to the dataset, record instances)``."""
    mot = tracked(class_map)
    categories = [{"id": c.id, "name": c.name, "supercategory": c.group} for c in class_map.classes if c.name in mot]
    videos, images, annotations = [], [], []
    tracks: dict[int, dict] = {}
    image_id = ann_id = 0
    for video_id, seq in enumerate(sequences, start=1):
        videos.append({"id": video_id, "name": seq["name"], "width": seq["width"], "height": seq["height"],
                       "fps": seq["fps"]})
        for frame, file_name, instances in seq["frames"]:
            image_id += 1
            images.append({"id": image_id, "video_id": video_id, "frame_index": frame - 1, "file_name": file_name,
                           "width": seq["width"], "height": seq["height"]})
            for entry in instances:
                if entry["class_name"] not in mot:
                    continue
                ann_id += 1
                track_id = video_id * 1_000_000 + int(entry["id"])  # unique over the dataset, the instance id kept
                tracks.setdefault(track_id, {"id": track_id, "video_id": video_id, "category_id": entry["category_id"]})
                annotations.append({"id": ann_id, "image_id": image_id, "video_id": video_id, "track_id": track_id,
                                    "category_id": entry["category_id"], "bbox": entry["bbox"], "area": entry["area"],
                                    "segmentation": entry["segmentation"], "iscrowd": 0,
                                    "amodal_bbox": entry["amodal_bbox"], "visibility": visibility(entry)})
    return {"info": {"description": "synthua-usd tracking sequences (COCO video, TAO layout)"}, "videos": videos,
            "images": images, "annotations": annotations, "tracks": [tracks[k] for k in sorted(tracks)],
            "categories": categories}
