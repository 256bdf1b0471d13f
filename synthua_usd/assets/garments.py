"""How images lie on a bank body: texture coordinates per triangle corner, in the body's rest pose.

Three mappings, one per kind of surface (``st`` in USD's convention, metres scaled to image repeats):

* **Face** (the triangles whose dominant bone is the head): around the head's vertical axis (through the ears'
  midpoint), ``s`` the arc from the face's front and ``t`` the height, both from the eyes' midpoint and
  normalised by this body's eye spacing and eye-to-nose drop, so that every body's eyes, brows and mouth land
  on the same places of the face image (:data:`FACE_SPAN_M` square, centred on the eyes, clamped at its edges).
* **Shoes** (the feet): seen from the side, ``s`` along the foot and ``t`` the height above the sole
  (:data:`SHOE_TILE_M`), so a shoe image's bottom rows are its sole.
* **Fabric** (everything else): around each bone's axis (the torso's is vertical), ``s`` the arc from the front
  and ``t`` the length along the bone, in repeats of :data:`FABRIC_TILE_M`: stripes run round the body, folds
  across the limbs. The seam at the back is unwrapped per triangle.

Every ``s`` but the face's is shifted by :data:`AWAY` whole repeats: fabric and shoe images repeat, so the shift
changes nothing of theirs, while a clamped face image shows only its (plain skin) edge there: bare forearms and
hands bound to the skin material stay plain.
"""

from __future__ import annotations

import functools

import numpy as np

from synthua_usd.assets.bodies import BONES, PARENT, Bank

#: Metres of garment per repeat of a fabric image.
FABRIC_TILE_M = 0.3
#: Metres of shoe per repeat of a shoe image (along the foot and up from the sole).
SHOE_TILE_M = 0.15
#: The face image covers this many metres square, centred on the eyes' midpoint.
FACE_SPAN_M = 0.2
#: Half the eye spacing and the eyes-to-nose-tip drop the face image is drawn for, metres (an adult's).
EYE_HALF_SPACING_M = 0.032
EYE_TO_NOSE_M = 0.035
#: Whole repeats added to every non-face ``s`` (see the module's docstring).
AWAY = 10.0
# COCO keypoints (bank.keypoints' order)
_NOSE, _EYES, _EARS = 0, (1, 2), (3, 4)
#: Each bone's axis for the fabric mapping: the joints it runs between (None: vertical through the joint).
_CHILD = {"torso": None, "head": None, "upperleg.L": "lowerleg.L", "upperleg.R": "lowerleg.R",
          "lowerleg.L": "foot.L", "lowerleg.R": "foot.R", "upperarm.L": "lowerarm.L", "upperarm.R": "lowerarm.R",
          "lowerarm.L": "hand.L", "lowerarm.R": "hand.R", "hand.L": None, "hand.R": None, "foot.L": None,
          "foot.R": None}
_FEET = ("foot.L", "foot.R")


def _frame(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(along, front, side): ``axis`` and two unit directions perpendicular to it, ``front`` as near the body's
    forward (+X) as it can be (up for a bone pointing forward)."""
    along = axis / np.linalg.norm(axis)
    for ref in (np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])):
        front = ref - np.dot(ref, along) * along
        if np.linalg.norm(front) > 0.3:
            break
    front /= np.linalg.norm(front)
    return along, front, np.cross(along, front)


def _bone_axis(joints: np.ndarray, bone: str) -> tuple[np.ndarray, np.ndarray]:
    """(origin, axis) of ``bone``'s fabric mapping in the rest pose (a hand continues its forearm)."""
    k = BONES.index(bone)
    child = _CHILD[bone]
    if child is not None:
        return joints[k], joints[BONES.index(child)] - joints[k]
    if bone.startswith("hand"):
        return joints[k], joints[k] - joints[BONES.index(PARENT[bone])]
    return joints[k], np.array([0.0, 0.0, 1.0])


def _fabric(points: np.ndarray, joints: np.ndarray, bone: str, corners: np.ndarray) -> np.ndarray:
    """(m, 3, 2) metres (arc, length) of the triangles ``corners`` (m, 3) of ``bone`` around its axis."""
    origin, axis = _bone_axis(joints, bone)
    along, front, side = _frame(axis)
    d = points[corners] - origin  # (m, 3, 3)
    radius = float(np.median(np.linalg.norm(d - (d @ along)[..., None] * along, axis=-1))) or 0.05
    angle = np.arctan2(d @ side, d @ front)
    # a triangle across the back seam (angle +-pi): its corners on the negative side go once round
    across = (angle.max(axis=1) - angle.min(axis=1)) > np.pi
    angle = np.where(across[:, None] & (angle < 0), angle + 2 * np.pi, angle)
    return np.stack([angle * radius, d @ along], axis=-1)


def _face(bank: Bank, body: int, corners: np.ndarray) -> np.ndarray:
    """(m, 3, 2) face-image st of the head's triangles ``corners`` (see the module's docstring)."""
    points, keys = bank.points[body], bank.keypoints[body]
    eyes = keys[list(_EYES)]
    centre_xy = keys[list(_EARS), :2].mean(axis=0)
    mid = eyes.mean(axis=0)
    radius = float(np.linalg.norm(mid[:2] - centre_xy))
    facing = np.arctan2(*(mid[:2] - centre_xy)[::-1])
    half = float(np.linalg.norm(eyes[0] - eyes[1])) / 2
    drop = max(float(mid[2] - keys[_NOSE, 2]), 1e-3)
    p = points[corners]
    angle = np.arctan2(p[..., 1] - centre_xy[1], p[..., 0] - centre_xy[0]) - facing
    angle = (angle + np.pi) % (2 * np.pi) - np.pi
    s = angle * radius * EYE_HALF_SPACING_M / half
    t = (p[..., 2] - mid[2]) * EYE_TO_NOSE_M / drop
    return np.stack([s, t], axis=-1) / FACE_SPAN_M + 0.5


def _shoe(points: np.ndarray, joints: np.ndarray, bone: str, corners: np.ndarray) -> np.ndarray:
    """(m, 3, 2) metres (along the foot from its joint, height above the ground) of the foot's triangles."""
    p = points[corners]
    return np.stack([p[..., 0] - joints[BONES.index(bone), 0], p[..., 2]], axis=-1)


@functools.lru_cache(maxsize=128)
def corner_uvs(bank: Bank, body: int) -> np.ndarray:
    """(F, 3, 2) float32 st of every corner of ``bank.triangles`` of ``body`` (the face, shoe and fabric
    mappings of the module's docstring, chosen by each triangle's dominant bone); read-only."""
    points, joints = bank.points[body], bank.joints[body]
    out = np.zeros((len(bank.triangles), 3, 2))
    for k, bone in enumerate(BONES):
        mine = np.flatnonzero(bank.face_bone == k)
        if not len(mine):
            continue
        corners = bank.triangles[mine]
        if bone == "head":
            out[mine] = _face(bank, body, corners)
        elif bone in _FEET:
            out[mine] = _shoe(points, joints, bone, corners) / SHOE_TILE_M + [AWAY, 0.0]
        else:
            out[mine] = _fabric(points, joints, bone, corners) / FABRIC_TILE_M + [AWAY, 0.0]
    out = out.astype(np.float32)
    out.flags.writeable = False
    return out
