"""Automatic cameras and the generated ground of imported twins, checked with an independent ray cast (Embree
through trimesh) on the written scenario."""

import json

import numpy as np
import pytest

from reference_raycast import reference_labels
from synthua_usd.composition.scenario import ROOT_FILE
from synthua_usd.geometry.ground import ground_object, height_at
from synthua_usd.model.materials import class_material, subset
from synthua_usd.model.meshes import box, merge
from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart
from synthua_usd.pipeline.twin_import import MIN_LABELLED_SHARE, REPORT_FILE, write_import

SIZE = (96, 72)


def _obj(path, label, mesh):
    return TwinObject(path, label, (TwinPart.of("Surface", mesh, class_material(label).key),))


def _model(objects, source="synthetic"):
    return TwinModel(tuple(objects), subset(p.material for o in objects for p in o.parts), source)


def _slab(x0, y0, x1, y1, z0=0.0, z1=0.0):
    """A road quad from (x0, y0) to (x1, y1) rising linearly from z0 (at x0) to z1 (at x1), facing up."""
    pts = np.array([[x0, y0, z0], [x1, y0, z1], [x1, y1, z1], [x0, y1, z0]], float)
    return pts, np.array([[0, 1, 2], [0, 2, 3]])


def _written(model, tmp_path, class_map):
    _, report = write_import(model, tmp_path / "twin", class_map, {"findings": []})
    return report


def _reference(tmp_path, class_map, camera):
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(tmp_path / "twin" / ROOT_FILE)
    snapshot = StageReader(stage, class_map).snapshot(1)
    cam = read_camera(stage, f"/World/Cameras/{camera}", 1)
    classes, _ = reference_labels(snapshot, cam, *SIZE)
    return snapshot, cam, classes


@pytest.mark.slow
def test_sparse_model_overview_frames_the_densest_cluster(tmp_path, class_map):
    """Thirty 12 m buildings in a 150 m block, three lone barns 8-9 km away (a model over 9 x 10 km): the
    overview frames the block. Framed on the whole extent (as before), a 74-degree view from 1.4 radii saw
    the block as a few dozen pixels."""
    rng = np.random.default_rng(4)
    objects = [_obj(f"B/b{k}", "building", box((x, y, 0), (x + 12, y + 12, rng.uniform(8, 20))))
               for k, (x, y) in enumerate(rng.uniform(0, 150, (30, 2)))]
    objects += [_obj(f"B/far{k}", "building", box((x, y, 0), (x + 10, y + 10, 6)))
                for k, (x, y) in enumerate([(8000, 500), (8500, 9000), (300, 9500)])]
    objects.append(_obj("R/road", "road", _slab(-50, 90, 250, 110)))
    report = _written(_model(objects), tmp_path, class_map)
    overview = report["cameras"]["Overview"]
    assert overview["cluster_objects"] == 30 and overview["objects"] == 33
    _, _, classes = _reference(tmp_path, class_map, "Overview")
    share = float(np.mean(classes != 0))
    assert share == pytest.approx(overview["labelled_share"], abs=0.02)  # Mitsuba's label pass agrees
    assert share >= MIN_LABELLED_SHARE and np.mean(classes == class_map.resolve("building").id) >= MIN_LABELLED_SHARE
    assert not [f for f in report["findings"] if f["rule"] == "camera-coverage" and "Overview" in f["where"]]


@pytest.mark.slow
def test_small_model_is_not_cut_off(tmp_path, class_map):
    """One 4 x 4 x 3 m hut on a 6 x 6 m yard: the overview holds all of it (no building pixel on the border)."""
    report = _written(_model([_obj("B/hut", "building", box((0, 0, 0), (4, 4, 3))),
                              _obj("R/yard", "road", _slab(-1, -1, 5, 5))]), tmp_path, class_map)
    _, _, classes = _reference(tmp_path, class_map, "Overview")
    building = classes == class_map.resolve("building").id
    assert building.mean() > 0.1
    border = np.concatenate([building[0], building[-1], building[:, 0], building[:, -1]])
    assert not border.any()
    assert report["cameras"]["Overview"]["labelled_share"] >= MIN_LABELLED_SHARE


@pytest.mark.slow
def test_street_camera_stands_above_rising_ground_and_nothing_shows_under_the_world(tmp_path, class_map):
    """A street climbing 30 m over 300 m with houses on both sides: the street camera stands 1.6 m above the
    road under it (before: 1.6 m above the model's lowest vertex, under the road where it rises), looks along
    the street, and every pixel below its horizon hits geometry (the generated ground reaches past the model)."""
    objects = [_obj("R/street", "road", _slab(0, -5, 300, 5, 0.0, 30.0))]
    for k, x in enumerate(range(10, 290, 20)):
        for side, (y0, y1) in enumerate(((8, 18), (-18, -8))):
            z = 0.1 * x
            objects.append(_obj(f"B/h{k}_{side}", "building", box((x, y0, z - 1), (x + 15, y1, z + 9))))
    model = _model(objects)
    report = _written(model, tmp_path, class_map)
    street = report["cameras"]["Street"]
    assert street["stands_on"] == "R/street" and street["on_street_surface"]
    snapshot, cam, classes = _reference(tmp_path, class_map, "Street")
    eye = cam.origin
    road_z = 0.1 * eye[0]
    assert eye[2] - road_z == pytest.approx(1.6, abs=0.05)
    assert eye[2] > 0.1 * 150 - 12 > 1.6  # above the road where it has risen, not at the bottom of the slope
    _, _, forward = cam.axes()
    assert abs(forward[0]) > 0.95  # along the street (x)
    ground = ground_object(model)
    assert height_at(ground, eye[None, :2])[0] < eye[2] - 1.5
    # Below the horizon every ray hits something: the twin or the ground.
    origins, dirs = cam.pixel_center_rays(*SIZE)
    import trimesh
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    verts, faces, _ = snapshot.world_triangles()
    hits = RayMeshIntersector(trimesh.Trimesh(verts, faces, process=False)).intersects_first(origins, dirs)
    below = dirs[:, 2] < -0.01
    assert below.sum() > 0.3 * len(dirs) and (hits[below] >= 0).all()
    assert street["labelled_share"] == pytest.approx(float(np.mean(classes != 0)), abs=0.02)
    assert json.loads((tmp_path / "twin" / REPORT_FILE).read_text())["ground"]["path"] == "Ground/Surroundings"


def test_ground_follows_the_model_and_reaches_past_it():
    objects = [_obj("R/street", "road", _slab(0, -5, 300, 5, 0.0, 30.0)),
               _obj("B/h", "building", box((100, 10, 10), (110, 20, 20)))]
    ground = ground_object(_model(objects))
    assert ground.label == "unlabelled"
    pts = ground.parts[0].points
    assert pts[:, 0].min() < -10_000 and pts[:, 0].max() > 10_000
    # Under the road it follows the road (5 cm below), rising with it.
    xy = np.array([[20.0, 0.0], [150.0, 0.0], [280.0, 0.0]])
    assert height_at(ground, xy) == pytest.approx(0.1 * xy[:, 0] - 0.05, abs=0.5)
    # Faces point up.
    tri = pts[ground.parts[0].triangles]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    assert (n[:, 2] > 0).all()


def _inside_any(point, boxes):
    return any(np.all(point > lo) and np.all(point < hi) for lo, hi in boxes)


def test_street_camera_of_a_dense_block_without_streets_stands_outside(tmp_path, class_map):
    """A 5 x 5 block of 10 m houses 1 m apart, no street surfaces: every ground spot near the centre is under a
    roof. Before, the camera fell back to the ground under the centre, inside a house (free view 0 m, the
    interior 'labelled' and no finding); now it stands on a ring round the block, in free space."""
    boxes = [((x, y, 0.0), (x + 10, y + 10, 8.0)) for x in range(0, 55, 11) for y in range(0, 55, 11)]
    objects = [_obj(f"B/h{k}", "building", box(lo, hi)) for k, (lo, hi) in enumerate(boxes)]
    report = _written(_model(objects), tmp_path, class_map)
    street = report["cameras"]["Street"]
    _, cam, classes = _reference(tmp_path, class_map, "Street")
    assert not _inside_any(cam.origin, boxes) and street["placement"]["free_space"]
    assert street["free_view_m"] >= 5.0 and street["stands_on"] == "Ground/Surroundings"
    assert np.mean(classes == class_map.resolve("building").id) > 0.1  # it sees the block from outside
    assert not [f for f in report["findings"] if f["rule"] == "camera-placement"]


def test_a_camera_with_no_free_spot_is_a_finding(tmp_path, class_map):
    """The whole twin inside a closed, unlabelled hall 400 m wide: no spot is outdoors, and both cameras say why."""
    objects = [_obj("B/house", "building", box((0, 0, 0), (10, 10, 8))),
               _obj("R/road", "road", _slab(-30, -8, 40, -2)),
               _obj("X/hall", "unlabelled", box((-200, -200, -1), (200, 200, 60)))]
    report = _written(_model(objects), tmp_path, class_map)
    placement = {f["where"]: f["message"] for f in report["findings"] if f["rule"] == "camera-placement"}
    assert sorted(placement) == ["/World/Cameras/Overview", "/World/Cameras/Street"]
    assert all("inside a closed surface" in m for m in placement.values())
    assert report["cameras"]["Street"]["placement"]["free_space"] is False
