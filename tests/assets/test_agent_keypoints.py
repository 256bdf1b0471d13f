"""Keypoints of posed agents: the body keypoints follow the rendered rigid segments and the full rig; the
contact points touch the device's geometry (checked with trimesh's closest points on the device meshes)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from synthua_usd.assets import devices
from synthua_usd.assets.agent_keypoints import body_keypoints, contact_points, segment_weights
from synthua_usd.assets.bodies import SEGMENTS, load_bank, skin, skin_keypoints
from synthua_usd.assets.postures import AID_OFFSETS, fit_device, pose, segment_motion
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES

PHASES = np.linspace(0.0, 2 * np.pi, 6, endpoint=False)
#: Rendered rigid segments vs the fully skinned rig (measured: 4.2 mm at most).
MAX_RIG_M = 0.01
#: A keypoint lies inside its body: at most this far from the nearest rendered vertex of its main segment
#: (measured: 11.9 cm, a hip inside a heavy pelvis).
MAX_INSIDE_M = 0.15
#: A hand's centroid is at most this far from the device's surface where it holds it (measured: 5.4 cm,
#: a hand round a crutch grip or the joystick); seats and tips lie on it.
MAX_HAND_M = 0.06


def _bodies(bank):
    return list(np.flatnonzero(bank.aid_stratum)[:2]) + list(np.flatnonzero(~bank.aid_stratum)[:2])


def _motions(bank, body, device):
    fit = fit_device(bank, body, device)
    base = pose(bank, body, device, fit, 0.0, 0.0)
    nows = [pose(bank, body, device, fit, p, 1.0) for p in PHASES]
    return fit, base, nows, [segment_motion(bank, body, base, now) for now in nows]


@pytest.mark.parametrize("device", [None, "manual_wheelchair", "walker", "crutch"])
def test_body_keypoints_follow_the_rendered_segments_and_the_rig(device):
    bank = load_bank()
    main_segment = segment_weights(bank).argmax(axis=1)
    for body in _bodies(bank):
        fit, base, nows, motions = _motions(bank, body, device)
        rest = bank.joints[body]
        rendered_base = skin(bank.points[body], bank, base.skinning(rest))
        kps = body_keypoints(bank, body, base, motions)
        still = body_keypoints(bank, body, base, [segment_motion(bank, body, base, base)])[0]
        np.testing.assert_allclose(still, skin_keypoints(bank.keypoints[body], bank, base.skinning(rest)), atol=1e-9)
        for now, motion, kp in zip(nows, motions, kps):
            full = skin_keypoints(bank.keypoints[body], bank, now.skinning(rest))
            assert np.linalg.norm(kp - full, axis=1).max() <= MAX_RIG_M
            for k, s in enumerate(main_segment):
                m = motion[list(SEGMENTS)[s]]
                verts = rendered_base[np.unique(bank.triangles[bank.face_segment == s])] @ m[:, :3].T + m[:, 3]
                assert np.linalg.norm(verts - kp[k], axis=1).min() <= MAX_INSIDE_M


def _device_mesh(device, fit) -> trimesh.Trimesh:
    """The device as the agents layer renders it: its parts at every placement, agent frame."""
    verts, faces, offset = [], [], 0
    for dx, dy in AID_OFFSETS.get(device, [(0.0, 0.0)]):
        for part in devices.DEVICES[device](fit):
            verts.append(part.points + [dx, dy, 0.0])
            faces.append(part.triangles + offset)
            offset += len(part.points)
    return trimesh.Trimesh(np.concatenate(verts), np.concatenate(faces), process=False)


@pytest.mark.parametrize("device", sorted(devices.DEVICES))
def test_contact_points_touch_the_device(device):
    bank = load_bank()
    names = KEYPOINT_CLASSES[device].names
    for body in _bodies(bank):
        fit, base, _, motions = _motions(bank, body, device)
        points = contact_points(bank, body, device, fit, base, motions)
        assert points.shape == (len(PHASES), len(names), 3)
        mesh = _device_mesh(device, fit)
        for k, name in enumerate(names):
            _, distance, _ = trimesh.proximity.closest_point(mesh, points[:, k])
            if name.endswith("tip"):
                assert np.abs(points[:, k, 2]).max() < 1e-9 and distance.max() < 1e-3, name  # on the ground
            elif name == "seat":
                assert np.abs(points[:, k, 2] - fit.seat_height_m).max() < 1e-9 and distance.max() < 1e-3
            else:
                assert distance.max() <= MAX_HAND_M, f"{name}: {distance.max():.3f} m from the device"
        if device == "manual_wheelchair":  # the hands travel along the rims with the push
            assert np.ptp(points[:, 0, 0]) > 0.1
        if device == "crutch":  # left and right as the user's
            assert points[0, names.index("left_tip"), 1] > 0 > points[0, names.index("right_tip"), 1]


@pytest.mark.parametrize("device", ["crutch", "wooden_cane", "tripod_cane"])
def test_contact_points_of_a_stepping_aid_follow_its_tips_and_grips(device):
    """Crutches and canes step with the gait (a forward shift of the device, the hands going with it): the
    tips and hand contacts lie on the device moved by that shift, at every phase."""
    from synthua_usd.assets.postures import aid_shift_m

    bank = load_bank()
    names = KEYPOINT_CLASSES[device].names
    cycle = 1.4
    for body in _bodies(bank)[:2]:
        fit = fit_device(bank, body, device)
        base = pose(bank, body, device, fit, 0.0, 0.0)
        shifts = [aid_shift_m(device, p, 1.0, cycle) for p in PHASES]
        assert np.ptp(shifts) > 0.1
        motions = [segment_motion(bank, body, base, pose(bank, body, device, fit, p, 1.0, x))
                   for p, x in zip(PHASES, shifts)]
        points = contact_points(bank, body, device, fit, base, motions, shifts)
        mesh = _device_mesh(device, fit)
        for t, shift in enumerate(shifts):
            _, distance, _ = trimesh.proximity.closest_point(mesh, points[t] - [shift, 0.0, 0.0])
            for k, name in enumerate(names):
                limit = 1e-3 if name.endswith("tip") else MAX_HAND_M
                assert distance[k] <= limit, f"{name} at phase {t}: {distance[k]:.3f} m from the moved device"
