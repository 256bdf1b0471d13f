"""The agents layer: every agent an Xform with time-sampled translate and heading, holding a labelled
``Person`` (swinging limbs when walking, seated in a wheelchair) and, for mobility-aid users, a
separately labelled device linked from the person by a ``synthua:uses`` relationship."""

from __future__ import annotations

from pxr import Gf, Kind, Sdf, Usd

from synthua_usd.agents.crowd import Crowd
from synthua_usd.assets import devices
from synthua_usd.assets.people import person, swing_deg
from synthua_usd.materials import PALETTE
from synthua_usd.scenario import StageMetadata
from synthua_usd.usd.authoring import apply_label, define_mesh, define_preview_material, define_xform, new_layer, set_kind

AGENTS_ROOT = "/World/Agents"

#: Where a device stands relative to its user (local frame: user faces +X): offsets per device.
DEVICE_PLACEMENT = {"walker": [(0.42, 0.0)], "crutch": [(0.12, 0.3), (0.12, -0.3)],
                    "smart_cane": [(0.3, -0.25)], "wooden_cane": [(0.12, -0.3)], "orthopedic_cane": [(0.12, -0.3)],
                    "tripod_cane": [(0.12, -0.32)]}


def _name(class_name: str) -> str:
    return "".join(part.title() for part in class_name.split("_"))


def build_agents_layer(crowd: Crowd, meta: StageMetadata, taxonomy: str) -> Usd.Stage:
    """The agents layer of ``crowd``: time samples from ``meta.start_time_code``, labels of ``taxonomy``."""
    trajectories, looks = crowd.trajectories, crowd.looks
    stage = new_layer(meta, crowd.doc)
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, AGENTS_ROOT, kind=Kind.Tokens.group)
    used = {look.skin for look in looks} | {look.shirt for look in looks} | {look.trousers for look in looks}
    used |= {p.material for t in trajectories if t.plan.profile.device for p in devices.DEVICES[t.plan.profile.device]()}
    mats = {key: define_preview_material(stage, f"{AGENTS_ROOT}/Looks/{key}", PALETTE[key]) for key in sorted(used)}
    times = [Usd.TimeCode(meta.start_time_code + f) for f in range(len(trajectories[0].positions))] if trajectories else []
    for i, (traj, look) in enumerate(zip(trajectories, looks)):
        profile = traj.plan.profile
        root = define_xform(stage, f"{AGENTS_ROOT}/Agent_{i:04d}", kind=Kind.Tokens.group)
        translate, heading = root.AddTranslateOp(), root.AddRotateZOp()
        for t, p, h in zip(times, traj.positions, traj.headings_deg):
            translate.Set(Gf.Vec3d(*map(float, p)), t)
            heading.Set(float(h), t)
        prim = root.GetPrim()
        prim.CreateAttribute("synthua:profile", Sdf.ValueTypeNames.String, custom=True).Set(profile.name)
        prim.CreateAttribute("synthua:speed_mps", Sdf.ValueTypeNames.Double, custom=True).Set(traj.plan.speed_mps)
        if traj.plan.rests:
            prim.CreateAttribute("synthua:behaviour", Sdf.ValueTypeNames.String, custom=True).Set("rests_at_bench")
        if traj.plan.group is not None:
            prim.CreateAttribute("synthua:group", Sdf.ValueTypeNames.Int, custom=True).Set(traj.plan.group)
        person_xf = define_xform(stage, f"{root.GetPath()}/Person")
        set_kind(person_xf.GetPrim(), Kind.Tokens.component)
        apply_label(person_xf.GetPrim(), taxonomy, "person")
        geom = person(look, seated=profile.seated)
        for name, (mesh, mat) in geom.body.items():
            define_mesh(stage, f"{person_xf.GetPath()}/{name}", *mesh, mats[mat])
        swing = swing_deg(traj.distance_m)
        for name, limb in geom.limbs.items():
            limb_xf = define_xform(stage, f"{person_xf.GetPath()}/{name}", translate=limb.pivot)
            op = limb_xf.AddRotateYOp()
            sign = (1.0 if name in ("LegL", "ArmR") else -1.0) * (0.6 if name.startswith("Arm") else 1.0)
            for t, a in zip(times, swing):
                op.Set(float(sign * a), t)
            define_mesh(stage, f"{limb_xf.GetPath()}/Mesh", *limb.mesh, mats[limb.material])
        if profile.device:
            device_xf = define_xform(stage, f"{root.GetPath()}/{_name(profile.device)}")
            set_kind(device_xf.GetPrim(), Kind.Tokens.component)
            apply_label(device_xf.GetPrim(), taxonomy, profile.device)
            pieces = devices.DEVICES[profile.device]()
            for k, (dx, dy) in enumerate(DEVICE_PLACEMENT.get(profile.device, [(0.0, 0.0)])):
                for part in pieces:
                    define_mesh(stage, f"{device_xf.GetPath()}/{part.name}{'' if k == 0 else f'_{k}'}",
                                part.points + [dx, dy, 0.0], part.triangles, mats[part.material])
            person_xf.GetPrim().CreateRelationship("synthua:uses", custom=True).SetTargets([device_xf.GetPath()])
    return stage
