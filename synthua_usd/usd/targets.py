"""What a camera rig can aim at, read from a composed stage: mobility-aid users (agents of the agents layer
whose person ``synthua:uses`` a device), crossings and curb ramps (labelled instances of those classes), or
any agent or labelled prim by path; and the agents a camera can ride with.

Agents are ``/World/Agents/Agent_NNNN`` Xforms with a time-sampled translate and rotateZ and a
``synthua:profile`` attribute (:mod:`synthua_usd.usd.agents_writer`). Boxes and transforms are world
space in metres, read with USD's own bounding-box and transform caches at each time code.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from pxr import Usd, UsdGeom

from synthua_usd.agents.profiles import PROFILES
from synthua_usd.core.errors import InputError, echo
from synthua_usd.model.scene import Instance
from synthua_usd.model.taxonomy import WHEELCHAIRS
from synthua_usd.usd.agents_writer import AGENTS_ROOT

#: Which aid users aim=aid_user tries first: wheelchair users (the rarest in real datasets, and the smallest in
#: the district's first CCTV view), then walkers, crutches and canes.
DEVICE_ORDER = ("electric_wheelchair", "manual_wheelchair", "walker", "crutch", "tripod_cane", "orthopedic_cane",
                "wooden_cane", "smart_cane")


@dataclass(frozen=True, eq=False)
class Target:
    """Something to aim at. ``instance_ids`` are the ids whose pixels count as the target (a person and their
    device); ``boxes`` maps each time code to the world box ``(lo (3,), hi (3,))`` in metres."""

    kind: str
    prim_path: str
    label: str
    instance_ids: tuple[int, ...]
    boxes: dict = field(repr=False)

    def anchor(self) -> np.ndarray:
        """(3,) the mean of the box centres over time: where a fixed camera looks."""
        return np.mean([(lo + hi) / 2 for lo, hi in self.boxes.values()], axis=0)

    def corners(self) -> np.ndarray:
        """(8 * t, 3) every corner of every box: what a fixed camera must keep in frame."""
        out = []
        for lo, hi in self.boxes.values():
            out += [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
        return np.array(out, np.float64)

    def footprint_m2(self) -> float:
        lo, hi = next(iter(self.boxes.values()))
        return float(np.prod(hi[:2] - lo[:2]))

    def to_dict(self) -> dict:
        return {"kind": self.kind, "prim_path": self.prim_path, "label": self.label,
                "instance_ids": list(self.instance_ids)}


@dataclass(frozen=True, eq=False)
class AgentTrack:
    """An agent: its prim, profile, device class (None for pedestrians), whether it sits, the ids of its
    labelled prims, and its root transform (4, 4) column-vector metres per time code."""

    prim_path: str
    profile: str
    device: str | None
    seated: bool
    instance_ids: tuple[int, ...]
    transforms: dict = field(repr=False)


def agents(stage: Usd.Stage, instances: dict[str, Instance], time_codes: list[float]) -> list[AgentTrack]:
    """Every agent under ``/World/Agents`` (prims with ``synthua:profile``), in path order."""
    root = stage.GetPrimAtPath(AGENTS_ROOT)
    if not root:
        return []
    caches = {t: UsdGeom.XformCache(Usd.TimeCode(t)) for t in time_codes}
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    out = []
    for prim in root.GetChildren():
        attr = prim.GetAttribute("synthua:profile")
        if not attr or not attr.HasAuthoredValue():
            continue
        path = str(prim.GetPath())
        ids = tuple(i.id for p, i in sorted(instances.items()) if p.startswith(path + "/"))
        device = _device(prim, instances)
        profile = str(attr.Get())
        known = PROFILES.get(profile)
        seated = known.seated if known else device in WHEELCHAIRS
        transforms = {}
        for t, cache in caches.items():
            m = np.array(cache.GetLocalToWorldTransform(prim), float).T
            m[:3, 3] *= mpu
            transforms[t] = m
        out.append(AgentTrack(path, profile, device, seated, ids, transforms))
    return out


def _device(agent: Usd.Prim, instances: dict[str, Instance]) -> str | None:
    """The class of the labelled device a prim of the agent ``synthua:uses``, or None."""
    for prim in Usd.PrimRange(agent):
        rel = prim.GetRelationship("synthua:uses")
        for target in (rel.GetTargets() if rel else []):
            if str(target) in instances:
                return instances[str(target)].class_name
    return None


def boxes(stage: Usd.Stage, paths: list[str], time_codes: list[float]) -> dict[float, tuple[np.ndarray, np.ndarray]]:
    """The world box of the prims ``paths`` together at each time code, metres."""
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    out = {}
    for t in time_codes:
        cache = UsdGeom.BBoxCache(Usd.TimeCode(t), [UsdGeom.Tokens.default_, UsdGeom.Tokens.render])
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for path in paths:
            box = cache.ComputeWorldBound(stage.GetPrimAtPath(path)).ComputeAlignedRange()
            if not box.IsEmpty():
                lo = np.minimum(lo, np.array(box.GetMin(), float) * mpu)
                hi = np.maximum(hi, np.array(box.GetMax(), float) * mpu)
        if not np.all(np.isfinite(lo)):
            raise InputError(f"{paths[0]}: has no geometry to aim at at time code {t:g}; expected a prim with geometry")
        out[t] = (lo, hi)
    return out


def find_targets(stage: Usd.Stage, aim: str, instances: dict[str, Instance], tracks: list[AgentTrack],
                 time_codes: list[float], source: str) -> list[Target]:
    """Every target ``aim`` names (see :class:`synthua_usd.composition.rigs.RigSpec`): aid users in the order of
    :data:`DEVICE_ORDER` (wheelchair users first), crossings and curb ramps largest first, ties in path order.
    Raises :class:`InputError` naming ``source`` when there is none."""
    if aim == "none":
        return []
    if aim.startswith("/"):
        track = next((a for a in tracks if a.prim_path == aim), None)
        if track is not None:
            found = [_agent_target(stage, track, time_codes)]
        elif aim in instances:
            inst = instances[aim]
            found = [Target(inst.class_name, aim, inst.class_name, (inst.id,), boxes(stage, [aim], time_codes))]
        else:
            raise InputError(f"{source}: aim = {echo(aim)}: no agent or labelled prim at that path; expected an agent "
                             f"({AGENTS_ROOT}/Agent_NNNN) or a labelled prim (see `synthua inspect`)")
        return found
    if aim in ("crossing", "curb_ramp"):
        name = "crosswalk" if aim == "crossing" else "curb_ramp"
        found = [Target(aim, p, i.class_name, (i.id,), boxes(stage, [p], time_codes))
                 for p, i in sorted(instances.items()) if i.class_name == name]
        missing = f"no labelled '{name}' instances"
    else:
        users = [a for a in tracks if a.device and (aim == "aid_user" or a.device == aim)]
        found = [_agent_target(stage, a, time_codes) for a in users]
        missing = ("no agents with mobility aids" if aim == "aid_user" else f"no agents using a {aim}")
    if not found:
        raise InputError(f"{source}: the scenario has {missing} to aim at; expected a scenario with them (agents come "
                         f"from `synthua agents populate`) or another aim (aid_user, crossing, curb_ramp, none)")
    if aim in ("crossing", "curb_ramp"):
        return sorted(found, key=lambda t: (-t.footprint_m2(), t.prim_path))
    rank = {t.prim_path: DEVICE_ORDER.index(a.device) if a.device in DEVICE_ORDER else len(DEVICE_ORDER)
            for t, a in zip(found, users)}
    return sorted(found, key=lambda t: (rank[t.prim_path], t.prim_path))


def _agent_target(stage: Usd.Stage, track: AgentTrack, time_codes: list[float]) -> Target:
    kind = "aid_user" if track.device else "agent"
    return Target(kind, track.prim_path, track.profile, track.instance_ids,
                  boxes(stage, [track.prim_path], time_codes))
