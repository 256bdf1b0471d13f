"""Reading a composed stage into plain scene snapshots: meshes, labels, materials, lights, time."""

import numpy as np
import pytest
from pxr import UsdGeom

from conftest import DATA
from normal_scenes import sphere_stage
from snapshot_checks import assert_same_snapshot
from synthua_usd.core.errors import StageError, UnsupportedPrimError
from synthua_usd.usd.reader import StageReader, read_snapshot
from synthua_usd.usd.semantics import renderable_gprims
from synthua_usd.usd.stage_io import open_stage
from synthua_usd.usd.texcoords import fan_corners


@pytest.fixture(scope="module")
def snap(demo_stage, class_map):
    return read_snapshot(demo_stage, 1.0, class_map)


def test_demo_snapshot_contents(snap, demo_stage):
    assert len(snap.meshes) == len(renderable_gprims(demo_stage))
    assert {l.kind for l in snap.lights} == {"distant", "dome"}
    assert all(m.instance_id > 0 and m.class_id > 0 for m in snap.meshes)
    assert [i.id for i in snap.instances] == list(range(1, len(snap.instances) + 1))


def test_person_and_wheelchair_are_distinct_instances_with_a_relation(snap):
    by_path = {i.prim_path: i for i in snap.instances}
    person = by_path["/World/Agents/Agent_0001/Person"]
    chair = by_path["/World/Agents/Agent_0001/ManualWheelchair"]
    assert person.id != chair.id and (person.class_name, chair.class_name) == ("person", "manual_wheelchair")
    assert dict(person.relations) == {"uses": chair.prim_path}


def test_world_transform_follows_the_animation(demo_stage, class_map):
    """The reader places a body segment by its world transform at the time code (agent root, then the
    segment's gait motion): its points equal the prototype's points under USD's own XformCache, and the
    agent root walks 1.3 m/s along +X (frames 1 -> 25: one second at 24 time codes per second)."""
    path = "/World/Agents/Agent_0000/Person/Torso/Skin/Mesh"
    proxy = demo_stage.GetPrimAtPath(path)
    local = np.array(UsdGeom.Mesh(proxy).GetPointsAttr().Get(), float)
    roots = []
    for t in (1.0, 25.0):
        s = read_snapshot(demo_stage, t, class_map)
        (mesh,) = [m for m in s.meshes if m.prim_path == path]
        world = np.array(UsdGeom.XformCache(t).GetLocalToWorldTransform(proxy), float)  # row vectors
        expected = local @ world[:3, :3] + world[3, :3]
        np.testing.assert_allclose(np.asarray(mesh.points, float), expected, atol=1e-4)
        root = np.array(UsdGeom.XformCache(t).GetLocalToWorldTransform(proxy.GetParent().GetParent().GetParent()
                                                                      .GetParent()), float)
        roots.append(root[3, :3])
    assert roots[1] - roots[0] == pytest.approx([1.3, 0.0, 0.0], abs=1e-5)


def test_instance_ids_are_stable_across_frames(demo_stage, class_map):
    a = read_snapshot(demo_stage, 1.0, class_map).instances
    b = read_snapshot(demo_stage, 48.0, class_map).instances
    assert a == b


def test_reader_reuses_static_meshes_and_rereads_moving_ones(demo_stage, class_map):
    reader = StageReader(demo_stage, class_map)
    a, b = reader.snapshot(1.0), reader.snapshot(24.0)
    fresh = read_snapshot(demo_stage, 24.0, class_map)
    for x, y, z in zip(a.meshes, b.meshes, fresh.meshes, strict=True):
        assert x.prim_path == y.prim_path == z.prim_path
        assert np.array_equal(y.points, z.points) and (y.class_id, y.instance_id) == (z.class_id, z.instance_id)
        if x.prim_path.startswith("/World/Agents/"):  # every agent moves between 1 and 24
            assert x is not y and not np.array_equal(x.points, y.points), x.prim_path
        else:
            assert x is y, x.prim_path
    assert sum(m.prim_path.startswith("/World/Agents/") for m in a.meshes) > 0


def test_tiny_scene_primitives_and_materials(class_map):
    stage = open_stage(DATA / "valid" / "tiny_scene.usda")
    snap = read_snapshot(stage, 1.0, class_map)
    ground, box = snap.meshes
    assert ground.triangles.shape == (2, 3)  # one quad, fan-triangulated
    assert box.points.min(axis=0) == pytest.approx([-0.5, -0.5, 0.0])  # Cube size 1 translated up 0.5
    assert box.points.max(axis=0) == pytest.approx([0.5, 0.5, 1.0])
    assert snap.instance(box.instance_id).class_name == "person"  # alias 'Pedestrian'
    assert snap.materials[ground.material_key].key == "default"


def test_fan_triangulation_skips_degenerate_faces_and_holes():
    counts = np.array([4, 2, 3])
    indices = np.array([0, 1, 2, 3, 4, 5, 6, 7, 8])
    corners, faces = fan_corners(counts, holes={2})
    assert indices[corners].tolist() == [[0, 1, 2], [0, 2, 3]]
    assert faces.tolist() == [0, 0]


def test_unknown_label_is_an_error_naming_the_prim(class_map):
    stage = open_stage(DATA / "invalid" / "unknown_label.usda")
    with pytest.raises(StageError, match="/World/Ground: label 'spaceship' is not a class"):
        read_snapshot(stage, 1.0, class_map)


def test_unsupported_gprim_lists_supported_types(class_map):
    stage = open_stage(DATA / "invalid" / "unsupported_gprim.usda")
    with pytest.raises(UnsupportedPrimError, match="gprim type 'Points' is not supported; supported types: "
                                                   "Capsule, Cone, Cube, Cylinder, Mesh, Sphere"):
        read_snapshot(stage, 1.0, class_map)


def test_frame_outside_time_range(demo_stage, class_map):
    with pytest.raises(StageError, match=r"time code 99 is outside the stage's time range \[1, 48\]"):
        read_snapshot(demo_stage, 99.0, class_map)


def test_reader_through_time_codes_equals_fresh_reads_of_animated_gprims(class_map):
    """A reader carried through time codes (forth and back) returns, at each, what a fresh read returns: a rigidly
    moving gprim re-placed from its cached local geometry, a mirroring scale flipping the winding, points
    that deform, and a gprim that blinks out at time code 2 (so the kept list of renderable gprims is not
    kept)."""
    stage = open_stage(DATA / "valid" / "animated_gprims.usda")
    reader = StageReader(stage, class_map)
    seen = {}
    for t in (1.0, 2.0, 3.0, 1.0, 2.0):
        carried, fresh = reader.snapshot(t), read_snapshot(stage, t, class_map)
        assert [m.prim_path for m in carried.meshes] == [m.prim_path for m in fresh.meshes]
        for a, b in zip(carried.meshes, fresh.meshes):
            assert np.array_equal(a.points, b.points) and np.array_equal(a.triangles, b.triangles), a.prim_path
            assert (a.material_key, a.instance_id, a.class_id) == (b.material_key, b.instance_id, b.class_id)
        seen[t] = {m.prim_path: m for m in fresh.meshes}
    # Not vacuous: each kind of change happens.
    assert "/World/Blink" in seen[1.0] and "/World/Blink" not in seen[2.0]
    assert not np.array_equal(seen[1.0]["/World/Walker/Body"].points, seen[2.0]["/World/Walker/Body"].points)
    assert not np.array_equal(seen[1.0]["/World/Flag"].points, seen[2.0]["/World/Flag"].points)
    mirrored = seen[1.0]["/World/Mirrored"].triangles, seen[2.0]["/World/Mirrored"].triangles
    assert np.array_equal(mirrored[0][:, ::-1], mirrored[1])


def test_rigidly_moving_gprims_are_placed_by_their_own_world_transforms(class_map):
    """The reader places all rigidly moving gprims at once: each one's points equal its authored points moved by
    its own world transform (computed by UsdGeom per prim), and a Cube's corners (half its size around the origin)
    likewise."""
    from pxr import Usd

    stage = open_stage(DATA / "valid" / "animated_gprims.usda")
    reader = StageReader(stage, class_map)
    for t in (1.0, 3.0, 2.0):
        meshes = {m.prim_path: m for m in reader.snapshot(t).meshes}
        for path in ("/World/Mirrored", "/World/Walker/Body"):
            prim = stage.GetPrimAtPath(path)
            m = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode(t)), float)
            if prim.GetTypeName() == "Mesh":
                local = np.array(UsdGeom.Mesh(prim).GetPointsAttr().Get(t), float)
                assert np.allclose(meshes[path].points, local @ m[:3, :3] + m[3, :3], atol=1e-12), (path, t)
            else:  # a Cube: its points span its box moved by the transform
                half = 0.5 * UsdGeom.Cube(prim).GetSizeAttr().Get()
                corners = np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)])
                placed = corners @ m[:3, :3] + m[3, :3]
                assert np.allclose(meshes[path].points.min(axis=0), placed.min(axis=0), atol=1e-12), (path, t)
                assert np.allclose(meshes[path].points.max(axis=0), placed.max(axis=0), atol=1e-12), (path, t)


def test_reader_follows_edits_of_the_stage_as_a_fresh_reader_reads_them(class_map):
    """Edits made after a reader was created (a layer inserted into the session layer, then transforms set in
    it, a prim added and deactivated, a size changed, a material added, bound and recoloured) reach the reader
    through USD's change notices: after each, its snapshot equals a fresh reader's, and a constant gprim no
    edit touched keeps its MeshItem (the backend tells what moved by identity)."""
    from pxr import Gf, Sdf, Usd, UsdShade

    from synthua_usd.usd.authoring import apply_label

    stage = open_stage(DATA / "valid" / "animated_gprims.usda")
    reader = StageReader(stage, class_map)
    reader.snapshot(1.0)
    layer = Sdf.Layer.CreateAnonymous("edits.usda")
    stage.GetSessionLayer().subLayerPaths.insert(0, layer.identifier)

    def edit(fn):
        with Usd.EditContext(stage, layer):
            fn()
        carried, fresh = reader.snapshot(1.0), read_snapshot(stage, 1.0, class_map)
        assert_same_snapshot(carried, fresh)
        return {m.prim_path: m for m in carried.meshes}

    first = edit(lambda: None)

    def add_group():
        group = UsdGeom.Xform.Define(stage, "/World/Group")
        group.AddTranslateOp().Set(Gf.Vec3d(3.0, 0.0, 0.0))
        cube = UsdGeom.Cube.Define(stage, "/World/Group/Box")
        cube.AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, 0.5))
        apply_label(cube.GetPrim(), class_map.taxonomy, "furniture")
    added = edit(add_group)
    assert added["/World/Ground"] is first["/World/Ground"]
    moved = edit(lambda: stage.GetPrimAtPath("/World/Group").GetAttribute("xformOp:translate").Set(Gf.Vec3d(4, 1, 0)))
    assert np.allclose(moved["/World/Group/Box"].points - added["/World/Group/Box"].points, [1.0, 1.0, 0.0])
    assert moved["/World/Ground"] is first["/World/Ground"]
    ground = edit(lambda: UsdGeom.Xformable(stage.GetPrimAtPath("/World/Ground")).AddTranslateOp().Set(
        Gf.Vec3d(0.0, 0.0, -0.25)))
    assert np.allclose(ground["/World/Ground"].points[:, 2], -0.25)
    def animate():  # the group's transform becomes time-varying: the box must now move between time codes
        translate = stage.GetPrimAtPath("/World/Group").GetAttribute("xformOp:translate")
        translate.Set(Gf.Vec3d(4, 1, 0), 1.0)
        translate.Set(Gf.Vec3d(6, 1, 0), 3.0)
    edit(animate)
    for t in (3.0, 1.0):
        assert_same_snapshot(reader.snapshot(t), read_snapshot(stage, t, class_map))
    assert reader.snapshot(3.0).meshes[-1].points[:, 0].min() > reader.snapshot(1.0).meshes[-1].points[:, 0].min()
    resized = edit(lambda: UsdGeom.Cube(stage.GetPrimAtPath("/World/Group/Box")).GetSizeAttr().Set(3.0))
    assert np.ptp(resized["/World/Group/Box"].points[:, 0]) == pytest.approx(3.0)

    def bind_red():
        mat = UsdShade.Material.Define(stage, "/World/EditLooks/Red")
        shader = UsdShade.Shader.Define(stage, "/World/EditLooks/Red/Surface")
        shader.CreateIdAttr("UsdPreviewSurface")
        shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.8, 0.1, 0.1))
        mat.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
        UsdShade.MaterialBindingAPI.Apply(stage.GetPrimAtPath("/World/Group/Box")).Bind(mat)
    bound = edit(bind_red)
    assert bound["/World/Group/Box"].material_key == "/World/EditLooks/Red"
    edit(lambda: UsdShade.Shader(stage.GetPrimAtPath("/World/EditLooks/Red/Surface")).GetInput(
        "diffuseColor").Set(Gf.Vec3f(0.1, 0.8, 0.1)))
    assert reader.snapshot(1.0).materials["/World/EditLooks/Red"].base_color == pytest.approx((0.1, 0.8, 0.1))
    gone = edit(lambda: stage.GetPrimAtPath("/World/Group").SetActive(False))
    assert "/World/Group/Box" not in gone
    stage.GetSessionLayer().subLayerPaths.remove(layer.identifier)  # the stage as it was
    assert_same_snapshot(reader.snapshot(1.0), read_snapshot(stage, 1.0, class_map))


@pytest.mark.parametrize("kind", ["vertex", "faceVarying", "primvar"])
def test_authored_normals_reach_the_snapshot_in_world_space(tmp_path, class_map, kind):
    """A unit sphere scaled (2, 1, 1) and turned 30 degrees about Z: its authored normals arrive as world-space unit
    vectors perpendicular to the ellipsoid (the gradient of its implicit equation, worked out here; within 2 degrees,
    the sphere's facets), however they were authored; face-varying ones with no point split where they agree."""
    stage = sphere_stage(tmp_path / "ball.usda", kind)
    item = read_snapshot(stage, 1.0, class_map).meshes[0]
    assert item.normals is not None and item.normals.shape == item.points.shape and item.normals.dtype == np.float32
    assert len(item.points) == 162  # an icosphere of subdivision 2: no point split
    a = np.radians(30.0)
    # world = turn @ scaled
    turn = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    scaled = item.points @ turn  # turned back into the holder's frame (rows: turn^-1 p)
    gradient = (scaled * np.array([1 / 4, 1.0, 1.0])) @ turn.T  # of x^2/4 + y^2 + z^2 there, turned into the world
    gradient /= np.linalg.norm(gradient, axis=1, keepdims=True)
    assert np.allclose(np.linalg.norm(item.normals, axis=1), 1.0, atol=1e-5)
    assert np.degrees(np.arccos(np.clip((gradient * item.normals).sum(axis=1), -1, 1))).max() < 2.0


def test_unusable_or_missing_normals_shade_flat(tmp_path, class_map, caplog):
    assert read_snapshot(sphere_stage(tmp_path / "none.usda", None), 1.0, class_map).meshes[0].normals is None
    with caplog.at_level("WARNING"):
        item = read_snapshot(sphere_stage(tmp_path / "bad.usda", "bad"), 1.0, class_map).meshes[0]
    assert item.normals is None
    assert any("/World/Holder/Ball: normals" in r.getMessage() and "shading it flat" in r.getMessage()
               for r in caplog.records)
