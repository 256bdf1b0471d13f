"""People's bodies from the body bank (:mod:`synthua_usd.assets.body_bank`), posed without torch or anny.

Frames: a body stands with its feet on z = 0 and faces +X, +Y to its left, metres. Posing is linear blend
skinning on the bank's reduced rig of 14 bones (:data:`body_bank.REDUCED_BONES`) with *world-aligned* joint
frames: a posture gives each bone a world rotation (a bone without one keeps its parent's), the joints
follow by forward kinematics from the rest joints, and a vertex moves by the blend of its bones'
``[R_b | p_b - R_b j_b]``. Limbs are aimed by two-bone inverse kinematics (hand on a handle, foot on a rest).

Animation is rigid per segment: a body is cut into nine segments (torso with head, thighs, shanks with feet,
upper arms, forearms with hands) by the dominant bone of each triangle. A *base posture* (standing, seated,
holding a walker, ...) is skinned properly; each time code moves every segment rigidly by its primary
bone's motion from the base posture (walking swings, push strokes). Segments are therefore shared between
agents of one body and posture (USD instancing) and only a translate and an orientation per segment and
time code are stored; the price is small gaps and overlaps at hips, knees, shoulders and elbows while they
swing (no blending across segments at animated time codes).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from synthua_usd.assets import body_bank

BONES = tuple(b[0] for b in body_bank.REDUCED_BONES)
PARENT = {"torso": None, "head": "torso", "upperleg.L": "torso", "upperleg.R": "torso", "lowerleg.L": "upperleg.L",
          "lowerleg.R": "upperleg.R", "foot.L": "lowerleg.L", "foot.R": "lowerleg.R", "upperarm.L": "torso",
          "upperarm.R": "torso", "lowerarm.L": "upperarm.L", "lowerarm.R": "upperarm.R", "hand.L": "lowerarm.L",
          "hand.R": "lowerarm.R"}
#: Index into BONES of each bone's parent (the root's own index for the root).
_PARENT_INDEX = tuple(k if PARENT[b] is None else BONES.index(PARENT[b]) for k, b in enumerate(BONES))
#: Segment name -> (bones it holds, its primary bone whose motion moves it).
SEGMENTS = {
    "Torso": (("torso", "head"), "torso"),
    "ThighL": (("upperleg.L",), "upperleg.L"), "ThighR": (("upperleg.R",), "upperleg.R"),
    "ShankL": (("lowerleg.L", "foot.L"), "lowerleg.L"), "ShankR": (("lowerleg.R", "foot.R"), "lowerleg.R"),
    "UpperArmL": (("upperarm.L",), "upperarm.L"), "UpperArmR": (("upperarm.R",), "upperarm.R"),
    "ForearmL": (("lowerarm.L", "hand.L"), "lowerarm.L"), "ForearmR": (("lowerarm.R", "hand.R"), "lowerarm.R"),
}
#: Garment regions: which look colour each region takes (skin, upper garment, lower garment, shoes); the
#: forearm and shin regions take the skin or the garment by the look's sleeve and leg length.
REGIONS = ("skin", "upper", "forearm", "lower", "shin", "shoes")
#: A segment also draws its neighbours' triangles whose corners its bones hold with at least this weight
#: (:attr:`Bank.segment_faces`).
OVERLAP_WEIGHT = 0.3

# anny faces -Y with +X to its left; ours face +X with +Y to the left: a quarter turn about Z.
_TO_OURS = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


@dataclass(frozen=True, eq=False)
class Bank:
    """The bank in our frame. ``points`` (B, V, 3) float64 rest vertices, ``joints`` (B, 14, 3) rest joints,
    ``keypoints`` (B, 17, 3) rest COCO keypoints; ``triangles`` (F, 3) int64 shared; ``skin_bones`` (V, 4)
    and ``skin_weights`` (V, 4) shared; ``keypoint_bones`` (17, 14) bone weights of each keypoint;
    per body ``years``, ``female``, ``aid_stratum``, ``height_m``, ``mass_kg``."""

    points: np.ndarray
    joints: np.ndarray
    keypoints: np.ndarray
    triangles: np.ndarray
    skin_bones: np.ndarray
    skin_weights: np.ndarray
    keypoint_bones: np.ndarray
    years: np.ndarray
    female: np.ndarray
    aid_stratum: np.ndarray
    height_m: np.ndarray
    mass_kg: np.ndarray

    def __len__(self) -> int:
        return len(self.points)

    @functools.cached_property
    def vertex_bone_weights(self) -> np.ndarray:
        """(V, 14) skin weight of every bone of :data:`BONES` at each vertex."""
        dense = np.zeros((self.points.shape[1], len(BONES)))
        np.add.at(dense, (np.repeat(np.arange(len(dense)), 4), self.skin_bones.ravel()), self.skin_weights.ravel())
        return dense

    @functools.cached_property
    def face_bone(self) -> np.ndarray:
        """(F,) index into :data:`BONES` of the bone that dominates each triangle."""
        return self.vertex_bone_weights[self.triangles].sum(axis=1).argmax(axis=1)

    @functools.cached_property
    def face_segment(self) -> np.ndarray:
        """(F,) index into :data:`SEGMENTS` of each triangle."""
        seg_of_bone = {b: k for k, (bones, _) in enumerate(SEGMENTS.values()) for b in bones}
        return np.array([seg_of_bone[BONES[b]] for b in self.face_bone])

    def segment_faces(self, body: int) -> np.ndarray:
        """(9, F) bool: the triangles each segment of :data:`SEGMENTS` renders for ``body``: its own, and the
        triangles of its neighbours that its bones hold with at least :data:`OVERLAP_WEIGHT` at some corner
        and that lie in a garment region the segment already has (so it needs no mesh more). Those are drawn
        by both segments (coinciding in the base posture), so that a bending hip or shoulder shows a
        segment's copy instead of a gap into the hollow body."""
        if body not in self._segment_faces:  # kept per body, read-only: a posed body asks for it once a segment
            own, held = self._own_and_held
            region = self.face_region(body)
            has_region = np.stack([np.isin(region, region[own[k]]) for k in range(len(SEGMENTS))])
            faces = own | (held & has_region)
            faces.flags.writeable = False
            self._segment_faces[body] = faces
        return self._segment_faces[body]

    @functools.cached_property
    def _segment_faces(self) -> dict[int, np.ndarray]:
        return {}

    @functools.cached_property
    def _own_and_held(self) -> tuple[np.ndarray, np.ndarray]:
        """(9, F) bool each: a segment's own triangles, and those its bones hold with OVERLAP_WEIGHT at a corner
        (the same for every body: one mesh topology and skinning)."""
        own = np.arange(len(SEGMENTS))[:, None] == self.face_segment[None]
        per_segment = np.stack([self.vertex_bone_weights[:, [BONES.index(b) for b in bones]].sum(axis=1)
                                for bones, _ in SEGMENTS.values()])  # (9, V)
        return own, per_segment[:, self.triangles].max(axis=2) >= OVERLAP_WEIGHT

    def face_region(self, body: int) -> np.ndarray:
        """(F,) index into :data:`REGIONS` of each triangle of ``body``: skin on head and hands, shoes on feet,
        the lower garment below the waist (a little above the hip joints), the upper garment above."""
        bone = np.array(BONES)[self.face_bone]
        centre_z = self.points[body][self.triangles].mean(axis=1)[:, 2]
        waist_z = self.joints[body, BONES.index("torso"), 2] + 0.06 * self.height_m[body]
        region = np.full(len(bone), REGIONS.index("upper"))
        region[np.isin(bone, ["head", "hand.L", "hand.R"])] = REGIONS.index("skin")
        region[np.isin(bone, ["lowerarm.L", "lowerarm.R"])] = REGIONS.index("forearm")
        region[np.isin(bone, ["upperleg.L", "upperleg.R"]) | ((bone == "torso") & (centre_z < waist_z))] = REGIONS.index("lower")
        region[np.isin(bone, ["lowerleg.L", "lowerleg.R"])] = REGIONS.index("shin")
        region[np.isin(bone, ["foot.L", "foot.R"])] = REGIONS.index("shoes")
        return region


@functools.lru_cache(maxsize=1)
def load_bank() -> Bank:
    """The shipped bank (read once per process)."""
    with np.load(body_bank.BANK_PATH) as raw:
        turn = lambda a: np.asarray(a, np.float64) @ _TO_OURS.T  # noqa: E731
        return Bank(points=turn(raw["points"]), joints=turn(raw["joints"]), keypoints=turn(raw["keypoints"]),
                    triangles=raw["triangles"].astype(np.int64), skin_bones=raw["skin_bones"].astype(np.int64),
                    skin_weights=raw["skin_weights"].astype(np.float64), keypoint_bones=raw["keypoint_bones"].astype(np.float64),
                    years=raw["years"], female=raw["female"], aid_stratum=raw["aid_stratum"], height_m=raw["height_m"],
                    mass_kg=raw["mass_kg"])


def rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation (3, 3) taking direction ``a`` to direction ``b``."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    v = np.cross(a, b)
    c = float(np.dot(a, b))
    if c < -0.999999:  # opposite: half a turn about any perpendicular
        axis = np.cross(a, [1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.cross(a, [0.0, 1.0, 0.0])
        axis /= np.linalg.norm(axis)
        return 2.0 * np.outer(axis, axis) - np.eye(3)
    k = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + k + k @ k / (1.0 + c)


def rot_y(deg: float) -> np.ndarray:
    a = np.radians(deg)
    return np.array([[np.cos(a), 0.0, np.sin(a)], [0.0, 1.0, 0.0], [-np.sin(a), 0.0, np.cos(a)]])


@dataclass(frozen=True, eq=False)
class Pose:
    """World rotations ``rotations`` (14, 3, 3) and posed joints ``joints`` (14, 3) of one body, body frame."""

    rotations: np.ndarray
    joints: np.ndarray

    def skinning(self, rest_joints: np.ndarray) -> np.ndarray:
        """(14, 3, 4) bone matrices ``[R_b | p_b - R_b j_b]``."""
        t = self.joints - np.einsum("bij,bj->bi", self.rotations, rest_joints)
        return np.concatenate([self.rotations, t[:, :, None]], axis=2)


def forward_kinematics(rest_joints: np.ndarray, aims: dict[str, np.ndarray], root: np.ndarray | None = None) -> Pose:
    """Pose from world rotations ``aims`` (bone -> (3, 3)); bones not named keep their parent's rotation.
    ``root`` moves the torso joint (default: where it rests)."""
    rots = np.zeros((len(BONES), 3, 3))
    joints = np.zeros((len(BONES), 3))
    offsets = rest_joints - rest_joints[list(_PARENT_INDEX)]  # each bone's rest joint from its parent's (the root's: 0)
    for k, bone in enumerate(BONES):  # parents come first in BONES
        p = _PARENT_INDEX[k]
        if p == k:
            rots[k] = aims.get(bone, np.eye(3))
            joints[k] = rest_joints[k] if root is None else root
            continue
        rots[k] = aims.get(bone, rots[p])
        joints[k] = joints[p] + rots[p] @ offsets[k]
    return Pose(rots, joints)


def two_bone_aims(rest_joints: np.ndarray, upper: str, lower: str, end: str, start: np.ndarray, target: np.ndarray,
                  pole: np.ndarray, parent_rotation: np.ndarray) -> dict[str, np.ndarray]:
    """World rotations of ``upper`` and ``lower`` putting the ``end`` joint on ``target`` (or as near as the
    limb reaches) from the posed ``start`` joint, bending towards ``pole``."""
    iu, il, ie = (BONES.index(b) for b in (upper, lower, end))
    a = float(np.linalg.norm(rest_joints[il] - rest_joints[iu]))
    b = float(np.linalg.norm(rest_joints[ie] - rest_joints[il]))
    to = target - start
    d = float(np.clip(np.linalg.norm(to), abs(a - b) + 1e-4, a + b - 1e-4))
    u = to / np.linalg.norm(to)
    v = pole - np.dot(pole, u) * u
    v /= np.linalg.norm(v)
    cos_a = (a * a + d * d - b * b) / (2 * a * d)
    elbow = start + a * (cos_a * u + np.sqrt(max(0.0, 1 - cos_a * cos_a)) * v)
    hand = start + d * u
    ru = rotation_between(parent_rotation @ (rest_joints[il] - rest_joints[iu]), elbow - start) @ parent_rotation
    rl = rotation_between(ru @ (rest_joints[ie] - rest_joints[il]), hand - elbow) @ ru
    return {upper: ru, lower: rl}


def skin(points: np.ndarray, bank: Bank, matrices: np.ndarray, vertices: np.ndarray | None = None) -> np.ndarray:
    """Linear blend skinning of ``points`` (V, 3) by bone ``matrices`` (14, 3, 4): (V, 3); only ``vertices``
    ((n,) int indices, n >= 2) if given: (n, 3), the same values as those rows of the whole (each vertex's
    sums are its own, whatever else is skinned; tests/assets/test_bodies.py checks it bit for bit)."""
    weights, bones = bank.skin_weights, bank.skin_bones
    if vertices is not None:
        points, weights, bones = points[vertices], weights[vertices], bones[vertices]
    m = np.einsum("vk,vkij->vij", weights, matrices[bones])
    return np.einsum("vij,vj->vi", m[:, :, :3], points) + m[:, :, 3]


def skin_keypoints(keypoints: np.ndarray, bank: Bank, matrices: np.ndarray) -> np.ndarray:
    """The 17 COCO keypoints (17, 3) posed with their bone weights."""
    m = np.einsum("kb,bij->kij", bank.keypoint_bones, matrices)
    return np.einsum("kij,kj->ki", m[:, :, :3], keypoints) + m[:, :, 3]
