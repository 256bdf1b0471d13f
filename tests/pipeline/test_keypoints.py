"""Keypoints in a dataset made by ``synthua generate``, checked against computations that share nothing
with the pipeline's projection and visibility code.

The scene: the demo street with a scripted crowd, a pedestrian walking +x towards a camera that looks at
it frontally from 4 m (35 mm lens on a 36 x 27 mm filmback, 320 x 240 pixels), a manual wheelchair user
and a cane user walking behind and beside it (partly hidden by it).

- Position: the COCO file's person keypoints of the pedestrian land within :data:`MAX_PX` pixels of the
  anny keypoints posed by the full rig (linear blend skinning of the pose at that time, not the rendered
  rigid segments) and within :data:`MAX_JOINT_PX` of the rig's own joints (shoulder, elbow, wrist, hip,
  knee, ankle), projected by our own pinhole arithmetic from the camera prim's USD attributes.
- Visibility: the flags equal those recomputed by the stated rule (:mod:`synthua_usd.dataset.keypoints`)
  from an independent label pass: Embree (through trimesh) casting rays through the pixel centres that
  numpy computes from the lens values.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
import trimesh
from conftest import generate_dataset
from pxr import Usd, UsdGeom
from reference_raycast import labels_of_rays

from synthua_usd.agents.crowd import CrowdParams, scripted_crowd
from synthua_usd.agents.motion import simulate
from synthua_usd.agents.population import Plan
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.assets.bodies import BONES, load_bank, skin_keypoints
from synthua_usd.assets.people import PersonLook
from synthua_usd.assets.postures import fit_device, pose
from synthua_usd.dataset.keypoints import DEPTH_TOLERANCE_M, WINDOW_PX
from synthua_usd.dataset.layout import Layout
from synthua_usd.demo.street import META, street_scenario
from synthua_usd.model.cameras import CameraSpec
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES, PERSON_KEYPOINTS
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.usd.agents_writer import _phases
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.scenario_writer import write_scenario
from synthua_usd.usd.stage_io import open_stage

T = 12.0
WIDTH, HEIGHT = 320, 240
DISTANCE_M = 4.0
#: Rendered rigid segments vs the fully skinned pose (measured: 0.16 px at most); 1 px (1.3 cm at 4 m) allowed.
MAX_PX = 1.0
#: anny's COCO keypoints vs our reduced rig's joints (the regressor puts hips, shoulders and ankles a few
#: centimetres from the bone heads; measured: 2.8 px at most, 1.4 px mean): 4 px (5 cm at 4 m) allowed.
MAX_JOINT_PX = 4.0
#: Keypoint -> the rig joint it stands for.
JOINT_OF = {"left_shoulder": "upperarm.L", "right_shoulder": "upperarm.R", "left_elbow": "lowerarm.L",
            "right_elbow": "lowerarm.R", "left_wrist": "hand.L", "right_wrist": "hand.R", "left_hip": "upperleg.L",
            "right_hip": "upperleg.R", "left_knee": "lowerleg.L", "right_knee": "lowerleg.R", "left_ankle": "foot.L",
            "right_ankle": "foot.R"}
LOOKS = (PersonLook(4, "Skin2", "Shirt0", "Trousers0"), PersonLook(60, "Skin8", "Shirt3", "Trousers2"),
         PersonLook(61, "Skin1", "Shirt2", "Trousers1", "Shoes1", True, False))


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """The stage, the crowd and the pedestrian's position at :data:`T`."""
    routes = [("pedestrian", (-6.0, 0.0), (0.0, 0.0)), ("manual_wheelchair", (-8.0, 0.35), (-2.0, 0.35)),
              ("wooden_cane", (-7.5, -0.6), (-1.5, -0.6))]
    plans = [Plan(PROFILES[name], 1.0, np.array([(*a, 0.0), (*b, 0.0)]), ("road", "road"), 0.0, 0.0)
             for name, a, b in routes]
    params = CrowdParams(density_per_m2=0.01, time_codes=META.time_code_count,
                         time_codes_per_second=META.time_codes_per_second)
    trajectories, dropped = simulate(plans, params.time_codes, params.time_codes_per_second)
    assert dropped == 0
    crowd = scripted_crowd(trajectories, list(LOOKS), params)
    k = int(T - META.start_time_code)
    x = float(trajectories[0].positions[k][0])
    camera = CameraSpec("Front", (x + DISTANCE_M, 0.0, 1.0), (x, 0.0, 1.0), 35.0, 36.0, 27.0, "frontal view")
    spec = dataclasses.replace(street_scenario(), crowd=crowd, cameras=(camera,), render_camera="Front")
    out = tmp_path_factory.mktemp("keypoint_street")
    write_scenario(spec, out)
    return out / "scenario.usda", crowd


@pytest.fixture(scope="module")
def dataset(scene, tmp_path_factory):
    root = tmp_path_factory.mktemp("keypoint_dataset")
    config = root / "front.json"
    config.write_text(json.dumps({
        "name": "front", "images": 1, "render": {"width": WIDTH, "height": HEIGHT, "spp": 1, "max_depth": 2,
                                                 "denoise": False},
        "time_codes": [T], "conditions": ["clear_day"], "seeds": [0], "cameras": ["/World/Cameras/Front"],
        "split": {"train": 1.0, "val": 0.0, "test": 0.0, "seed": 0}, "qa": {"reject": []}, "workers": 1}))
    generate_dataset(root / "out", config=config, scenario=scene[0])
    coco = json.loads((root / "out" / Layout.coco_instances("train")).read_text())
    assert len(coco["images"]) == 1
    return coco


def _annotation(coco: dict, prim_path: str) -> dict:
    found = [a for a in coco["annotations"] if a["prim_path"] == prim_path]
    assert len(found) == 1, f"{prim_path} is not annotated once"
    return found[0]


def _pinhole(stage: Usd.Stage, points: np.ndarray) -> np.ndarray:
    """Our own projection: the camera prim's focal length, apertures (tenths of a unit = mm at 1 m per unit)
    and transform; the camera looks down -Z with +Y up; pixel centres at +0.5 (so the edge is 0)."""
    cam = UsdGeom.Camera(stage.GetPrimAtPath("/World/Cameras/Front"))
    t = Usd.TimeCode(T)
    focal = cam.GetFocalLengthAttr().Get(t)
    h_ap, v_ap = cam.GetHorizontalApertureAttr().Get(t), cam.GetVerticalApertureAttr().Get(t)
    assert abs(h_ap / v_ap - WIDTH / HEIGHT) < 1e-6  # no aperture conform to think about
    to_world = np.array(cam.ComputeLocalToWorldTransform(t)).T  # column vectors
    local = (np.linalg.inv(to_world) @ np.c_[points, np.ones(len(points))].T).T[:, :3]
    f_px = focal * WIDTH / h_ap
    return np.c_[WIDTH / 2 + f_px * local[:, 0] / -local[:, 2], HEIGHT / 2 - f_px * local[:, 1] / -local[:, 2]]


def _agent_to_world(stage: Usd.Stage, k: int) -> np.ndarray:
    return np.array(UsdGeom.Xformable(stage.GetPrimAtPath(f"/World/Agents/Agent_{k:04d}"))
                    .ComputeLocalToWorldTransform(Usd.TimeCode(T))).T


def test_frontal_person_keypoints_land_on_the_independently_projected_rig(scene, dataset):
    path, crowd = scene
    stage = Usd.Stage.Open(str(path))
    bank = load_bank()
    traj, look = crowd.trajectories[0], crowd.looks[0]
    phase, amplitude, _ = _phases(traj, float(bank.height_m[look.body]), META.time_codes_per_second)
    k = int(T - META.start_time_code)
    assert amplitude[k] > 0.9, "the pedestrian should be mid-stride"
    rest = bank.joints[look.body]
    now = pose(bank, look.body, None, fit_device(bank, look.body, None), phase[k], amplitude[k])
    to_world = _agent_to_world(stage, 0)
    world = lambda p: (to_world[:3, :3] @ p.T).T + to_world[:3, 3]  # noqa: E731
    posed = world(skin_keypoints(bank.keypoints[look.body], bank, now.skinning(rest)))
    joints = world(now.joints[[BONES.index(JOINT_OF[n]) for n in PERSON_KEYPOINTS[5:]]])

    ann = _annotation(dataset, "/World/Agents/Agent_0000/Person")
    kp = np.array(ann["keypoints"], float).reshape(-1, 3)
    assert (kp[:, 2] > 0).all(), "a person seen frontally in full has every keypoint labelled"
    assert kp[kp[:, 2] == 2].shape[0] >= 13, f"visible: {kp[:, 2]}"
    off_posed = np.linalg.norm(kp[:, :2] - _pinhole(stage, posed), axis=1)
    off_joints = np.linalg.norm(kp[5:, :2] - _pinhole(stage, joints), axis=1)
    print(f"pixels from the fully posed keypoints: max {off_posed.max():.2f}, mean {off_posed.mean():.2f}; "
          f"from the rig joints: max {off_joints.max():.2f}, mean {off_joints.mean():.2f}")
    assert off_posed.max() <= MAX_PX
    assert off_joints.max() <= MAX_JOINT_PX
    # frontal: the person's left side is on the image's right
    assert kp[PERSON_KEYPOINTS.index("left_shoulder"), 0] > kp[PERSON_KEYPOINTS.index("right_shoulder"), 0]


def test_visibility_flags_agree_with_an_independent_label_pass(scene, dataset):
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    stage = open_stage(scene[0])
    snapshot = StageReader(stage, ClassMap.default()).snapshot(T)
    camera = read_camera(stage, "/World/Cameras/Front", T)
    origins, dirs = camera.pixel_center_rays(WIDTH, HEIGHT)
    _, instance_ids = labels_of_rays(snapshot, origins, dirs, WIDTH, HEIGHT)
    verts, faces, _ = snapshot.world_triangles()
    locations, index, _ = RayMeshIntersector(trimesh.Trimesh(verts, faces, process=False, validate=False)
                                             ).intersects_location(origins, dirs, multiple_hits=False)
    z = np.zeros(WIDTH * HEIGHT)
    z[index] = (locations - camera.origin) @ camera.axes()[2]
    z = z.reshape(HEIGHT, WIDTH)

    by_path = {i.prim_path: i.id for i in snapshot.instances}
    counts = np.zeros(3, int)
    checked = 0
    for ann in dataset["annotations"]:
        if "keypoints" not in ann:
            continue
        inst = by_path[ann["prim_path"]]
        world = snapshot.keypoints[inst].points
        cam = (world - camera.origin) @ np.stack(camera.axes()).T  # right, up, forward
        kp = np.array(ann["keypoints"], float).reshape(-1, 3)
        assert len(kp) == len(KEYPOINT_CLASSES[snapshot.instance(inst).class_name].names)
        for (u, v, flag), depth in zip(kp, cam[:, 2]):
            if flag == 0:
                continue
            col, row = int(u), int(v)
            window = (slice(max(0, row - WINDOW_PX), row + WINDOW_PX + 1),
                      slice(max(0, col - WINDOW_PX), col + WINDOW_PX + 1))
            expected = 2 if ((instance_ids[window] == inst) & (z[window] >= depth - DEPTH_TOLERANCE_M)).any() else 1
            assert flag == expected, f"{ann['prim_path']} at ({u:.1f}, {v:.1f}): flag {flag}, Embree says {expected}"
            counts[int(flag)] += 1
            checked += 1
    print(f"flags checked: {checked} (occluded {counts[1]}, visible {counts[2]})")
    assert counts[1] > 0 and counts[2] > 0, "the scene should hold both visible and occluded keypoints"
