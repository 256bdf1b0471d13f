"""Postures and motion of a bank body with its mobility aid, and the aid's size fitted to that body.

A posture is a function of the body, its device fit and a cycle phase: walking (stride and cadence from
the speed), walking with a walker (both hands on its handles), with forearm crutches (hands on the grips),
with a cane (cane hand on its grip), seated in a manual wheelchair (hands on the push rims, a push cycle),
seated in an electric wheelchair (left hand on the joystick), seated on a bench (hands on the thighs, feet on
the ground), and walking behind a manual wheelchair pushing it (both hands on its push handles). Frames as in
:mod:`bodies`: feet on z = 0 (standing), facing +X; a seated body sits on the seat
its :class:`DeviceFit` gives, its back at x = -0.15.

Fitting follows clinical practice: cane, crutch and walker grips at the wrist crease of the standing user
with the arms hanging; the wheelchair seat at the user's seated lower-leg drop plus the footrest's ground
clearance, as wide as the hips plus 2 cm a side.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache

import numpy as np

from synthua_usd.assets.bodies import (BONES, REGIONS, SEGMENTS, Bank, Pose, forward_kinematics, load_bank, rot_y,
                                       rotation_between, skin, two_bone_aims)
from synthua_usd.assets.garments import corner_uvs
from synthua_usd.assets.hair import hair_mesh
from synthua_usd.model import meshes as geo

#: Walk ratio (step length / cadence) of adults, m per (steps/min), for a 1.7 m person (Sekiya & Nagasaki 1998).
WALK_RATIO = 0.0064
FOOTREST_CLEARANCE_M = 0.08
#: Wheelchair rear wheels: centre behind the seat's origin, radius of the push rim.
REAR_WHEEL_X = -0.1
RIM_RADIUS_M = 0.27
#: Where each walking aid stands relative to its user (user faces +X): offsets per device.
AID_OFFSETS = {"walker": [(0.42, 0.0)], "crutch": [(0.14, 0.3), (0.14, -0.3)], "smart_cane": [(0.3, -0.25)],
               "wooden_cane": [(0.14, -0.3)], "orthopedic_cane": [(0.14, -0.3)], "tripod_cane": [(0.14, -0.32)]}
SEATED = ("manual_wheelchair", "electric_wheelchair")
#: The posture of a pedestrian seated on a bench (not a device: no device prim; :func:`bench_fit` sizes it).
BENCH = "bench"
CANES = ("smart_cane", "wooden_cane", "orthopedic_cane", "tripod_cane")
#: Aids whose tips step with the gait (:func:`aid_shift_m`): planted on the ground in the middle of the left
#: foot's stance (phase pi/2 .. 3 pi/2), swung forward while the left leg swings. A cane in the right hand
#: moves with the left leg; forearm crutches move together with it (three-point gait, the left leg taken
#: as the affected one). Planted for AID_STANCE of the cycle: shorter than the foot's half, so that the
#: hand reaches the grip at both ends of the stroke.
STEPPING_AIDS = ("crutch",) + CANES
AID_STANCE = 0.4
AID_STANCE_START = np.pi - AID_STANCE * np.pi
#: Where the hand holds a stepping aid: its grip's distance ahead of the aid's origin, m.
GRIP_DX = {"crutch": 0.08, **{cane: -0.03 for cane in CANES}}
#: The posture of a companion walking behind a manual wheelchair with both hands on its push handles (not a
#: device of its own: its fit is the pushed chair's, :func:`push_handles`).
PUSHING = "pushing"
#: A manual wheelchair's push handles in its frame: where the hand grips them, behind the backrest
#: (x, metres; inside the grips of both models, :mod:`synthua_usd.assets.devices`) and above the seat top (z).
PUSH_HANDLE_X = -0.29
PUSH_HANDLE_DZ = 0.46
#: How far behind the pushed chair's origin its pusher's origin walks, m: the handles 0.35 m ahead of the pusher.
PUSH_DISTANCE_M = 0.64


@dataclass(frozen=True)
class DeviceFit:
    """Sizes of a device fitted to its user, metres (rounded to 1 cm so users of one size share a device)."""

    grip_height_m: float = 0.85
    seat_height_m: float = 0.45
    seat_width_m: float = 0.46

    def key(self) -> str:
        return f"{round(self.grip_height_m * 100)}_{round(self.seat_height_m * 100)}_{round(self.seat_width_m * 100)}"


def _arms_down(rest: np.ndarray) -> dict[str, np.ndarray]:
    """Upper arms from the bank's A pose to hanging 7 degrees out from the body, forearms 10 degrees forward."""
    out = {}
    for side, sign in (("L", 1.0), ("R", -1.0)):
        up, low, hand = (BONES.index(f"{b}.{side}") for b in ("upperarm", "lowerarm", "hand"))
        ru = rotation_between(rest[low] - rest[up], np.array([0.0, sign * 0.12, -1.0]))
        out[f"upperarm.{side}"] = ru
        out[f"lowerarm.{side}"] = rot_y(-10.0) @ rotation_between(ru @ (rest[hand] - rest[low]), np.array([0.0, sign * 0.05, -1.0])) @ ru
    return out


def _standing(bank: Bank, body: int) -> Pose:
    rest = bank.joints[body]
    return forward_kinematics(rest, _arms_down(rest))


def fit_device(bank: Bank, body: int, device: str | None) -> DeviceFit:
    """The device of class ``device`` sized to ``body``."""
    if device == PUSHING:
        raise ValueError("the pushing posture has no device of its own: pass the pushed chair's fit")
    if device is None:
        return DeviceFit()
    rest = bank.joints[body]
    if device in SEATED:
        pose = _seated_legs(bank, body, 0.0)
        pts = skin(bank.points[body], bank, pose.skinning(rest))
        hips = _hip_vertices(bank, pts, pose)
        drop = float(pts[hips, 2].min() - pts[_segment_vertices(bank, ("ShankL", "ShankR")), 2].min())
        width = float(np.ptp(pts[hips, 1]))
        return DeviceFit(seat_height_m=round(float(np.clip(drop + FOOTREST_CLEARANCE_M, 0.3, 0.62)), 2),
                         seat_width_m=round(width + 0.04, 2))
    wrist = _standing(bank, body).joints[BONES.index("hand.R"), 2]
    return DeviceFit(grip_height_m=round(float(wrist), 2))


def _segment_vertices(bank: Bank, names) -> np.ndarray:
    seg = [list(SEGMENTS).index(n) for n in names]
    return np.unique(bank.triangles[np.isin(bank.face_segment, seg)])


def _hip_vertices(bank: Bank, pts: np.ndarray, pose: Pose) -> np.ndarray:
    """Vertices of the torso and thighs within 0.15 m (along X) of the hip joints: what sits on a seat."""
    cand = _segment_vertices(bank, ("Torso", "ThighL", "ThighR"))
    hip_x = pose.joints[BONES.index("upperleg.L"), 0]
    return cand[np.abs(pts[cand, 0] - hip_x) < 0.15]


def _seated_legs(bank: Bank, body: int, root_z: float, shank_deg: float = 12.0) -> Pose:
    """Thighs level, shanks ``shank_deg`` forward of vertical, arms hanging."""
    rest = bank.joints[body]
    aims = _arms_down(rest)
    for side in ("L", "R"):
        aims[f"upperleg.{side}"] = rot_y(-86.0)
        aims[f"lowerleg.{side}"] = rot_y(-shank_deg)
        aims[f"foot.{side}"] = rot_y(-12.0)
    root = rest[0] + np.array([0.0, 0.0, root_z])
    return forward_kinematics(rest, aims, root)


def _seat_drop(bank: Bank, body: int, shank_deg: float) -> float:
    """Seated with shanks ``shank_deg`` forward: how far the feet reach below what sits on the seat, m."""
    pose = _seated_legs(bank, body, 0.0, shank_deg)
    pts = skin(bank.points[body], bank, pose.skinning(bank.joints[body]))
    return float(pts[_hip_vertices(bank, pts, pose), 2].min() - pts[_segment_vertices(bank, ("ShankL", "ShankR")), 2].min())


def _bench_shank_deg(bank: Bank, body: int, seat_height_m: float) -> float:
    """The shank angle (12-70 degrees forward) that puts the feet on the ground below a seat ``seat_height_m``
    high; 12 when they do not reach it (a child's feet dangle)."""
    lo, hi = 12.0, 70.0
    if _seat_drop(bank, body, lo) <= seat_height_m:
        return lo
    for _ in range(20):  # the drop falls as the shanks tilt forward
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if _seat_drop(bank, body, mid) > seat_height_m else (lo, mid)
    return hi


def push_handles(fit: DeviceFit) -> np.ndarray:
    """(2, 3) where the hands grip a manual wheelchair of ``fit``'s push handles (left, then right; chair frame,
    metres): behind the backrest at :data:`PUSH_HANDLE_X`, :data:`PUSH_HANDLE_DZ` above the seat top, over the
    seat's sides."""
    y = fit.seat_width_m / 2 + 0.005
    z = fit.seat_height_m + PUSH_HANDLE_DZ
    return np.array([[PUSH_HANDLE_X, y, z], [PUSH_HANDLE_X, -y, z]])


#: Share of the arm's length (shoulder to wrist, straight) at which a pusher holds the handles.
PUSH_REACH = 0.97
#: The most a pusher leans forward to reach the handles, degrees.
MAX_PUSH_LEAN_DEG = 35.0


def push_lean_deg(bank: Bank, body: int, fit: DeviceFit) -> float:
    """How far (degrees, about the pelvis) ``body`` leans forward to hold the push handles of a chair of ``fit``
    :data:`PUSH_DISTANCE_M` ahead with its arms at :data:`PUSH_REACH` of their length: 0 when it reaches them
    upright, more for a tall person over low handles (at most :data:`MAX_PUSH_LEAN_DEG`). From the rest joints
    (standing), whatever the gait phase, so one pusher leans the same at every step."""
    rest = bank.joints[body]
    root, shoulder = rest[0], rest[BONES.index("upperarm.L")]
    arm = (np.linalg.norm(rest[BONES.index("lowerarm.L")] - shoulder)
           + np.linalg.norm(rest[BONES.index("hand.L")] - rest[BONES.index("lowerarm.L")]))
    handle = push_handles(fit)[0] + np.array([PUSH_DISTANCE_M, 0.0, 0.0])

    def short(deg: float) -> float:  # > 0 while the handle is out of reach
        return float(np.linalg.norm(handle - (root + rot_y(deg) @ (shoulder - root)))) - PUSH_REACH * arm

    if short(0.0) <= 0.0:
        return 0.0
    if short(MAX_PUSH_LEAN_DEG) > 0.0:
        return MAX_PUSH_LEAN_DEG
    lo, hi = 0.0, MAX_PUSH_LEAN_DEG
    for _ in range(30):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if short(mid) > 0.0 else (lo, mid)
    return hi


def bench_fit(seat_height_m: float) -> DeviceFit:
    """The fit of a bench posture: the seat's top above the ground the sitter's feet stand on."""
    return DeviceFit(seat_height_m=round(float(seat_height_m), 2))


def _with_arms(bank: Bank, body: int, pose: Pose, targets: dict[str, np.ndarray], aims: dict) -> Pose:
    """``pose`` with the named hands ("L", "R") on ``targets`` (body frame) by two-bone IK."""
    rest = bank.joints[body]
    aims = dict(aims)
    for side, target in targets.items():
        sign = 1.0 if side == "L" else -1.0
        shoulder = pose.joints[BONES.index(f"upperarm.{side}")]
        aims.update(two_bone_aims(rest, f"upperarm.{side}", f"lowerarm.{side}", f"hand.{side}", shoulder, target,
                                  np.array([-1.0, sign * 0.6, 0.0]), pose.rotations[0]))
    root = pose.joints[0]
    return forward_kinematics(rest, aims, root)


def step_length_m(speed_mps: float, height_m: float) -> float:
    """Step length from speed: cadence c (steps/min) and step length W c (W the walk ratio, scaled by height)
    give speed W c² / 60."""
    w = WALK_RATIO * height_m / 1.7
    cadence = np.sqrt(60.0 * max(speed_mps, 0.05) / w)
    return float(w * cadence)


def aid_shift_m(device: str | None, phase: float, amplitude: float, cycle_m: float) -> float:
    """How far (m, along the user's heading) a stepping aid (:data:`STEPPING_AIDS`) stands ahead of its
    place in :data:`AID_OFFSETS` at gait ``phase``, for a gait cycle of ``cycle_m`` metres travelled (phase
    2 pi per cycle). Planted for :data:`AID_STANCE` of the cycle from :data:`AID_STANCE_START`: the shift
    falls by exactly the distance the user travels, so the tip stays put on the ground; then it swings
    forward again (smoothstep, the tip gliding along the ground). The stroke, ``amplitude * AID_STANCE *
    cycle_m`` long, is centred so that the grip passes under the shoulder (x = 0), where the hand reaches
    furthest both ways. 0 for other devices."""
    if device not in STEPPING_AIDS:
        return 0.0
    travel = amplitude * AID_STANCE * cycle_m  # while planted
    centre = -amplitude * (AID_OFFSETS[device][0][0] + GRIP_DX[device])
    u = ((phase - AID_STANCE_START) / (2 * np.pi)) % 1.0
    if u < AID_STANCE:
        return centre + travel * (0.5 - u / AID_STANCE)
    v = (u - AID_STANCE) / (1.0 - AID_STANCE)
    return centre + travel * (v * v * (3 - 2 * v) - 0.5)


#: A posture of one body and fit: (phase, amplitude, aid_shift) -> the body's pose (:func:`pose`'s last three).
PostureCycle = Callable[[float, float, float], Pose]


def pose(bank: Bank, body: int, device: str | None, fit: DeviceFit, phase: float, amplitude: float,
         aid_shift: float = 0.0) -> Pose:
    """The body's pose at cycle ``phase`` (radians; gait cycle walking, push cycle in a manual chair) with
    the motion scaled by ``amplitude`` (0 still, 1 full stride); a walking aid moved ``aid_shift`` metres
    forward (:func:`aid_shift_m`) takes the hands on it along. ``device`` :data:`PUSHING` walks with both hands
    on the push handles of a manual wheelchair of ``fit`` whose origin is :data:`PUSH_DISTANCE_M` ahead.
    For many poses of one body and fit, keep its :func:`posture_cycle` (as :meth:`BodyParts.posture_cycle` does)."""
    return posture_cycle(bank, body, device, fit)(phase, amplitude, aid_shift)


def posture_cycle(bank: Bank, body: int, device: str | None, fit: DeviceFit) -> PostureCycle:
    """The posture of ``body`` with ``device`` fitted by ``fit`` as a function of the cycle (:data:`PostureCycle`,
    giving what :func:`pose` gives). What does not depend on the cycle (the seated base, the hanging arms, a
    pusher's lean, the shank vertices) is worked out here, once."""
    if device in SEATED or device == BENCH:
        return _seated_posture(bank, body, device, fit)
    return _walking_posture(bank, body, device, fit)


def _seated_posture(bank: Bank, body: int, device: str, fit: DeviceFit) -> PostureCycle:
    """In a wheelchair or on a bench: seated once; only a manual wheelchair's hands follow the cycle."""
    rest = bank.joints[body]
    base = _seated_legs(bank, body, 0.0, _bench_shank_deg(bank, body, fit.seat_height_m) if device == BENCH else 12.0)
    pts = skin(bank.points[body], bank, base.skinning(rest))
    seat_bottom = pts[_hip_vertices(bank, pts, base), 2].min()
    back = pts[_segment_vertices(bank, ("Torso",)), 0].min()
    # Sit on the seat (its top at seat height), the back 3 cm in front of the backrest (x = -0.18).
    shift = np.array([-0.15 - back, 0.0, fit.seat_height_m - seat_bottom])
    seated = forward_kinematics(rest, {b: base.rotations[k] for k, b in enumerate(BONES)}, rest[0] + shift)
    aims = {b: seated.rotations[k] for k, b in enumerate(BONES) if not b.startswith(("upperarm", "lowerarm", "hand"))}
    half = fit.seat_width_m / 2
    if device == "manual_wheelchair":  # hands on the push rims, along the push cycle
        def at(phase: float, amplitude: float, aid_shift: float = 0.0) -> Pose:
            targets = {}
            for side, sign in (("L", 1.0), ("R", -1.0)):
                angle = np.radians(20.0 + 35.0 * amplitude * np.sin(phase))
                targets[side] = np.array([REAR_WHEEL_X + (RIM_RADIUS_M + 0.02) * np.sin(angle), sign * (half + 0.07),
                                          0.3 + (RIM_RADIUS_M + 0.02) * np.cos(angle)])
            return _with_arms(bank, body, seated, targets, aims)
        return at
    if device == BENCH:  # hands resting on the thighs
        hip = seated.joints[BONES.index("upperleg.L")]
        targets = {side: np.array([hip[0] + 0.24, sign * 0.12, fit.seat_height_m + 0.17])
                   for side, sign in (("L", 1.0), ("R", -1.0))}
    else:
        targets = {"L": np.array([0.22, half + 0.03, fit.seat_height_m + 0.3]),
                   "R": np.array([shift[0] + rest[0, 0] + 0.32, -0.1, fit.seat_height_m + 0.2])}
    still = _with_arms(bank, body, seated, targets, aims)  # the same at every phase

    def at_rest(phase: float, amplitude: float, aid_shift: float = 0.0) -> Pose:
        return Pose(still.rotations.copy(), still.joints.copy())
    return at_rest


def _walking_posture(bank: Bank, body: int, device: str | None, fit: DeviceFit) -> PostureCycle:
    """On foot, with or without a walking aid, or pushing a wheelchair: legs and arms swing with the cycle."""
    rest = bank.joints[body]
    height = float(bank.height_m[body])
    step = step_length_m(1.0, height)
    leg = float(np.linalg.norm(rest[BONES.index("foot.L")] - rest[BONES.index("upperleg.L")]))
    full_hip_deg = np.degrees(np.arctan2(0.5 * step, leg))  # the hip's swing at amplitude 1
    arms_down = _arms_down(rest)
    lean = rot_y(push_lean_deg(bank, body, fit)) if device == PUSHING else None
    shanks = _segment_vertices(bank, ("ShankL", "ShankR"))

    def at(phase: float, amplitude: float, aid_shift: float = 0.0) -> Pose:
        hip_amp = full_hip_deg * amplitude
        aims = dict(arms_down)
        for side, sign in (("L", 1.0), ("R", -1.0)):
            swing = sign * np.sin(phase)
            swinging = max(0.0, sign * np.cos(phase))  # the leg moving forward bends its knee
            hip = hip_amp * swing
            knee = amplitude * (5.0 + 40.0 * swinging ** 2)
            aims[f"upperleg.{side}"] = rot_y(-hip)
            aims[f"lowerleg.{side}"] = rot_y(-(hip - knee))
            aims[f"foot.{side}"] = rot_y(-(hip - knee) * 0.5)
            arm = -0.7 * hip
            aims[f"upperarm.{side}"] = rot_y(-arm) @ aims[f"upperarm.{side}"]
            aims[f"lowerarm.{side}"] = rot_y(-arm) @ aims[f"lowerarm.{side}"]
        if lean is not None:
            aims["torso"] = lean
        walking = forward_kinematics(rest, aims)
        targets = {}
        if device == "walker":
            targets = {s: np.array([0.3, sign * 0.26, fit.grip_height_m + 0.03])
                       for s, sign in (("L", 1.0), ("R", -1.0))}
        elif device == PUSHING:  # the chair's handles, seen from PUSH_DISTANCE_M behind its origin
            handles = push_handles(fit) + np.array([PUSH_DISTANCE_M, 0.0, 0.0])
            targets = {"L": handles[0], "R": handles[1]}
        elif device == "crutch":
            targets = {s: np.array([AID_OFFSETS["crutch"][k][0] + GRIP_DX["crutch"] + aid_shift,
                                    AID_OFFSETS["crutch"][k][1], fit.grip_height_m + 0.03])
                       for k, s in enumerate(("L", "R"))}
        elif device in CANES:
            x, y = AID_OFFSETS[device][0]
            targets = {"R": np.array([x + GRIP_DX[device] + aid_shift, y, fit.grip_height_m + 0.04])}
        # Keep the lower foot on the ground, then put the hands on the aid (whose grips do not bob with the body).
        low = skin(bank.points[body], bank, walking.skinning(rest), shanks)[:, 2].min()
        walking = forward_kinematics(rest, aims, walking.joints[0] - np.array([0.0, 0.0, low]))
        if device == PUSHING:
            return _palms_on(bank, body, walking, targets, aims)
        return _with_arms(bank, body, walking, targets, aims) if targets else walking
    return at


def _palms_on(bank: Bank, body: int, pose_: Pose, targets: dict[str, np.ndarray], aims: dict) -> Pose:
    """``pose_`` with the centre of each named hand's mesh (not its wrist joint) on its target: the wrists are
    aimed at the targets less the hand's offset as the last solution turns it, twice."""
    rest = bank.joints[body]
    now = _with_arms(bank, body, pose_, targets, aims)
    for _ in range(2):
        wrists = {}
        for side, target in targets.items():
            k = BONES.index(f"hand.{side}")
            centre = bank.points[body][np.unique(bank.triangles[bank.face_bone == k])].mean(axis=0)
            wrists[side] = target - now.rotations[k] @ (centre - rest[k])
        now = _with_arms(bank, body, pose_, wrists, aims)
    return now


def segment_motion(bank: Bank, body: int, base: Pose, now: Pose) -> dict[str, np.ndarray]:
    """Per segment, the rigid motion (3, 4) taking it from ``base`` to ``now``: ``now``'s primary bone
    matrix times the inverse of ``base``'s."""
    rest = bank.joints[body]
    a, b = base.skinning(rest), now.skinning(rest)
    out = {}
    for name, (_, primary) in SEGMENTS.items():
        k = BONES.index(primary)
        r = b[k, :, :3] @ a[k, :, :3].T
        out[name] = np.concatenate([r, (b[k, :, 3] - r @ a[k, :, 3])[:, None]], axis=1)
    return out


class BodyParts:
    """Base postures, fits and segment meshes per (body, posture, fit), each computed once: what authoring a
    crowd needs of the body bank (the agents layer, a randomised scene). The meshes it hands out are read-only,
    so one instance may serve every scene of a process (:func:`shared_body_parts`); it keeps the last
    :attr:`KEEP` (body, posture, fit) keys (about 340 KB each), so a long run's memory stays bounded (72 bodies
    pushing each other's chairs alone are 5,184 keys)."""

    KEEP = 256

    def __init__(self) -> None:
        self.bank = load_bank()
        self._cache: dict[tuple, tuple] = {}
        self._posed: dict[tuple, np.ndarray] = {}
        self._hair: dict[tuple, tuple | None] = {}
        self._surfaces: dict[tuple, dict] = {}
        self._postures: dict[tuple, PostureCycle] = {}

    def posture_cycle(self, body: int, posture: str | None, fit: DeviceFit) -> PostureCycle:
        """:func:`posture_cycle` of ``body`` in ``posture`` (a device class, :data:`BENCH`, :data:`PUSHING` or None)
        fitted by ``fit``, made once: a crowd poses each body at every time code."""
        key = (body, posture, fit)
        if key not in self._postures:
            self._postures[key] = posture_cycle(self.bank, body, posture, fit)
            if len(self._postures) > self.KEEP:
                del self._postures[next(iter(self._postures))]
        return self._postures[key]

    def get(self, body: int, posture: str | None, fit: DeviceFit | None = None):
        """``posture`` a device class, :data:`BENCH` or None (walking); ``fit`` None: the device fitted to the body."""
        key = (body, posture, fit)
        if key not in self._cache:
            fit = fit or fit_device(self.bank, body, posture)
            base = self.posture_cycle(body, posture, fit)(0.0, 0.0, 0.0)
            pts = skin(self.bank.points[body], self.bank, base.skinning(self.bank.joints[body]))
            region = self.bank.face_region(body)
            segment_faces = self.bank.segment_faces(body)
            parts = {}
            for k, name in enumerate(SEGMENTS):
                for r, region_name in enumerate(REGIONS):
                    tris = self.bank.triangles[segment_faces[k] & (region == r)]
                    if len(tris):
                        used, inverse = np.unique(tris, return_inverse=True)
                        parts[(name, region_name)] = _read_only(pts[used], inverse.reshape(-1, 3))
            self._cache[key] = (fit, base, parts)
            self._posed[key] = pts
            if len(self._cache) > self.KEEP:  # the oldest key goes, with what was made of it
                oldest = next(iter(self._cache))
                for kept in (self._cache, self._posed, self._surfaces):
                    kept.pop(oldest, None)
                for hair_key in [k for k in self._hair if k[:3] == oldest]:
                    del self._hair[hair_key]
        return self._cache[key]

    def surfaces(self, body: int, posture: str | None, fit: DeviceFit | None = None) -> dict:
        """Per (segment, region) of :meth:`get`'s parts, the part as a smooth textured mesh: ``(points (k, 3),
        triangles (m, 3), uvs (k, 2) float32, normals (k, 3) float32)``, points split where the texture
        coordinates of its corners disagree (:func:`synthua_usd.assets.garments.corner_uvs`; at bone boundaries
        and the fabric's back seam), normals the whole posed body's (:func:`synthua_usd.model.meshes.vertex_normals`:
        smooth across the parts' edges too)."""
        key = (body, posture, fit)
        if key not in self._surfaces:
            self.get(body, posture, fit)
            pts = self._posed[key]
            normals = geo.vertex_normals(pts, self.bank.triangles).astype(np.float32)
            uvs = corner_uvs(self.bank, body)
            region = self.bank.face_region(body)
            segment_faces = self.bank.segment_faces(body)
            out = {}
            for k, name in enumerate(SEGMENTS):
                for r, region_name in enumerate(REGIONS):
                    faces = np.flatnonzero(segment_faces[k] & (region == r))
                    if len(faces):
                        tris = self.bank.triangles[faces]
                        data = np.concatenate([uvs[faces], normals[tris]], axis=2)  # (m, 3, 5) per corner
                        points, local, per_point = geo.split_corners(pts, tris, data)
                        out[(name, region_name)] = _read_only(points, local, per_point[:, :2].copy(),
                                                              per_point[:, 2:].copy())
            self._surfaces[key] = out
        return self._surfaces[key]

    def hair(self, body: int, posture: str | None, fit: DeviceFit | None, style: str):
        """The hair mesh ``(points, triangles)`` of ``body`` in ``style`` (:func:`synthua_usd.assets.hair.hair_mesh`)
        in the frame of its ``Torso`` segment in the base posture, or None for ``"none"``."""
        key = (body, posture, fit, style)
        if key not in self._hair:
            self.get(body, posture, fit)
            mesh = hair_mesh(self.bank, body, self._posed[(body, posture, fit)], style)
            self._hair[key] = None if mesh is None else _read_only(*mesh)
        return self._hair[key]


@cache
def shared_body_parts() -> BodyParts:
    """The process's one :class:`BodyParts`: every randomiser of a process (a worker's districts, generate's view
    scores, a replay) takes each body's parts from it, computed once."""
    return BodyParts()


def _read_only(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    for a in arrays:
        a.setflags(write=False)
    return arrays
