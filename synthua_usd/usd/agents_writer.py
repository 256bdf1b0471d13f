"""The agents layer: every agent an Xform with time-sampled translate and heading, holding a labelled
``Person`` (an articulated body from the body bank, :mod:`synthua_usd.assets.bodies`) and, for mobility-aid
users, a separately labelled device sized to that body, linked from the person by a ``synthua:uses``
relationship.

A body is nine rigid segments (:data:`synthua_usd.assets.bodies.SEGMENTS`) cut from its base posture
(standing, seated in its wheelchair or on a bench, holding its walker, crutches or cane; :mod:`synthua_usd.assets.postures`),
each split into garment regions. Geometry is shared through USD scenegraph instancing: each (body, posture,
segment, region) mesh and each (device, fit) is authored once as a prototype under :data:`PROTOTYPES`, a
``class`` prim, which USD's default traversal (and so the reader and every validator rule) never visits;
agents reference prototypes from ``instanceable`` prims. Per agent, and therefore never inside a prototype:

- the labelled ``Person`` prim and its ``synthua:uses`` relationship, so instance ids stay one per agent;
- each region's material (skin tone, garment colours), bound on the region's instance root;
- each segment's motion from the base posture (walking swings, push strokes), a time-sampled translate and
  orientation on the segment's Xform; a segment that does not move has none;
- the device prim, which is itself the instance root of its device prototype and carries the label; crutches
  and canes step with the gait (:func:`synthua_usd.assets.postures.aid_shift_m`), a time-sampled translate
  on the device prim;
- keypoints (:mod:`synthua_usd.assets.agent_keypoints`): on the ``Person`` prim the 17 COCO body keypoints,
  on the device prim its contact points, each as ``synthua:keypoints`` (point3f[], the prim's frame,
  time-sampled when they move) with their names in ``synthua:keypointNames`` (token[], uniform; the order
  of :data:`synthua_usd.model.keypoint_classes.KEYPOINT_CLASSES`).

Layout of one agent (``*`` marks instance roots, ``->`` their prototype)::

    Agent_0007            translate, rotateZ (time-sampled)
      Person              label person, synthua:uses -> ../ManualWheelchair, synthua:keypoints (time-sampled)
        Torso             (static when seated)
          Skin*           material:binding -> Looks/Skin3       -> Prototypes/Body51ManualWheelchairTorsoSkin_0
          Upper*          material:binding -> Looks/Shirt1      -> ...
        ForearmL          translate, orient (time-sampled: the push stroke)
          ...
      ManualWheelchair*   label manual_wheelchair, synthua:keypoints -> Prototypes/ManualWheelchair_85_47_46
"""

from __future__ import annotations

from collections import Counter

import numpy as np
from pxr import Gf, Kind, Sdf, Usd, UsdGeom, UsdShade, Vt

from synthua_usd.agents.crowd import Crowd
from synthua_usd.assets import devices
from synthua_usd.assets.agent_keypoints import body_keypoints, contact_points
from synthua_usd.assets.bodies import REGIONS, SEGMENTS
from synthua_usd.assets.postures import (AID_OFFSETS, BENCH, STEPPING_AIDS, BodyParts, DeviceFit, aid_shift_m,
                                       bench_fit, segment_motion, step_length_m)
from synthua_usd.composition.scenario import StageMetadata
from synthua_usd.model import meshes as geo
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES
from synthua_usd.model.materials import PALETTE
from synthua_usd.usd.authoring import (apply_label, bind_material, bind_material_path, define_mesh,
                                       define_preview_material, define_xform, new_layer, set_kind)
from synthua_usd.usd.keypoints import KEYPOINT_NAMES_ATTR, KEYPOINTS_ATTR

AGENTS_ROOT = "/World/Agents"
#: Where the shared geometry lives: a ``class`` prim, so it is composed but never rendered itself.
PROTOTYPES = f"{AGENTS_ROOT}/Prototypes"


def prim_name(class_name: str) -> str:
    """``ManualWheelchair`` for ``manual_wheelchair``: a class name as a prim name."""
    return "".join(part.title() for part in class_name.split("_"))


class PrototypeLibrary:
    """The prototypes of one agents layer, authored on first use and shared by content.

    A person part's prototype is an Xform holding one unbound ``Mesh``; two parts with the same points and
    triangles (two agents of one body and posture) get the same prototype. A device's prototype (one per
    class and fit) holds its parts at every placement of :data:`synthua_usd.assets.postures.AID_OFFSETS`,
    each bound to its material.
    Names are the shape with a counter in order of first use, so the same crowd gives the same layer.
    """

    def __init__(self, stage: Usd.Stage, materials: dict[str, UsdShade.Material], root: str = PROTOTYPES) -> None:
        self.stage = stage
        self.materials = materials
        self.root = root
        stage.CreateClassPrim(root)
        self._paths: dict[tuple, Sdf.Path] = {}
        self._counts: Counter[str] = Counter()

    def part(self, shape: str, mesh: geo.Mesh, uvs: np.ndarray | None = None,
             normals: np.ndarray | None = None) -> Sdf.Path:
        """The prototype of a part mesh ``(points (n, 3), triangles (m, 3))``, metres, in the frame of the
        prim that will reference it, with its texture coordinates ``uvs`` (n, 2) and shading ``normals`` (n, 3)
        when given."""
        points = np.ascontiguousarray(mesh[0], np.float32)  # what define_mesh stores: equal here means equal there
        tris = np.ascontiguousarray(mesh[1], np.int32)
        extra = tuple(np.ascontiguousarray(a, np.float32).tobytes() if a is not None else b"" for a in (uvs, normals))
        key = ("part", shape, points.tobytes(), tris.tobytes(), *extra)
        if key not in self._paths:
            path = Sdf.Path(f"{self.root}/{shape}_{self._counts[shape]}")
            self._counts[shape] += 1
            define_xform(self.stage, str(path))
            define_mesh(self.stage, f"{path}/Mesh", points, tris, uvs=uvs, normals=normals)
            self._paths[key] = path
        return self._paths[key]

    def device(self, class_name: str, fit: DeviceFit, model: str = "standard",
               materials: dict[str, Sdf.Path] | None = None, name: str = "") -> Sdf.Path:
        """The prototype of the device ``class_name`` (a key of :data:`synthua_usd.assets.devices.DEVICE_MODELS`)
        in ``model``, sized by ``fit``. Its parts bind the library's materials, or for the palette keys in
        ``materials`` those material paths instead; ``name`` (a prim name) tells such a prototype apart."""
        key = ("device", class_name, model, fit, name)
        if key not in self._paths:
            path = Sdf.Path(f"{self.root}/{name or f'{prim_name(class_name)}_{fit.key()}'}")
            define_xform(self.stage, str(path))
            pieces = devices.DEVICE_MODELS[class_name][model](fit)
            for k, (dx, dy) in enumerate(AID_OFFSETS.get(class_name, [(0.0, 0.0)])):
                for part in pieces:
                    mesh = define_mesh(self.stage, f"{path}/{part.name}{'' if k == 0 else f'_{k}'}",
                                       part.points + [dx, dy, 0.0], part.triangles)
                    if materials and part.material in materials:
                        bind_material_path(mesh.GetPrim(), materials[part.material])
                    else:
                        bind_material(mesh.GetPrim(), self.materials[part.material])
            self._paths[key] = path
        return self._paths[key]


def instance(stage: Usd.Stage, path: str, prototype: Sdf.Path, translate=None) -> Usd.Prim:
    """An instanceable Xform at ``path`` referencing ``prototype``."""
    prim = define_xform(stage, path, translate=translate).GetPrim()
    prim.GetReferences().AddInternalReference(prototype)
    prim.SetInstanceable(True)
    return prim


def _phases(traj, height_m: float, fps: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Per time code, the motion cycle's phase (radians) and amplitude (0 still .. 1 moving at the agent's
    speed); and the cycle's length in metres travelled. Walking: one gait cycle per two steps of :func:`step_length_m` at the agent's speed; a manual
    wheelchair: one push per 1.2 m. The amplitude follows the speed over the last time code, eased over
    three time codes so a stop does not freeze a stride."""
    d = np.asarray(traj.distance_m, float)
    speed = np.diff(d, prepend=d[0]) * fps
    if len(speed) > 1:
        speed[0] = speed[1]
    moving = np.clip(speed / max(traj.plan.speed_mps, 1e-6), 0.0, 1.0)
    amplitude = np.convolve(np.pad(moving, 1, mode="edge"), np.ones(3) / 3, mode="valid")
    cycle = 1.2 if traj.plan.profile.device == "manual_wheelchair" else 2 * step_length_m(traj.plan.speed_mps, height_m)
    return 2 * np.pi * d / cycle, amplitude, cycle


def posture_name(device: str | None) -> str:
    return prim_name(device) if device else "Walk"


def quat(r: np.ndarray) -> Gf.Quatf:
    q = Gf.Matrix3d(*r.T.ravel().tolist()).ExtractRotation().GetQuat()  # Gf matrices act on row vectors
    return Gf.Quatf(q)  # each component rounded to float, as Quatf(real, i, j, k) would; without iterating a Vec3d


def author_keypoints(prim: Usd.Prim, names, points: np.ndarray, times) -> None:
    """``points`` (T, k, 3), the prim's frame, one row per time code of ``times``, as ``synthua:keypoints``
    (a single default value when they never move) and ``names`` as ``synthua:keypointNames``."""
    prim.CreateAttribute(KEYPOINT_NAMES_ATTR, Sdf.ValueTypeNames.TokenArray, custom=True,
                         variability=Sdf.VariabilityUniform).Set(list(names))
    attr = prim.CreateAttribute(KEYPOINTS_ATTR, Sdf.ValueTypeNames.Point3fArray, custom=True)
    points = np.asarray(points, np.float32)
    if len(points) and np.all(points == points[0]):
        attr.Set(Vt.Vec3fArray.FromNumpy(points[0]))
        return
    for t, p in zip(times, points):
        attr.Set(Vt.Vec3fArray.FromNumpy(p), t)


def build_agents_layer(crowd: Crowd, meta: StageMetadata, taxonomy: str, root_path: str = AGENTS_ROOT,
                       time_step: float = 1.0, deactivate: tuple[str, ...] = ()) -> Usd.Stage:
    """The agents layer of ``crowd``: under ``root_path``, one time sample every ``time_step`` time codes from
    ``meta.start_time_code`` (the crowd is simulated at ``crowd.params.time_codes_per_second`` samples a second:
    a sequence's crowd at its frame rate), labels of ``taxonomy``; the prims at ``deactivate`` (the scenario's own
    crowd, where this one stands in for it) overridden inactive."""
    trajectories, looks = crowd.trajectories, crowd.looks
    stage = new_layer(meta, crowd.doc)
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, root_path, kind=Kind.Tokens.group)
    used = set().union(*(look.materials() for look in looks)) if looks else set()
    used |= {p.material for t in trajectories if t.plan.profile.device for p in devices.DEVICES[t.plan.profile.device]()}
    mats = {key: define_preview_material(stage, f"{root_path}/Looks/{key}", PALETTE[key]) for key in sorted(used)}
    library = PrototypeLibrary(stage, mats, root=f"{root_path}/Prototypes")
    bodies = BodyParts()
    times = [Usd.TimeCode(meta.start_time_code + f * time_step) for f in range(len(trajectories[0].positions))] \
        if trajectories else []
    for i, (traj, look) in enumerate(zip(trajectories, looks)):
        profile = traj.plan.profile
        root = define_xform(stage, f"{root_path}/Agent_{i:04d}", kind=Kind.Tokens.group)
        translate, heading = root.AddTranslateOp(), root.AddRotateZOp()
        for t, p, h in zip(times, traj.positions, traj.headings_deg):
            translate.Set(Gf.Vec3d(*map(float, p)), t)
            heading.Set(float(h), t)
        prim = root.GetPrim()
        prim.CreateAttribute("synthua:profile", Sdf.ValueTypeNames.String, custom=True).Set(profile.name)
        prim.CreateAttribute("synthua:speed_mps", Sdf.ValueTypeNames.Double, custom=True).Set(traj.plan.speed_mps)
        if traj.plan.rests:
            prim.CreateAttribute("synthua:behaviour", Sdf.ValueTypeNames.String, custom=True).Set(
                "sits_on_bench" if traj.plan.seat is not None else "rests_at_bench")
        if traj.plan.group is not None:
            prim.CreateAttribute("synthua:group", Sdf.ValueTypeNames.Int, custom=True).Set(traj.plan.group)
        person_xf = define_xform(stage, f"{root.GetPath()}/Person")
        set_kind(person_xf.GetPrim(), Kind.Tokens.component)
        apply_label(person_xf.GetPrim(), taxonomy, "person")
        device = profile.device
        posture = BENCH if traj.plan.seat is not None else device
        fit, base, parts = bodies.get(look.body, posture, bench_fit(traj.plan.seat.seat_height_m) if posture == BENCH else None)
        phase, amplitude, cycle = _phases(traj, float(bodies.bank.height_m[look.body]),
                                          crowd.params.time_codes_per_second)
        if device == "electric_wheelchair":
            amplitude = np.zeros_like(amplitude)
        shifts = [aid_shift_m(device, p, a, cycle) for p, a in zip(phase, amplitude)]
        posed = bodies.posture_cycle(look.body, posture, fit)
        motions = [segment_motion(bodies.bank, look.body, base, posed(p, a, x))
                   for p, a, x in zip(phase, amplitude, shifts)]
        # The Person prim has no transform of its own: the agent frame is its frame.
        author_keypoints(person_xf.GetPrim(), KEYPOINT_CLASSES["person"].names,
                         body_keypoints(bodies.bank, look.body, base, motions), times)
        for name in SEGMENTS:
            seg = define_xform(stage, f"{person_xf.GetPath()}/{name}")
            track = np.stack([m[name] for m in motions]) if motions else np.zeros((0, 3, 4))
            if len(track) and not np.allclose(track, np.eye(3, 4), atol=1e-6):
                translate, orient = seg.AddTranslateOp(), seg.AddOrientOp()
                for t, m in zip(times, track):
                    translate.Set(Gf.Vec3d(*map(float, m[:, 3])), t)
                    orient.Set(quat(m[:, :3]), t)
            for region in REGIONS:
                if (name, region) not in parts:
                    continue
                shape = f"Body{look.body:02d}{posture_name(posture)}{name}{region.title()}"
                part = instance(stage, f"{seg.GetPath()}/{region.title()}", library.part(shape, parts[(name, region)]))
                bind_material(part, mats[look.region_material(region)])
        if profile.device:
            aid = instance(stage, f"{root.GetPath()}/{prim_name(device)}", library.device(device, fit))
            if device in STEPPING_AIDS and times:  # the tips step with the gait
                aid_translate = UsdGeom.Xformable(aid).AddTranslateOp()
                for t, x in zip(times, shifts):
                    aid_translate.Set(Gf.Vec3d(x, 0.0, 0.0), t)
            set_kind(aid, Kind.Tokens.component)
            apply_label(aid, taxonomy, device)
            person_xf.GetPrim().CreateRelationship("synthua:uses", custom=True).SetTargets([aid.GetPath()])
            contacts = contact_points(bodies.bank, look.body, device, fit, base, motions, shifts)
            if device in STEPPING_AIDS and times:  # agent frame -> the stepping aid's own frame
                contacts = contacts - np.asarray(shifts)[:, None, None] * np.array([1.0, 0.0, 0.0])
            author_keypoints(aid, KEYPOINT_CLASSES[device].names, contacts, times)
    for path in deactivate:
        stage.OverridePrim(path).SetActive(False)
    return stage
