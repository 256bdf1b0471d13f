"""Which classes have keypoints, their names, skeleton and OKS sigmas: the one owner of these facts.

A person has COCO's 17 body keypoints, in COCO's order, with COCO's skeleton and per-keypoint OKS sigmas
(``pycocotools.cocoeval.Params.kpt_oks_sigmas``). A mobility aid has *contact points*: where its user
touches it (hands on push rims, handles, grips or the joystick; the seat under the pelvis) and where it
touches the ground (crutch and cane tips). Their OKS sigmas are ours, chosen by analogy with COCO's: a hand
on the device as a wrist (0.062), the seat contact as a hip (0.107), a tip on the ground as an ankle (0.089).
COCOeval takes one sigma array for all categories, so a device category is evaluated on its own
(``params.catIds = [id]``, ``params.kpt_oks_sigmas = sigmas(name)``).

Skeletons are COCO's 1-based index pairs into the names.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: COCO's 17 person keypoints, in COCO's order (anny's keypoint regressor names them so too).
PERSON_KEYPOINTS = ("nose", "left_eye", "right_eye", "left_ear", "right_ear", "left_shoulder", "right_shoulder",
                    "left_elbow", "right_elbow", "left_wrist", "right_wrist", "left_hip", "right_hip", "left_knee",
                    "right_knee", "left_ankle", "right_ankle")
PERSON_SKELETON = ((16, 14), (14, 12), (17, 15), (15, 13), (12, 13), (6, 12), (7, 13), (6, 7), (6, 8), (7, 9),
                   (8, 10), (9, 11), (2, 3), (1, 2), (1, 3), (2, 4), (3, 5), (4, 6), (5, 7))
#: COCO's OKS sigmas of the 17 person keypoints (pycocotools' defaults).
PERSON_SIGMAS = (.026, .025, .025, .035, .035, .079, .079, .072, .072, .062, .062, .107, .107, .087, .087, .089, .089)

_HAND, _SEAT, _TIP = 0.062, 0.107, 0.089


@dataclass(frozen=True)
class KeypointClass:
    """The keypoints of one class: ``names``, ``skeleton`` (1-based pairs) and OKS ``sigmas`` per name."""

    names: tuple[str, ...]
    skeleton: tuple[tuple[int, int], ...]
    sigmas: tuple[float, ...]

    def coco_category_fields(self) -> dict:
        """The ``keypoints`` and ``skeleton`` fields of a COCO category."""
        return {"keypoints": list(self.names), "skeleton": [list(pair) for pair in self.skeleton]}


_CANE = KeypointClass(("hand_grip", "tip"), ((1, 2),), (_HAND, _TIP))

#: Class name (as in the class map) -> its keypoints.
KEYPOINT_CLASSES: dict[str, KeypointClass] = {
    "person": KeypointClass(PERSON_KEYPOINTS, PERSON_SKELETON, PERSON_SIGMAS),
    "manual_wheelchair": KeypointClass(("left_hand_rim", "right_hand_rim", "seat"), ((1, 3), (2, 3)),
                                       (_HAND, _HAND, _SEAT)),
    "electric_wheelchair": KeypointClass(("joystick_hand", "seat"), ((1, 2),), (_HAND, _SEAT)),
    "walker": KeypointClass(("left_hand_handle", "right_hand_handle"), ((1, 2),), (_HAND, _HAND)),
    "crutch": KeypointClass(("left_hand_grip", "right_hand_grip", "left_tip", "right_tip"), ((1, 3), (2, 4)),
                            (_HAND, _HAND, _TIP, _TIP)),
    "smart_cane": _CANE, "wooden_cane": _CANE, "orthopedic_cane": _CANE, "tripod_cane": _CANE,
}


def sigmas(class_name: str) -> np.ndarray:
    """OKS sigmas of ``class_name``'s keypoints, for ``COCOeval.params.kpt_oks_sigmas``."""
    return np.array(KEYPOINT_CLASSES[class_name].sigmas)
