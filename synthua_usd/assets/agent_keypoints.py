"""Keypoints of a posed agent, consistent with the geometry that renders: the 17 COCO body keypoints and
the contact points of its mobility aid (names: :mod:`synthua_usd.model.keypoint_classes`).

The rendered body is its base posture's skinned mesh moved rigidly per segment
(:func:`synthua_usd.assets.postures.segment_motion`), so a keypoint is computed the same way: the bank's
keypoint (anny's COCO regressor on the rest body) skinned into the base posture with its bone weights,
then moved by the blend of its segments' rigid motions at that time, weighted by the keypoint's bone
weights summed per segment (a wrist, 0.59 hand and 0.41 forearm, moves with the forearm segment, which
holds both; a knee, half thigh and half shank, lies between the two pieces while they swing).

Contact points, in the agent's frame (the user faces +X; :data:`synthua_usd.assets.postures.AID_OFFSETS`
places the aid):

- a hand on the aid (push rim, walker handle, crutch or cane grip, joystick): the centroid of that hand's
  rendered vertices (those whose dominant bone is the hand) at that time;
- the seat: the point of the seat's top (the fitted seat height) under the midpoint of the hip joints;
- a crutch or cane tip: the centre of the aid's lowest points (within 5 mm of its bottom; the three feet of a
  tripod cane together) at each placement, where it stands on the ground.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.assets import devices
from synthua_usd.assets.bodies import BONES, SEGMENTS, Bank, Pose, skin, skin_keypoints
from synthua_usd.assets.postures import AID_OFFSETS, DeviceFit
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES

#: How far above its lowest point a device point still counts as its tip, metres.
TIP_BAND_M = 0.005


def _apply(motion: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(n, 3) ``points`` moved by the rigid ``motion`` (3, 4)."""
    return points @ motion[:, :3].T + motion[:, 3]


def segment_weights(bank: Bank) -> np.ndarray:
    """(17, 9) weight of each segment (order of :data:`SEGMENTS`) in each COCO keypoint: its bone weights
    summed over the segment's bones."""
    out = np.zeros((bank.keypoint_bones.shape[0], len(SEGMENTS)))
    for s, (bones, _) in enumerate(SEGMENTS.values()):
        out[:, s] = bank.keypoint_bones[:, [BONES.index(b) for b in bones]].sum(axis=1)
    return out / out.sum(axis=1, keepdims=True)


def body_keypoints(bank: Bank, body: int, base: Pose, motions: list[dict[str, np.ndarray]]) -> np.ndarray:
    """(T, 17, 3) COCO keypoints of ``body`` in its base posture ``base`` moved by ``motions`` (one
    :func:`segment_motion` dict per time code), agent frame."""
    rest = base.skinning(bank.joints[body])
    at_base = skin_keypoints(bank.keypoints[body], bank, rest)
    weights = segment_weights(bank)
    out = np.zeros((len(motions), len(at_base), 3))
    for t, motion in enumerate(motions):
        for s, name in enumerate(SEGMENTS):
            out[t] += weights[:, s, None] * _apply(motion[name], at_base)
    return out


def _hand_centroid(bank: Bank, body: int, base: Pose, side: str) -> np.ndarray:
    """(3,) centroid of the vertices whose dominant skin bone is ``hand.{side}``, skinned into ``base``."""
    bone = BONES.index(f"hand.{side}")
    dominant = bank.skin_bones[np.arange(len(bank.skin_bones)), bank.skin_weights.argmax(axis=1)]
    pts = skin(bank.points[body], bank, base.skinning(bank.joints[body]))
    return pts[dominant == bone].mean(axis=0)


def _tips(device: str, fit: DeviceFit) -> list[np.ndarray]:
    """The ground contact of ``device`` at each of its placements, agent frame."""
    points = np.concatenate([p.points for p in devices.DEVICES[device](fit)])
    low = points[points[:, 2] <= points[:, 2].min() + TIP_BAND_M]
    centre = np.array([low[:, 0].mean(), low[:, 1].mean(), points[:, 2].min()])
    return [centre + [dx, dy, 0.0] for dx, dy in AID_OFFSETS[device]]


def contact_points(bank: Bank, body: int, device: str, fit: DeviceFit, base: Pose,
                   motions: list[dict[str, np.ndarray]], shifts=None) -> np.ndarray:
    """(T, k, 3) contact points of ``device`` used by ``body``, in the order of
    ``KEYPOINT_CLASSES[device].names``, agent frame. ``shifts`` (T,): a stepping aid's forward shift along the
    agent's +x at each time (:func:`synthua_usd.assets.postures.aid_shift_m`), which moves its tips; the
    hands' motions already include it."""
    names = KEYPOINT_CLASSES[device].names
    hands = {side: _hand_centroid(bank, body, base, side) for side in ("L", "R")}
    hips = base.joints[[BONES.index("upperleg.L"), BONES.index("upperleg.R")]].mean(axis=0)
    tips = _tips(device, fit) if device in AID_OFFSETS else []
    out = np.zeros((len(motions), len(names), 3))
    for t, motion in enumerate(motions):
        for k, name in enumerate(names):
            if name == "seat":
                pelvis = _apply(motion["Torso"], hips[None])[0]
                out[t, k] = [pelvis[0], pelvis[1], fit.seat_height_m]
            elif name.endswith("tip"):
                out[t, k] = tips[1 if name == "right_tip" else 0]  # crutches: left placement first
                if shifts is not None:
                    out[t, k, 0] += shifts[t]
            else:
                side = "L" if name.startswith(("left", "joystick")) else "R"
                out[t, k] = _apply(motion[f"Forearm{side}"], hands[side][None])[0]
    return out
