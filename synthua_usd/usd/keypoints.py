"""Keypoints authored on labelled prims: a person's COCO body keypoints, a device's contact points.

On an instance prim (the prim carrying the label), two custom attributes:

- ``synthua:keypointNames`` (token[], uniform): the names, which must be those of the instance's class in
  :data:`synthua_usd.model.keypoint_classes.KEYPOINT_CLASSES`, in that order (an instance whose class, in the
  class map in use, has no keypoints there keeps none, with a warning);
- ``synthua:keypoints`` (point3f[], one point per name): positions in the prim's own frame, stage units,
  time-sampled when they move.

:func:`read_keypoints` gives them in world metres at a time code (the prim's local-to-world transform at
that time applied), as plain :class:`synthua_usd.model.scene.Keypoints`.
"""

from __future__ import annotations

import logging

import numpy as np
from pxr import Usd, UsdGeom

from synthua_usd.core.errors import StageError
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES
from synthua_usd.model.scene import Instance, Keypoints

log = logging.getLogger(__name__)

KEYPOINTS_ATTR = "synthua:keypoints"
KEYPOINT_NAMES_ATTR = "synthua:keypointNames"


def keypoint_prims(stage: Usd.Stage, instances: dict[str, Instance]) -> list[tuple[Usd.Prim, Instance]]:
    """The instance prims that author ``synthua:keypoints``, with their instance, checked (names of the class)."""
    out, skipped = [], []
    for path, inst in sorted(instances.items()):
        prim = stage.GetPrimAtPath(path)
        attr = prim.GetAttribute(KEYPOINTS_ATTR) if prim else None
        if attr is None or not attr.HasAuthoredValue():
            continue
        names_attr = prim.GetAttribute(KEYPOINT_NAMES_ATTR)
        names = tuple(names_attr.Get() or ()) if names_attr else ()
        expected = KEYPOINT_CLASSES.get(inst.class_name)
        if expected is None:  # a class map that maps the person or device to a class without keypoints
            skipped.append(path)
            continue
        if names != expected.names:
            raise StageError(f"{path}: {KEYPOINT_NAMES_ATTR} is {list(names)[:20]}; expected the keypoints of "
                             f"class {inst.class_name}: {list(expected.names)}")
        out.append((prim, inst))
    if skipped:
        log.warning("%d instances author keypoints but their class in this class map has none (e.g. %s); "
                    "they get no keypoints", len(skipped), skipped[0])
    return out


def read_keypoints(prims: list[tuple[Usd.Prim, Instance]], time_code: float, xcache: UsdGeom.XformCache,
                   meters_per_unit: float) -> dict[int, Keypoints]:
    """Instance id -> keypoints in world metres at ``time_code`` of ``prims`` (from :func:`keypoint_prims`)."""
    out = {}
    for prim, inst in prims:
        names = KEYPOINT_CLASSES[inst.class_name].names
        local = np.asarray(prim.GetAttribute(KEYPOINTS_ATTR).Get(Usd.TimeCode(time_code)), np.float64).reshape(-1, 3)
        if len(local) != len(names) or not np.all(np.isfinite(local)):
            raise StageError(f"{prim.GetPath()}: {KEYPOINTS_ATTR} at time {time_code:g} holds {len(local)} points "
                             f"(finite: {bool(np.all(np.isfinite(local)))}); expected {len(names)} finite points, "
                             f"one per name")
        m = np.array(xcache.GetLocalToWorldTransform(prim), float)  # row-vector convention
        world = (local @ m[:3, :3] + m[3, :3]) * meters_per_unit
        out[inst.id] = Keypoints(instance_id=inst.id, names=names, points=world)
    return out
