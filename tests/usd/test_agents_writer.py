"""The agents layer: shared (instanceable) person and device prototypes, with every agent keeping its own
labelled prims, ids, relation, colours and motion."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import STAGES
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade

from synthua_usd.agents.crowd import CrowdParams, scripted_crowd
from synthua_usd.agents.motion import simulate
from synthua_usd.agents.population import Plan
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.assets.bodies import REGIONS, SEGMENTS, load_bank
from synthua_usd.assets.people import PersonLook
from synthua_usd.assets.postures import STEPPING_AIDS, aid_shift_m, step_length_m
from synthua_usd.core.errors import StageError
from synthua_usd.demo.street import META, street_scenario
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES, PERSON_KEYPOINTS
from synthua_usd.usd.agents_writer import AGENTS_ROOT, PROTOTYPES, build_agents_layer
from synthua_usd.usd.keypoints import KEYPOINT_NAMES_ATTR, KEYPOINTS_ATTR
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.scenario_writer import write_scenario
from synthua_usd.usd.semantics import renderable_gprims
from synthua_usd.usd.stage_checks import validate_stage
from synthua_usd.usd.stage_io import open_stage

# Two of one body in different colours (shared shapes, own materials) and one of another body.
LOOKS = (PersonLook(4, "Skin2", "Shirt0", "Trousers0"), PersonLook(4, "Skin8", "Shirt3", "Trousers2", "Shoes2", False),
         PersonLook(60, "Skin1", "Shirt2", "Trousers1", "Shoes1", True, False))


@pytest.fixture(scope="module")
def crowd():
    """Every profile once plus three more pedestrians (12 agents) on a 3 x 4 grid in the street's CCTV view,
    all walking +x at 1 m/s."""
    profiles = list(PROFILES) + ["pedestrian"] * 3
    plans = []
    for k, name in enumerate(profiles):
        x, y = -4.0 + 3.0 * (k % 4), -2.4 + 2.4 * (k // 4)
        plans.append(Plan(PROFILES[name], 1.0, np.array([(x, y, 0.0), (x + 4.0, y, 0.0)]), ("road", "road"), 0.0, 0.0))
    params = CrowdParams(density_per_m2=0.01, time_codes=META.time_code_count,
                         time_codes_per_second=META.time_codes_per_second)
    trajectories, dropped = simulate(plans, params.time_codes, params.time_codes_per_second)
    assert dropped == 0
    return scripted_crowd(trajectories, [LOOKS[k % len(LOOKS)] for k in range(len(trajectories))], params)


@pytest.fixture(scope="module")
def scenario(crowd, tmp_path_factory):
    """The demo street's layers with ``crowd`` as its agents layer (``agents.usdc``)."""
    out = tmp_path_factory.mktemp("instanced_street")
    write_scenario(dataclasses.replace(street_scenario(), crowd=crowd), out)
    return out / "scenario.usda"


@pytest.fixture(scope="module")
def stage(scenario):
    return open_stage(scenario)


@pytest.fixture(scope="module")
def deinstanced(scenario):
    """The same scenario with instancing switched off in the session layer: every instance becomes ordinary
    prims composed from its prototype's specs."""
    stage = open_stage(scenario)
    roots = [p.GetPath() for p in stage.Traverse() if p.IsInstance()]
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        for path in roots:
            stage.GetPrimAtPath(path).SetInstanceable(False)
    assert not stage.GetPrototypes()
    return stage


def _agents(stage):
    return [p for p in stage.GetPrimAtPath(AGENTS_ROOT).GetChildren() if p.GetName().startswith("Agent_")]


def _part_count(stage) -> int:
    """Person parts: one instance per (segment, garment region) of every agent's body."""
    return sum(1 for p in stage.Traverse() if p.IsInstance() and "/Person/" in str(p.GetPath()))


def _meshes(snapshot) -> dict:
    return {m.prim_path: m for m in snapshot.meshes}


def test_agents_layer_is_a_crate_and_the_scenario_validates_clean(scenario, stage, class_map):
    layer = Sdf.Layer.FindOrOpen(str(scenario.parent / "agents.usdc"))
    assert layer.GetFileFormat().formatId == "usdc"
    assert validate_stage(stage, class_map) == []


def test_prototypes_are_shared_between_agents(stage, crowd):
    instances = [p for p in stage.Traverse() if p.IsInstance()]
    assert len(instances) == _part_count(stage) + 8  # and one per device
    # Agents 9, 10 and 11 walk with bodies 4, 4 and 60: the first two share every part.
    assert len(stage.GetPrototypes()) < len(instances)
    nine, ten = ([p.GetPrototype() for p in Usd.PrimRange(_agents(stage)[k]) if p.IsInstance()] for k in (9, 10))
    assert nine == ten and len(nine) >= 12
    person = _agents(stage)[0].GetChild("Person")
    assert [p.GetName() for p in person.GetChildren()] == list(SEGMENTS)
    assert {p.GetName() for p in person.GetChild("Torso").GetChildren()} <= {r.title() for r in REGIONS}


def test_one_shape_takes_each_agents_own_material(stage, crowd):
    """Agents 9 and 10 are pedestrians of one body in different clothes (LOOKS[0] and LOOKS[1])."""
    a, b = (_agents(stage)[k].GetChild("Person").GetChild("Torso").GetChild("Upper") for k in (9, 10))
    assert crowd.looks[9].body == crowd.looks[10].body and crowd.looks[9].shirt != crowd.looks[10].shirt
    assert a.GetPrototype() == b.GetPrototype()
    for root, shirt in ((a, crowd.looks[9].shirt), (b, crowd.looks[10].shirt)):
        proxy = root.GetChild("Mesh")
        assert proxy.IsInstanceProxy()
        bound, _ = UsdShade.MaterialBindingAPI(proxy).ComputeBoundMaterial()
        assert bound.GetPath() == Sdf.Path(f"{AGENTS_ROOT}/Looks/{shirt}")


def test_prototypes_themselves_are_never_rendered(stage):
    assert stage.GetPrimAtPath(PROTOTYPES).GetSpecifier() == Sdf.SpecifierClass
    assert not [p for p in renderable_gprims(stage) if str(p.GetPath()).startswith(PROTOTYPES)]
    assert not [p for p in renderable_gprims(stage) if p.IsInPrototype()]


def test_each_agent_keeps_its_own_person_and_device_instance_and_relation(stage, crowd, class_map):
    snapshot = StageReader(stage, class_map).snapshot(1.0)
    by_path = {i.prim_path: i for i in snapshot.instances}
    ids = set()
    for prim, traj in zip(_agents(stage), crowd.trajectories):
        person = by_path[f"{prim.GetPath()}/Person"]
        assert person.class_name == "person"
        ids.add(person.id)
        device = traj.plan.profile.device
        if device is None:
            assert person.relations == ()
            continue
        (name, target), = person.relations
        assert name == "uses" and by_path[target].class_name == device and target.startswith(f"{prim.GetPath()}/")
        ids.add(by_path[target].id)
    assert len(ids) == len(crowd.trajectories) + sum(1 for t in crowd.trajectories if t.plan.profile.device)
    # Every agent mesh carries the id of its own agent's labelled prim.
    for mesh in snapshot.meshes:
        if mesh.prim_path.startswith(AGENTS_ROOT):
            owner = next(i for i in snapshot.instances if i.id == mesh.instance_id)
            assert mesh.prim_path.startswith(owner.prim_path + "/")


@pytest.mark.parametrize("time_code", [1.0, 24.0, 48.0])
def test_instanced_and_deinstanced_snapshots_are_identical(stage, deinstanced, crowd, class_map, time_code):
    a = _meshes(StageReader(stage, class_map).snapshot(time_code))
    b = _meshes(StageReader(deinstanced, class_map).snapshot(time_code))
    assert a.keys() == b.keys()
    # Device meshes: wheelchairs 4 each, walker 2, crutches 2 x 2, smart cane 3, three canes 1, 1, 2.
    assert sum(1 for p in a if p.startswith(AGENTS_ROOT)) == _part_count(stage) + 4 + 4 + 2 + 4 + 3 + 1 + 1 + 2
    for path, m in a.items():
        n = b[path]
        assert (m.instance_id, m.class_id, m.material_key) == (n.instance_id, n.class_id, n.material_key), path
        assert np.array_equal(m.triangles, n.triangles) and np.array_equal(m.points, n.points), path


def test_flattened_layer_reads_the_same(stage, class_map):
    flat = Usd.Stage.Open(stage.Flatten())
    a = _meshes(StageReader(stage, class_map).snapshot(24.0))
    b = _meshes(StageReader(flat, class_map).snapshot(24.0))
    assert a.keys() == b.keys()
    assert all(np.array_equal(a[k].points, b[k].points) and a[k].instance_id == b[k].instance_id for k in a)


def test_label_maps_are_byte_identical_instanced_and_deinstanced(stage, deinstanced, class_map):
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.usd.cameras import read_camera

    camera = read_camera(stage, "/World/Cameras/CCTV", 24.0)
    maps = []
    for s in (stage, deinstanced):
        session = RenderSession(RenderConfig(width=160, height=120, spp=1, variant=None))
        frame = session.render(StageReader(s, class_map).snapshot(24.0), camera, rgb=False)
        maps.append((frame.class_ids, frame.instance_ids))
    (ca, ia), (cb, ib) = maps
    assert ca.tobytes() == cb.tobytes() and ia.tobytes() == ib.tobytes()
    seen = {i.class_name for i in StageReader(stage, class_map).instances.values() if i.id in set(np.unique(ia).tolist())}
    assert "person" in seen and len(seen & set(p.device for p in PROFILES.values() if p.device)) >= 4


def test_instance_proxies_under_animated_roots_move_between_time_codes(stage, deinstanced, class_map):
    reader = StageReader(stage, class_map)
    first, later, again = (_meshes(reader.snapshot(t)) for t in (1.0, 24.0, 1.0))
    agent = str(_agents(stage)[0].GetPath())  # a pedestrian: walks and swings its limbs
    for part in ("Person/Torso/Upper/Mesh", "Person/ThighL/Lower/Mesh", "Person/UpperArmR/Upper/Mesh"):
        path = f"{agent}/{part}"
        assert not np.allclose(first[path].points, later[path].points)
        assert np.array_equal(first[path].points, again[path].points)
    # The thigh's swing (its segment's time-sampled orientation) is applied, not only the agent's translation.
    leg = f"{agent}/Person/ThighL/Lower/Mesh"
    body = f"{agent}/Person/Torso/Upper/Mesh"
    shift = later[body].points.mean(0) - first[body].points.mean(0)
    assert not np.allclose(later[leg].points - first[leg].points, shift, atol=1e-3)
    device = f"{_agents(stage)[1].GetPath()}/ManualWheelchair/Seat"
    assert stage.GetPrimAtPath(device).IsInstanceProxy()
    assert not np.allclose(first[device].points, later[device].points)
    fresh = _meshes(StageReader(deinstanced, class_map).snapshot(24.0))
    assert all(np.array_equal(later[k].points, fresh[k].points) for k in later)


def test_same_crowd_gives_byte_identical_crate(crowd, tmp_path, class_map):
    paths = []
    for name in ("a.usdc", "b.usdc"):
        built = build_agents_layer(crowd, META, class_map.taxonomy)  # the stage owns its root layer: keep it
        built.GetRootLayer().Export(str(tmp_path / name))
        paths.append(tmp_path / name)
    assert paths[0].read_bytes() == paths[1].read_bytes()


def test_a_crowd_standing_in_for_the_scenarios_deactivates_it(crowd, class_map):
    """A sequence's crowd layer (under its own root) overrides the scenario's crowd inactive, and nothing else."""
    built = build_agents_layer(crowd, META, class_map.taxonomy, root_path="/World/SequenceAgents",
                               deactivate=(AGENTS_ROOT,))  # the stage owns its root layer: keep it
    spec = built.GetRootLayer().GetPrimAtPath(Sdf.Path(AGENTS_ROOT))
    assert spec.specifier == Sdf.SpecifierOver and spec.active is False and not spec.nameChildren
    world = built.GetRootLayer().GetPrimAtPath(Sdf.Path("/World"))
    assert list(world.nameChildren.keys()) == ["SequenceAgents", "Agents"]
    assert not world.nameChildren["SequenceAgents"].HasInfo("active")


def test_random_looks_draw_bodies_of_their_stratum_and_every_skin_tone():
    from synthua_usd.assets.bodies import load_bank
    from synthua_usd.model.materials import SKINS
    bank = load_bank()
    rng = np.random.default_rng(5)
    walkers = [PersonLook.random(rng) for _ in range(400)]
    users = [PersonLook.random(rng, aid_user=True) for _ in range(100)]
    assert not any(bank.aid_stratum[l.body] for l in walkers) and all(bank.aid_stratum[l.body] for l in users)
    assert {l.skin for l in walkers} == {m.key for m in SKINS}
    assert min(bank.years[l.body] for l in users) >= 50


@pytest.mark.parametrize("layer", ["agents.usdc", "district/agents.usdc"])
def test_shipped_agents_layers_are_instanced(layer):
    """The street's two agents have bodies of their own (nothing to share); the district's crowd shares."""
    stage = Usd.Stage.Open(str(STAGES / layer))
    instances = sum(1 for p in stage.Traverse() if p.IsInstance())
    assert instances > 0 and all(p.IsInstance() for p in stage.Traverse() if p.GetName() in ("Skin", "Upper"))
    if layer.startswith("district"):
        assert 0 < len(stage.GetPrototypes()) < instances / 1.5


@pytest.mark.parametrize("time_code", [1.0, 24.0])
def test_every_person_and_device_carries_keypoints_on_its_rendered_geometry(stage, crowd, class_map, time_code):
    """The reader's world keypoints (the agent's time-sampled transform applied to the authored ones) lie
    in the world box of the instance's rendered meshes, grown by 5 cm (a hand holds a grip from outside)."""
    snapshot = StageReader(stage, class_map).snapshot(time_code)
    by_path = {i.prim_path: i for i in snapshot.instances}
    for prim, traj in zip(_agents(stage), crowd.trajectories):
        device = traj.plan.profile.device
        for path, cls in [(f"{prim.GetPath()}/Person", "person")] + (
                [(f"{prim.GetPath()}/{''.join(p.title() for p in device.split('_'))}", device)] if device else []):
            inst = by_path[path]
            # a person's keypoints are in the agent's frame: the Person prim must not move on its own (a stepping
            # aid's prim does: its contact points are in its own frame, checked by their place in the world below)
            if cls == "person":
                assert not UsdGeom.Xformable(stage.GetPrimAtPath(path)).GetOrderedXformOps(), path
            found = snapshot.keypoints[inst.id]
            assert found.names == KEYPOINT_CLASSES[cls].names
            points = np.concatenate([m.points for m in snapshot.meshes if m.instance_id == inst.id])
            if cls == "person":
                lo, hi = points.min(axis=0) - 0.05, points.max(axis=0) + 0.05
            else:  # the device's contacts: its box joined with its user's
                user = np.concatenate([m.points for m in snapshot.meshes if m.instance_id == by_path[f"{prim.GetPath()}/Person"].id])
                lo, hi = np.minimum(points.min(0), user.min(0)) - 0.05, np.maximum(points.max(0), user.max(0)) + 0.05
            assert ((found.points >= lo) & (found.points <= hi)).all(), path
    assert len(snapshot.keypoints) == len(crowd.trajectories) + sum(1 for t in crowd.trajectories if t.plan.profile.device)


def test_keypoints_named_otherwise_are_refused(scenario, class_map, tmp_path):
    stage = open_stage(scenario)
    person = stage.GetPrimAtPath(f"{AGENTS_ROOT}/Agent_0000/Person")
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        person.GetAttribute(KEYPOINT_NAMES_ATTR).Set(list(PERSON_KEYPOINTS[1:]) + ["nose"])
    with pytest.raises(StageError, match="synthua:keypointNames is .* expected the keypoints of class person"):
        StageReader(stage, class_map)
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        person.GetAttribute(KEYPOINT_NAMES_ATTR).Set(list(PERSON_KEYPOINTS))
        person.GetAttribute(KEYPOINTS_ATTR).Set([(0.0, 0.0, 0.0)] * 16, Usd.TimeCode(3.0))
    reader = StageReader(stage, class_map)
    with pytest.raises(StageError, match="holds 16 points.*expected 17"):
        reader.snapshot(3.0)


def test_crutches_and_canes_step_with_the_gait_and_the_hands_go_with_them(stage, crowd, class_map):
    """A stepping aid's device prim has a forward translate per time code equal to :func:`aid_shift_m` of the
    agent's gait (an independent recomputation from the agent's travelled distance), and the holding hand's
    mesh moves with it: the world distance between the aid's grip and the hand stays within a few cm."""
    reader = StageReader(stage, class_map)
    checked = 0
    for k, traj in enumerate(crowd.trajectories):
        device = traj.plan.profile.device
        if device not in STEPPING_AIDS:
            continue
        look = crowd.looks[k]
        cycle = 2 * step_length_m(traj.plan.speed_mps, float(load_bank().height_m[look.body]))
        aid = stage.GetPrimAtPath(f"{AGENTS_ROOT}/Agent_{k:04d}/{''.join(p.title() for p in device.split('_'))}")
        translate = UsdGeom.Xformable(aid).GetOrderedXformOps()[0]
        assert translate.GetNumTimeSamples() == len(traj.positions)
        shifts = [translate.Get(Usd.TimeCode(META.start_time_code + f))[0] for f in range(len(traj.positions))]
        # Walking at constant speed: the amplitude is 1 once moving.
        expected = [aid_shift_m(device, 2 * np.pi * d / cycle, 1.0, cycle) for d in traj.distance_m]
        assert np.allclose(shifts[2:], expected[2:], atol=1e-6)
        assert np.ptp(shifts) > 0.1
        gaps = []
        for f in (5, 15, 30):
            snap = _meshes(reader.snapshot(META.start_time_code + f))
            hand = snap[f"{AGENTS_ROOT}/Agent_{k:04d}/Person/ForearmR/Skin/Mesh"].points
            aid_pts = np.concatenate([m.points for p, m in snap.items() if p.startswith(str(aid.GetPath()) + "/")])
            top = aid_pts[aid_pts[:, 2] > aid_pts[:, 2].max() - (0.3 if device == "crutch" else 0.05)]
            gaps.append(float(np.min(np.linalg.norm(hand[:, None] - top[None], axis=-1))))
        assert max(gaps) < 0.05, (device, gaps)
        checked += 1
    assert checked == 5  # crutches and four canes


def test_segment_orientations_round_each_quaternion_component_to_float():
    """quat() converts Gf's double quaternion with Quatf(Quatd): the same floats as rounding the real part and
    each imaginary component one by one (what the layers were written with before), for any rotation."""
    from scipy.spatial.transform import Rotation

    from synthua_usd.usd.agents_writer import quat

    rng = np.random.default_rng(5)
    rotations = Rotation.random(2000, random_state=6).as_matrix()
    for r in np.concatenate([rotations, rotations + rng.normal(0, 1e-7, rotations.shape), np.eye(3)[None]]):
        q = Gf.Matrix3d(*r.T.ravel().tolist()).ExtractRotation().GetQuat()
        expected = Gf.Quatf(float(q.GetReal()), *(float(q.GetImaginary()[i]) for i in range(3)))
        assert quat(r) == expected, r
