"""Where people stand and cameras go in a procedural setting, and the cameras a scenario's rigs get there.

A setting scenario must offer every camera of the dataset's scenario at the same prim path (a sampled image names
its camera by path, whatever its scene): :func:`setting_cameras` places each of them by its rig type, with its
lens (its filmback, the focal length its rig type's lens starts at: a setting is smaller than the street a rig
was zoomed for; a camera without a rig type keeps its own), aimed at the setting's :attr:`Layout.focus` (the middle
of where people stand):

| rig type | where |
|---|---|
| ``cctv``, a camera without a rig type | the high spots in turn (a room's corners 0.5 m under the ceiling; outdoors 5 m up) |
| ``pedestrian_eye``, ``dashcam`` | the eye spots in turn (a room's ends, a path's ends, a sidewalk's), 1.6 m / 1.35 m up |
| ``wheelchair_eye`` | the eye spots from the other end, 1.2 m up |
| ``uav_nadir`` | outdoors straight above the focus, 25 m up; indoors a high spot from the far corners in turn (a room has no room for a view from above: a camera under a 3 m ceiling looking straight down sees a few floor tiles) |
| ``uav_oblique`` | outdoors 45 degrees up from a high spot's side, 25 m above the focus; indoors as ``uav_nadir`` |

The rig types' heights above the ground are kept outdoors; indoors a CCTV or UAV camera hangs under the ceiling
(lower than a street's), and ``randomise.camera`` moves it from there (keep its ``height_m`` under 0.5 m).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from synthua_usd.composition.rigs import RIG_TYPES
from synthua_usd.model.cameras import CameraSpec

#: Camera heights above the floor of the eye-level rigs, metres (their rig types' defaults).
EYE_HEIGHT_M = {"pedestrian_eye": 1.6, "dashcam": 1.35, "wheelchair_eye": 1.2}
#: Outdoors: a CCTV's height and an overhead camera's height above the focus, metres.
OUTDOOR_CCTV_M = 5.0
OUTDOOR_OVERHEAD_M = 25.0


@dataclass(frozen=True)
class Layout:
    """``focus`` (3,) world metres: the middle of where people stand, at 0.8 m; ``eye_spots`` floor points
    (x, y, floor z) where eye-level cameras stand; ``high_spots`` (x, y, z) where CCTV cameras hang; ``ceiling_z``
    the underside of the ceiling (None outdoors)."""

    focus: tuple[float, float, float]
    eye_spots: tuple[tuple[float, float, float], ...]
    high_spots: tuple[tuple[float, float, float], ...]
    ceiling_z: float | None = None

    @property
    def overhead_z(self) -> float:
        """Where an overhead (UAV) camera flies outdoors: 25 m above the focus."""
        return self.focus[2] + OUTDOOR_OVERHEAD_M


def room_layout(x0: float, y0: float, x1: float, y1: float, height: float, inset: float = 0.5) -> Layout:
    """The layout of a room's inside ``[x0, x1] x [y0, y1]`` under a ceiling at ``height``: eye spots at the middles
    of its two short walls, high spots in its four corners 0.5 m under the ceiling, the focus at its centre."""
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    if x1 - x0 >= y1 - y0:
        eyes = ((x0 + inset, cy, 0.0), (x1 - inset, cy, 0.0))
    else:
        eyes = ((cx, y0 + inset, 0.0), (cx, y1 - inset, 0.0))
    z = height - 0.5
    corners = ((x0 + inset, y0 + inset, z), (x1 - inset, y1 - inset, z), (x1 - inset, y0 + inset, z),
               (x0 + inset, y1 - inset, z))
    return Layout((cx, cy, 0.8), eyes, corners, float(height))


def setting_cameras(layout: Layout, cameras: list[CameraSpec]) -> tuple[CameraSpec, ...]:
    """``cameras`` (the dataset scenario's, by name, rig type and lens) placed in the setting of ``layout``: the
    same names, rig types, filmbacks and clipping, the rig type's default focal length, new eyes and targets (see
    the module's docstring)."""
    focus = np.asarray(layout.focus, float)
    counters: dict[str, int] = {}
    out = []
    for cam in cameras:
        kind = cam.rig_type if cam.rig_type in ("pedestrian_eye", "dashcam", "wheelchair_eye", "uav_nadir",
                                                "uav_oblique") else "cctv"
        k = counters.get(kind, 0)
        counters[kind] = k + 1
        if kind in EYE_HEIGHT_M:
            turn = k + (1 if kind == "wheelchair_eye" else 0)
            spot = np.asarray(layout.eye_spots[turn % len(layout.eye_spots)], float)
            eye = spot + [0.0, 0.0, EYE_HEIGHT_M[kind]]
            target = np.array([focus[0], focus[1], spot[2] + 1.0])
            if np.linalg.norm(target[:2] - eye[:2]) < 1.0:  # standing on the focus: look along the room
                target[:2] = eye[:2] + (focus[:2] - np.asarray(layout.eye_spots[0][:2])) + [1e-3, 0.0]
        elif kind in ("uav_nadir", "uav_oblique") and layout.ceiling_z is not None:
            # indoors: from the corners the CCTV views take last, under the ceiling
            eye = np.asarray(layout.high_spots[(len(layout.high_spots) - 1 - k) % len(layout.high_spots)], float)
            target = focus
        elif kind == "uav_nadir":
            eye = np.array([focus[0], focus[1], layout.overhead_z])
            target = focus + [0.0, 0.01, 0.0]  # straight down, +Y at the image's top
        elif kind == "uav_oblique":  # 45 degrees down from the overhead height, on a high spot's side
            spot = layout.high_spots[k % len(layout.high_spots)]
            away = np.asarray(spot[:2], float) - focus[:2]
            away = away / max(np.linalg.norm(away), 1e-9)
            eye = np.array([*(focus[:2] + away * (layout.overhead_z - focus[2])), layout.overhead_z])
            target = focus
        else:
            eye = np.asarray(layout.high_spots[k % len(layout.high_spots)], float)
            target = focus
        rig = RIG_TYPES.get(cam.rig_type or "")
        focal = rig.lens.default_focal_mm if rig is not None else cam.focal_length_mm
        out.append(CameraSpec(cam.name, tuple(map(float, eye)), tuple(map(float, target)), focal,
                              cam.horizontal_aperture_mm, cam.vertical_aperture_mm,
                              f"{cam.doc or cam.name} (placed in the setting as a {kind} view)".strip(),
                              cam.clip_near_m, cam.clip_far_m, cam.rig_type))
    return tuple(out)
