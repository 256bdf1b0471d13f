"""How one cast member's body stands in one view: its base posture (walking, seated in its wheelchair or on its
bench, holding its walker, crutches or cane), each segment's rigid motion at the view's gait phase, its COCO
keypoints and its device's contact points. The same posing the agents layer animates over time
(:mod:`synthua_usd.usd.agents_writer`), taken at one instant. Plain data, agent frame (metres, +X forward).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from synthua_usd.agents.profiles import PROFILES
from synthua_usd.assets.agent_keypoints import body_keypoints, contact_points
from synthua_usd.assets.postures import (BENCH, PUSHING, STEPPING_AIDS, BodyParts, DeviceFit, aid_shift_m, bench_fit,
                                         segment_motion, step_length_m)
from synthua_usd.randomisation.scene import CastMember
from synthua_usd.randomisation.view import Placement

#: A manual wheelchair's push cycle, metres travelled (as the agents layer).
PUSH_CYCLE_M = 1.2


def posture_of(member: CastMember) -> tuple[str | None, DeviceFit | None]:
    """(posture, fit) of ``member``: :data:`BENCH` with the bench's fit for a sitter, :data:`PUSHING` with the
    pushed chair's fit for a pusher, else its device (None walking) with the fit to its body (None: fitted by
    :class:`BodyParts`)."""
    if member.seat is not None:
        return BENCH, bench_fit(member.seat.seat_height_m)
    if member.pushes is not None:
        return PUSHING, member.pushing
    return member.aid, None


@dataclass(frozen=True, eq=False)
class MemberPose:
    """``segments``: segment name -> (3, 4) rigid motion from the base posture; ``keypoints`` (17, 3) COCO body
    keypoints; ``device_shift_m`` a stepping aid's forward shift; ``contacts`` (k, 3) the device's contact
    points in the device prim's frame (None without a device); ``fit`` the device fit the body was posed with."""

    posture: str | None
    fit: DeviceFit
    segments: dict = field(repr=False)
    keypoints: np.ndarray = field(repr=False)
    device_shift_m: float = 0.0
    contacts: np.ndarray | None = field(default=None, repr=False)


def pose_member(bodies: BodyParts, member: CastMember, placement: Placement) -> MemberPose:
    """``member`` at ``placement``'s phase and amplitude (an electric wheelchair's user sits still, and so does a
    manual one who is pushed, hands on the rims; one who is not pushes once per :data:`PUSH_CYCLE_M`; walkers,
    pushers among them, stride by their speed and height)."""
    posture, fit = posture_of(member)
    fit, base, _ = bodies.get(member.body, posture, fit)
    device = member.aid if member.seat is None else None
    still = device == "electric_wheelchair" or (device == "manual_wheelchair" and member.pushed_by is not None)
    amplitude = 0.0 if still else placement.amplitude
    height = float(bodies.bank.height_m[member.body])
    cycle = PUSH_CYCLE_M if device == "manual_wheelchair" else 2 * step_length_m(
        placement.speed_mps or PROFILES[member.profile].speed_mps, height)
    shift = aid_shift_m(device, placement.phase, amplitude, cycle)
    now = bodies.posture_cycle(member.body, posture, fit)(placement.phase, amplitude, shift)
    motion = segment_motion(bodies.bank, member.body, base, now)
    keypoints = body_keypoints(bodies.bank, member.body, base, [motion])[0]
    contacts = None
    if device is not None:
        contacts = contact_points(bodies.bank, member.body, device, fit, base, [motion], [shift])[0]
        if device in STEPPING_AIDS:  # agent frame -> the stepping aid's own frame
            contacts = contacts - np.array([shift, 0.0, 0.0])
    return MemberPose(posture, fit, motion, keypoints, float(shift), contacts)
