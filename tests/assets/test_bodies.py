"""Bodies from the body bank: topology and triangle count, phenotypes against their stated distributions,
walking on the ground with a stride that follows speed, seated users on their seats, and no body part inside
its own device beyond a stated tolerance at sampled times."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from scipy import stats

from synthua_usd.assets import body_bank, devices
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.assets.bodies import BONES, SEGMENTS, forward_kinematics, load_bank, rot_y, rotation_between, skin
from synthua_usd.assets.postures import (AID_OFFSETS, AID_STANCE, AID_STANCE_START, BENCH, GRIP_DX, MAX_PUSH_LEAN_DEG,
                                         PUSH_DISTANCE_M, PUSHING, SEATED, STEPPING_AIDS, BodyParts, aid_shift_m,
                                         bench_fit, fit_device, pose, push_handles, push_lean_deg, segment_motion,
                                         step_length_m)

#: How deep a body vertex may sit inside its own device: hands close round grips and push rims, whose
#: boxes and cylinders are solid here.
DEVICE_TOLERANCE_M = 0.04
SEAT_TOLERANCE_M = 0.02


@pytest.fixture(scope="module")
def bank():
    return load_bank()


def test_bank_shares_one_topology_of_3000_triangles(bank):
    assert bank.triangles.shape == (body_bank.TARGET_TRIANGLES, 3)
    assert bank.points.shape[1] == bank.skin_bones.shape[0] == int(bank.triangles.max()) + 1
    assert np.allclose(bank.skin_weights.sum(axis=1), 1.0, atol=1e-5)
    # Every body stands on z = 0 and is as tall as its stated height.
    # (The decimated mesh keeps a subset of the full mesh's vertices: its lowest may sit 2 mm up.)
    assert np.all(np.abs(bank.points[:, :, 2].min(axis=1)) < 2e-3)
    assert np.allclose(np.ptp(bank.points[:, :, 2], axis=1), bank.height_m, atol=4e-3)


def test_phenotypes_follow_their_stated_distributions(bank):
    general = bank.years[~bank.aid_stratum]
    counts = [np.sum((general >= lo) & (general < hi)) for lo, hi, _ in body_bank.AGE_BANDS]
    expected = np.array([share for _, _, share in body_bank.AGE_BANDS]) * len(general)
    assert stats.chisquare(counts, expected).pvalue > 0.01
    aid = bank.years[bank.aid_stratum]
    assert aid.min() >= body_bank.AID_AGE_RANGE[0] and aid.max() <= body_bank.AID_AGE_RANGE[1]
    assert stats.kstest(aid, "uniform", args=(50.0, 40.0)).pvalue > 0.01
    assert 0.3 < bank.female.mean() < 0.7
    # Adults: heights in the human range, men taller than women on average (WHO-calibrated model).
    adult = bank.years >= 20
    men, women = bank.height_m[adult & ~bank.female], bank.height_m[adult & bank.female]
    assert 1.70 < men.mean() < 1.90 and 1.52 < women.mean() < 1.72 and men.mean() - women.mean() > 0.08
    children = bank.years < 12
    assert bank.height_m[children].max() < 1.6


def test_stride_and_cadence_follow_speed():
    step = step_length_m(1.34, 1.7)
    assert 0.68 < step < 0.76  # adults at free speed: ~0.72 m at ~110 steps/min
    assert 100 < 60 * 1.34 / step < 120
    assert step_length_m(0.8, 1.7) < step < step_length_m(1.8, 1.7)


@pytest.mark.parametrize("body", [4, 15, 50])
def test_walking_keeps_a_foot_on_the_ground(bank, body):
    for phase in np.linspace(0, 2 * np.pi, 9):
        posed = pose(bank, body, None, fit_device(bank, body, None), phase, 1.0)
        pts = skin(bank.points[body], bank, posed.skinning(bank.joints[body]))
        assert abs(pts[:, 2].min()) < 1e-6


def _device_solids(device: str, fit, model: str = "standard") -> list[trimesh.Trimesh]:
    """The convex pieces (boxes, cylinders, tubes; a torus's is its disc) of the device as placed beside its user."""
    out = []
    for dx, dy in AID_OFFSETS.get(device, [(0.0, 0.0)]):
        for part in devices.DEVICE_MODELS[device][model](fit):
            mesh = trimesh.Trimesh(part.points + [dx, dy, 0.0], part.triangles, process=True)
            out += [piece.convex_hull for piece in mesh.split(only_watertight=False)]
    return out


def _penetration(points: np.ndarray, solids: list[trimesh.Trimesh]) -> float:
    """Deepest any point lies inside any solid (0 if none), metres: the least plane distance of the hull."""
    deepest = 0.0
    for solid in solids:
        lo, hi = solid.bounds
        near = points[np.all((points >= lo) & (points <= hi), axis=1)]  # outside its box, outside the solid
        if not len(near):
            continue
        normals, origins = solid.face_normals, solid.triangles[:, 0]
        d = np.einsum("pfk,fk->pf", near[:, None, :] - origins[None], normals)
        inside = d.max(axis=1)
        deepest = max(deepest, float(-inside.min()) if (inside < 0).any() else 0.0)
    return deepest


@pytest.mark.parametrize("model", ["standard", "detailed"])
@pytest.mark.parametrize("device", ["manual_wheelchair", "electric_wheelchair"])
@pytest.mark.parametrize("body", [48, 56, 66])
def test_seated_pelvis_rests_on_the_seat(bank, body, device, model):
    fit = fit_device(bank, body, device)
    seat = [p for p in devices.DEVICE_MODELS[device][model](fit) if p.name == "Seat"][0]
    pieces = trimesh.Trimesh(seat.points, seat.triangles).split(only_watertight=False)
    cushion = max(pieces, key=lambda m: np.prod(np.ptp(m.vertices[:, :2], axis=0)))  # the seat, not the backrest
    top = cushion.vertices[:, 2].max()
    lo, hi = cushion.vertices[:, :2].min(axis=0), cushion.vertices[:, :2].max(axis=0)
    posed = pose(bank, body, device, fit, 0.0, 0.0)
    pts = skin(bank.points[body], bank, posed.skinning(bank.joints[body]))
    # What sits: the torso and thighs (segments 0-2), over the cushion.
    sitting = np.unique(bank.triangles[bank.face_segment <= 2])
    pts = pts[sitting]
    above = pts[np.all((pts[:, :2] > lo) & (pts[:, :2] < hi), axis=1)]
    assert abs(above[:, 2].min() - top) < SEAT_TOLERANCE_M


DEVICES = ["manual_wheelchair", "electric_wheelchair", "walker", "crutch", "smart_cane", "wooden_cane",
           "orthopedic_cane", "tripod_cane"]


def _cycle_m(bank, body: int, device: str) -> float:
    """The gait cycle of ``body`` walking with ``device`` at its profile's mean speed (as the agents layer has it)."""
    speed = next(p.speed_mps for p in PROFILES.values() if p.device == device)
    return 2 * step_length_m(speed, float(bank.height_m[body]))


def _animated(bank, body: int, device: str | None, fit, phase: float, amplitude: float, shift: float) -> np.ndarray:
    """The body as the agents layer renders it at ``phase``: each segment of the base posture moved rigidly by
    its motion (a segment's vertices counted once per segment)."""
    base = pose(bank, body, device, fit, 0.0, 0.0)
    motion = segment_motion(bank, body, base, pose(bank, body, device, fit, phase, amplitude, shift))
    pts = skin(bank.points[body], bank, base.skinning(bank.joints[body]))
    out = []
    for k, name in enumerate(SEGMENTS):
        v = pts[np.unique(bank.triangles[bank.segment_faces(body)[k]])]
        out.append(v @ motion[name][:, :3].T + motion[name][:, 3])
    return np.concatenate(out)


@pytest.mark.parametrize("model", ["standard", "detailed"])
@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("body", [52, 60, 66])
def test_no_body_part_inside_its_own_device(bank, body, device, model):
    """At twelve phases of the cycle, the rendered (rigid-segment) body against its device (each model) where
    it stands then."""
    fit = fit_device(bank, body, device)
    amplitude = 0.0 if device == "electric_wheelchair" else 1.0
    solids = _device_solids(device, fit, model)
    for phase in np.linspace(0, 2 * np.pi, 12, endpoint=False):
        shift = aid_shift_m(device, phase, amplitude, _cycle_m(bank, body, device))
        pts = _animated(bank, body, device, fit, phase, amplitude, shift) - [shift, 0.0, 0.0]
        assert _penetration(pts, solids) <= DEVICE_TOLERANCE_M, (device, phase)


@pytest.mark.parametrize("device", STEPPING_AIDS)
def test_stepping_aid_tips_stay_planted_then_swing(bank, device):
    """Walking d metres, the aid's tip is at d + shift along the way: constant while planted (a stance of
    AID_STANCE of the cycle), moving forward while it swings, with no jump anywhere; on the ground throughout
    (the aid only slides along its user's heading)."""
    cycle = _cycle_m(bank, 60, device)
    d = np.linspace(0.0, 2 * cycle, 4001)
    phase = 2 * np.pi * d / cycle
    tip = d + np.array([aid_shift_m(device, p, 1.0, cycle) for p in phase])
    u = ((phase - AID_STANCE_START) / (2 * np.pi)) % 1.0
    planted = u < AID_STANCE - 1e-3
    step = np.diff(tip)
    assert np.all(np.abs(step[planted[:-1] & planted[1:]]) < 1e-9)
    assert np.all(step > -1e-9)  # never backwards
    assert np.max(step) < 10 * (d[1] - d[0])  # no jump
    assert np.ptp(tip[planted & (d < cycle)]) < 1e-9 and np.ptp(tip) > cycle  # it does move on
    assert aid_shift_m(device, 1.0, 0.0, cycle) == 0.0  # standing still, the aid stands in its place
    assert aid_shift_m("walker", 1.0, 1.0, cycle) == 0.0


@pytest.mark.parametrize("device", STEPPING_AIDS)
@pytest.mark.parametrize("body", [52, 60, 66])
def test_hands_stay_on_the_grips_of_stepping_aids(bank, body, device):
    """The holding hand's wrist joint within 4 cm of the grip at twelve phases (two-bone IK reaches it)."""
    fit = fit_device(bank, body, device)
    cycle = _cycle_m(bank, body, device)
    k = 1 if device == "crutch" else 0  # the right hand's aid
    x, y = AID_OFFSETS[device][k]
    for phase in np.linspace(0, 2 * np.pi, 12, endpoint=False):
        shift = aid_shift_m(device, phase, 1.0, cycle)
        hand = pose(bank, body, device, fit, phase, 1.0, shift).joints[BONES.index("hand.R")]
        grip = np.array([x + GRIP_DX[device] + shift, y, fit.grip_height_m])
        assert np.linalg.norm(hand[:2] - grip[:2]) < 0.04 and abs(hand[2] - grip[2]) < 0.08, (phase, hand - grip)


@pytest.mark.parametrize("body", [15, 2, 47, 60, 67])
def test_seated_on_a_bench_the_pelvis_rests_on_the_seat_and_the_feet_on_the_ground(bank, body):
    """The street bench (synthua_usd.assets.street.bench: seat top 0.47 m, 0.44 m deep centred on x = 0,
    backrest behind x = -0.22) placed where :mod:`synthua_usd.agents.seats` puts a sitter's origin (0.17 m in
    front of the seat's back edge): what sits rests on the cushion within the seat tolerance, nothing is
    inside the bench beyond the device tolerance, and the feet stand on the ground unless too short to reach
    it (a child's dangle)."""
    from synthua_usd.agents.seats import ORIGIN_FROM_BACK_M
    from synthua_usd.assets import street

    dx = 0.22 - ORIGIN_FROM_BACK_M  # the bench's centre in the sitter's frame
    solids = []
    for part in street.bench():
        mesh = trimesh.Trimesh(part.points + [dx, 0.0, 0.0], part.triangles, process=True)
        solids += [piece.convex_hull for piece in mesh.split(only_watertight=False)]
    seat = max(solids, key=lambda m: np.prod(np.ptp(m.vertices[:, :2], axis=0)))
    top = seat.vertices[:, 2].max()
    posed = pose(bank, body, BENCH, bench_fit(top), 0.0, 0.0)
    pts = skin(bank.points[body], bank, posed.skinning(bank.joints[body]))
    sitting = pts[np.unique(bank.triangles[bank.face_segment <= 2])]
    lo, hi = seat.vertices[:, :2].min(axis=0), seat.vertices[:, :2].max(axis=0)
    above = sitting[np.all((sitting[:, :2] > lo) & (sitting[:, :2] < hi), axis=1)]
    assert abs(above[:, 2].min() - top) < SEAT_TOLERANCE_M
    assert _penetration(pts, solids) <= DEVICE_TOLERANCE_M
    feet = pts[:, 2].min()
    assert feet > -SEAT_TOLERANCE_M
    if bank.height_m[body] > 1.6:
        assert feet < 0.04


def _outside(point: np.ndarray, solids: list[trimesh.Trimesh]) -> float:
    """How far ``point`` lies outside the nearest of ``solids`` (convex), along its farthest face plane (a lower
    bound of the distance; <= 0 inside)."""
    return min(float(((point - s.triangles[:, 0]) * s.face_normals).sum(axis=1).max()) for s in solids)


@pytest.mark.parametrize("model", ["standard", "detailed"])
@pytest.mark.parametrize("user", [52, 60, 66])
def test_the_push_handles_are_where_the_pusher_holds_them(bank, user, model):
    fit = fit_device(bank, user, "manual_wheelchair")
    solids = _device_solids("manual_wheelchair", fit, model)
    for handle in push_handles(fit):
        assert _outside(handle, solids) <= 0.015, (handle, model)


@pytest.mark.parametrize("model", ["standard", "detailed"])
@pytest.mark.parametrize("pusher, user", [(8, 52), (40, 60), (17, 66), (30, 52)])
def test_a_pusher_holds_the_handles_walks_on_the_ground_and_stays_out_of_the_chair(bank, pusher, user, model):
    """At twelve phases of the gait, a pusher (1.93 m, 1.76 m, 1.50 m, 1.83 m tall) behind the chair of a user:
    the centre of both hands' meshes on the push handles (within 2 cm), a foot on the ground, and no
    vertex of the rendered body deeper than the device tolerance inside the chair (each model), which stands
    PUSH_DISTANCE_M ahead; a tall pusher leans forward to reach low handles, at most MAX_PUSH_LEAN_DEG."""
    fit = fit_device(bank, user, "manual_wheelchair")
    solids = _device_solids("manual_wheelchair", fit, model)
    handles = push_handles(fit) + [PUSH_DISTANCE_M, 0.0, 0.0]
    assert 0.0 <= push_lean_deg(bank, pusher, fit) <= MAX_PUSH_LEAN_DEG
    for phase in np.linspace(0, 2 * np.pi, 12, endpoint=False):
        now = pose(bank, pusher, PUSHING, fit, phase, 1.0)
        posed = skin(bank.points[pusher], bank, now.skinning(bank.joints[pusher]))
        for side, handle in zip("LR", handles):
            hand = np.unique(bank.triangles[bank.face_bone == BONES.index(f"hand.{side}")])
            assert np.linalg.norm(posed[hand].mean(axis=0) - handle) < 0.02, (phase, side)
        assert abs(posed[:, 2].min()) < 1e-6, phase  # as walking: the lower foot on the ground
        pts = _animated(bank, pusher, PUSHING, fit, phase, 1.0, 0.0)
        assert _penetration(pts - [PUSH_DISTANCE_M, 0.0, 0.0], solids) <= DEVICE_TOLERANCE_M, phase


def test_skinning_some_vertices_gives_those_rows_of_the_whole(bank):
    """``skin(..., vertices)`` (what keeps a walking foot on the ground) is bit for bit the skinning of the
    whole body at those rows, for every body in random poses and any subset."""
    rng = np.random.default_rng(7)
    for body in range(len(bank)):
        rest = bank.joints[body]
        aims = {b: rot_y(rng.uniform(-60, 60)) @ rotation_between(rng.normal(size=3), rng.normal(size=3))
                for b in BONES if rng.random() < 0.7}
        matrices = forward_kinematics(rest, aims, rest[0] + rng.normal(0, 0.1, 3)).skinning(rest)
        whole = skin(bank.points[body], bank, matrices)
        for vertices in (np.sort(rng.choice(len(whole), rng.integers(2, len(whole)), replace=False)),
                         np.arange(len(whole))):
            assert skin(bank.points[body], bank, matrices, vertices).tobytes() == whole[vertices].tobytes()


@pytest.mark.parametrize("device", [None, "walker", "crutch", "tripod_cane", "manual_wheelchair",
                                    "electric_wheelchair", BENCH, PUSHING])
def test_a_kept_posture_poses_as_a_fresh_one_in_any_order(bank, device):
    """A crowd keeps one posture per body and fit (BodyParts.posture_cycle) and poses it at every time code: what
    it computes once is never changed by a pose, so poses in any order equal, bit for bit, fresh ones."""
    body = 11
    fit = (bench_fit(0.45) if device == BENCH else fit_device(bank, body, "manual_wheelchair") if device == PUSHING
           else fit_device(bank, body, device))
    bodies = BodyParts()
    cycle = bodies.posture_cycle(body, device, fit)
    assert bodies.posture_cycle(body, device, fit) is cycle
    rng = np.random.default_rng(3)
    times = [(rng.uniform(0, 2 * np.pi), rng.uniform(0, 1), rng.uniform(-0.1, 0.1)) for _ in range(6)]
    for phase, amplitude, shift in times + times[::-1]:
        kept = cycle(phase, amplitude, shift)
        fresh = pose(bank, body, device, fit, phase, amplitude, shift)
        assert kept.rotations.tobytes() == fresh.rotations.tobytes()
        assert kept.joints.tobytes() == fresh.joints.tobytes()
        kept.joints[:] = np.nan  # a caller's scribbles do not reach the next pose


def test_the_shared_body_parts_hand_out_read_only_meshes():
    """Every randomiser of a process takes its parts from one BodyParts (shared_body_parts): no scene can change a
    mesh another scene is given."""
    from synthua_usd.assets.postures import shared_body_parts

    bodies = shared_body_parts()
    assert shared_body_parts() is bodies
    _, _, parts = bodies.get(4, "manual_wheelchair")
    surfaces = bodies.surfaces(4, "manual_wheelchair")
    hair = bodies.hair(4, "manual_wheelchair", None, "short")
    arrays = [a for mesh in [*parts.values(), *surfaces.values(), hair] for a in mesh]
    assert len(arrays) > 20
    for a in arrays:
        with pytest.raises(ValueError, match="read-only"):
            a[...] = 0


def test_body_parts_keep_a_bounded_number_of_keys_and_remake_the_rest_alike():
    class Few(BodyParts):
        KEEP = 2

    few, fresh = Few(), BodyParts()
    keys = [(1, None), (2, "walker"), (3, "manual_wheelchair"), (1, None), (4, None)]
    for body, posture in keys + keys[::-1]:
        made = few.surfaces(body, posture)
        hair = few.hair(body, posture, None, "long")
        assert len(few._cache) <= 2 and len(few._surfaces) <= 2 and len({k[:3] for k in few._hair}) <= 2
        for part, mesh in fresh.surfaces(body, posture).items():
            assert all(a.tobytes() == b.tobytes() for a, b in zip(mesh, made[part]))
        assert all(a.tobytes() == b.tobytes() for a, b in zip(hair, fresh.hair(body, posture, None, "long")))
