"""Labels are checked against an independent computation: Embree ray casting of the same triangles."""

import numpy as np
import pytest

from conftest import SCENARIO
from reference_raycast import reference_labels
from synthua_usd.pipeline.frame import FrameRequest, run_frame

CAMERAS = ["/World/Cameras/CCTV", "/World/Cameras/PedestrianEye", "/World/Cameras/WheelchairEye"]


@pytest.fixture(scope="module", params=CAMERAS)
def frame(request, tmp_path_factory):
    out = tmp_path_factory.mktemp("frame")
    return run_frame(FrameRequest(stage_path=SCENARIO, out_dir=out, camera_path=request.param, frame=24,
                                  width=320, height=240, spp=1))


@pytest.mark.slow
def test_labels_agree_with_embree(frame):
    ref_class, ref_inst = reference_labels(frame.snapshot, frame.camera, 320, 240)
    r = frame.rendered
    class_agree = np.mean(ref_class == r.class_ids)
    inst_agree = np.mean(ref_inst == r.instance_ids)
    print(f"{frame.camera.path}: class agreement {class_agree:.6%}, instance agreement {inst_agree:.6%}")
    assert class_agree >= 0.9999 and inst_agree >= 0.9999


@pytest.mark.slow
def test_every_instance_visible_to_embree_is_in_frame_json(frame):
    _, ref_inst = reference_labels(frame.snapshot, frame.camera, 320, 240)
    listed = {i["id"]: i for i in frame.document["instances"] if i["pixel_count"] > 0}
    by_path = {i["prim_path"]: i for i in frame.document["instances"]}
    for inst_id in set(np.unique(ref_inst)) - {0}:
        assert inst_id in listed, f"instance {inst_id} visible to Embree is missing from frame.json"
        assert frame.snapshot.instance(inst_id).prim_path in by_path


@pytest.mark.slow
def test_pixel_counts_match_the_instance_map(frame):
    counts = np.bincount(frame.rendered.instance_ids.ravel())
    for inst in frame.document["instances"]:
        expected = counts[inst["id"]] if inst["id"] < len(counts) else 0
        assert inst["pixel_count"] == expected


@pytest.mark.slow
def test_person_and_wheelchair_get_different_ids_and_classes(frame):
    if frame.camera.path == "/World/Cameras/WheelchairEye":
        pytest.skip("the check needs both visible; the CCTV and pedestrian cameras see them")
    by_path = {i["prim_path"]: i for i in frame.document["instances"]}
    person = by_path["/World/Agents/Agent_0001/Person"]
    chair = by_path["/World/Agents/Agent_0001/ManualWheelchair"]
    assert person["pixel_count"] > 0 and chair["pixel_count"] > 0
    assert person["id"] != chair["id"]
    assert (person["class_name"], chair["class_name"]) == ("person", "manual_wheelchair")
    assert person["relations"] == {"uses": chair["prim_path"]}
    inst = frame.rendered.instance_ids
    cls = frame.rendered.class_ids
    assert set(np.unique(cls[inst == person["id"]])) == {person["class_id"]}
    assert set(np.unique(cls[inst == chair["id"]])) == {chair["class_id"]}


@pytest.mark.slow
def test_depth_is_z_depth_of_the_hit(frame):
    r = frame.rendered
    origins, dirs = frame.camera.pixel_center_rays(320, 240)
    _, _, forward = frame.camera.axes()
    hit = r.hits.mesh_index.ravel() >= 0
    z = r.hits.z_m.ravel()
    dist = r.hits.distance_m.ravel()
    assert np.all(z[~hit] == 0) and np.all(z[hit] > 0)
    assert np.allclose(z[hit], dist[hit] * (dirs[hit] @ forward), rtol=1e-4)
