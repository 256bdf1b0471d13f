"""The agents layer: every agent an Xform with time-sampled translate and heading, holding a labelled
``Person`` (swinging limbs when walking, seated in a wheelchair) and, for mobility-aid users, a
separately labelled device linked from the person by a ``synthua:uses`` relationship.

Geometry is shared through USD scenegraph instancing. Each distinct part shape (a torso of one size, a
leg, a head, ...) and each device is authored once as a prototype under :data:`PROTOTYPES`, a ``class``
prim, which USD's default traversal (and so the reader and every validator rule) never visits; agents
reference prototypes from ``instanceable`` prims. Per agent, and therefore never inside a prototype:

- the labelled ``Person`` prim (an ordinary Xform above its part instances) and its ``synthua:uses``
  relationship, so instance ids stay one per agent;
- each person part's material, bound on the part's instance root, so one shape takes every agent's colours;
- each walking limb's pivot and time-sampled swing, authored on the limb's instance root;
- the device prim, which is itself the instance root of its device prototype and carries the label
  (a device's materials never vary, so they are bound inside the prototype).

Layout of one agent (``*`` marks instance roots, ``->`` their prototype)::

    Agent_0007            translate, rotateZ (time-sampled)
      Person              label person, synthua:uses -> ../ManualWheelchair
        Torso*            material:binding -> Looks/Shirt3      -> Prototypes/SeatedTorso_2
        Head*             material:binding -> Looks/Skin1       -> Prototypes/SeatedHead_1
        ...
      ManualWheelchair*   label manual_wheelchair               -> Prototypes/ManualWheelchair

A walking person's limbs are ``LegL*``, ``LegR*``, ``ArmL*``, ``ArmR*`` with translate (the pivot) and
rotateY (time-sampled); left and right share one prototype.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
from pxr import Gf, Kind, Sdf, Usd, UsdGeom, UsdShade

from synthua_usd import geometry as geo
from synthua_usd.agents.crowd import Crowd
from synthua_usd.assets import devices
from synthua_usd.assets.people import person, swing_deg
from synthua_usd.materials import PALETTE
from synthua_usd.scenario import StageMetadata
from synthua_usd.usd.authoring import (apply_label, bind_material, define_mesh, define_preview_material, define_xform,
                                       new_layer, set_kind)

AGENTS_ROOT = "/World/Agents"
#: Where the shared geometry lives: a ``class`` prim, so it is composed but never rendered itself.
PROTOTYPES = f"{AGENTS_ROOT}/Prototypes"

#: Where a device stands relative to its user (local frame: user faces +X): offsets per device.
DEVICE_PLACEMENT = {"walker": [(0.42, 0.0)], "crutch": [(0.12, 0.3), (0.12, -0.3)],
                    "smart_cane": [(0.3, -0.25)], "wooden_cane": [(0.12, -0.3)], "orthopedic_cane": [(0.12, -0.3)],
                    "tripod_cane": [(0.12, -0.32)]}


def _name(class_name: str) -> str:
    return "".join(part.title() for part in class_name.split("_"))


def _side_less(limb: str) -> str:
    """``LegL`` -> ``Leg``: left and right limbs are one shape."""
    return limb[:-1] if limb[-1:] in ("L", "R") else limb


class PrototypeLibrary:
    """The prototypes of one agents layer, authored on first use and shared by content.

    A person part's prototype is an Xform holding one unbound ``Mesh``; two parts with the same points and
    triangles (left and right legs, two agents of the same size) get the same prototype. A device's
    prototype holds its parts at every placement of :data:`DEVICE_PLACEMENT`, each bound to its material.
    Names are the shape with a counter in order of first use, so the same crowd gives the same layer.
    """

    def __init__(self, stage: Usd.Stage, materials: dict[str, UsdShade.Material]) -> None:
        self.stage = stage
        self.materials = materials
        stage.CreateClassPrim(PROTOTYPES)
        self._paths: dict[tuple, Sdf.Path] = {}
        self._counts: Counter[str] = Counter()

    def part(self, shape: str, mesh: geo.Mesh) -> Sdf.Path:
        """The prototype of a part mesh ``(points (n, 3), triangles (m, 3))``, metres, in the frame of the
        prim that will reference it."""
        points = np.ascontiguousarray(mesh[0], np.float32)  # what define_mesh stores: equal here means equal there
        tris = np.ascontiguousarray(mesh[1], np.int32)
        key = ("part", shape, points.tobytes(), tris.tobytes())
        if key not in self._paths:
            path = Sdf.Path(f"{PROTOTYPES}/{shape}_{self._counts[shape]}")
            self._counts[shape] += 1
            define_xform(self.stage, str(path))
            define_mesh(self.stage, f"{path}/Mesh", points, tris)
            self._paths[key] = path
        return self._paths[key]

    def device(self, class_name: str) -> Sdf.Path:
        """The prototype of the device ``class_name`` (a key of :data:`synthua_usd.assets.devices.DEVICES`)."""
        key = ("device", class_name)
        if key not in self._paths:
            path = Sdf.Path(f"{PROTOTYPES}/{_name(class_name)}")
            define_xform(self.stage, str(path))
            pieces = devices.DEVICES[class_name]()
            for k, (dx, dy) in enumerate(DEVICE_PLACEMENT.get(class_name, [(0.0, 0.0)])):
                for part in pieces:
                    define_mesh(self.stage, f"{path}/{part.name}{'' if k == 0 else f'_{k}'}",
                                part.points + [dx, dy, 0.0], part.triangles, self.materials[part.material])
            self._paths[key] = path
        return self._paths[key]


def _instance(stage: Usd.Stage, path: str, prototype: Sdf.Path, translate=None) -> Usd.Prim:
    """An instanceable Xform at ``path`` referencing ``prototype``."""
    prim = define_xform(stage, path, translate=translate).GetPrim()
    prim.GetReferences().AddInternalReference(prototype)
    prim.SetInstanceable(True)
    return prim


def build_agents_layer(crowd: Crowd, meta: StageMetadata, taxonomy: str) -> Usd.Stage:
    """The agents layer of ``crowd``: time samples from ``meta.start_time_code``, labels of ``taxonomy``."""
    trajectories, looks = crowd.trajectories, crowd.looks
    stage = new_layer(meta, crowd.doc)
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, AGENTS_ROOT, kind=Kind.Tokens.group)
    used = {look.skin for look in looks} | {look.shirt for look in looks} | {look.trousers for look in looks}
    used |= {p.material for t in trajectories if t.plan.profile.device for p in devices.DEVICES[t.plan.profile.device]()}
    mats = {key: define_preview_material(stage, f"{AGENTS_ROOT}/Looks/{key}", PALETTE[key]) for key in sorted(used)}
    library = PrototypeLibrary(stage, mats)
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
        pose = "Seated" if profile.seated else ""
        for name, (mesh, mat) in geom.body.items():
            part = _instance(stage, f"{person_xf.GetPath()}/{name}", library.part(pose + name, mesh))
            bind_material(part, mats[mat])
        swing = swing_deg(traj.distance_m)
        for name, limb in geom.limbs.items():
            # The limb's own prim is the instance root: its pivot, swing and material are this agent's.
            part = _instance(stage, f"{person_xf.GetPath()}/{name}", library.part(_side_less(name), limb.mesh),
                             translate=limb.pivot)
            bind_material(part, mats[limb.material])
            op = UsdGeom.Xformable(part).AddRotateYOp()
            sign = (1.0 if name in ("LegL", "ArmR") else -1.0) * (0.6 if name.startswith("Arm") else 1.0)
            for t, a in zip(times, swing):
                op.Set(float(sign * a), t)
        if profile.device:
            device = _instance(stage, f"{root.GetPath()}/{_name(profile.device)}", library.device(profile.device))
            set_kind(device, Kind.Tokens.component)
            apply_label(device, taxonomy, profile.device)
            person_xf.GetPrim().CreateRelationship("synthua:uses", custom=True).SetTargets([device.GetPath()])
    return stage
