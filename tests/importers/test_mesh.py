import numpy as np
import pytest
import trimesh

from conftest import DATA
from synthua_usd.core.errors import InputError
from synthua_usd.importers.mesh import import_mesh
from synthua_usd.model.class_assignment import AssignmentRules


@pytest.fixture
def rules(class_map):
    return AssignmentRules.load(DATA / "valid" / "mesh_rules.json", class_map)


def by_path(model):
    return {o.path: o for o in model.objects}


def test_obj_keeps_objects_and_materials(rules):
    model = import_mesh(DATA / "valid" / "street.obj", rules)
    objs = by_path(model)
    assert set(objs) == {"Road_Main", "Building_01/window", "Building_01/building", "Lamp"}
    assert objs["Road_Main"].label == "road" and [p.name for p in objs["Road_Main"].parts] == ["asphalt"]
    assert objs["Building_01/window"].label == "window"  # material rule beats the object rule
    assert objs["Lamp"].label == "unlabelled"
    assert model.report["unmatched"] == ["Lamp_metal"]
    # The quad became two triangles; Z-up input kept as is.
    road = objs["Road_Main"].parts[0]
    assert road.triangles.shape == (2, 3) and road.points[:, 2].max() == 0.0
    # Kd 0.8 0.6 0.4 (sRGB, stored by trimesh as 8-bit 204 153 102) becomes linear Rec.709.
    import colour

    plaster = model.materials["plaster"].base_color
    assert plaster == pytest.approx(colour.cctf_decoding(np.array([204, 153, 102]) / 255, function="sRGB"), abs=1e-6)


def test_unmatched_geometry_is_reported_in_the_log(rules, caplog):
    import_mesh(DATA / "valid" / "street.obj", rules)
    assert "1 of 4 meshes matched no rule and are labelled 'unlabelled': Lamp_metal" in caplog.text


def test_glb_is_y_up_and_named_by_node(tmp_path, class_map):
    scene = trimesh.Scene()
    box = trimesh.creation.box(extents=(1, 2, 3))  # 3 m tall along glTF's +Y after the rotation below
    box.apply_transform(trimesh.transformations.rotation_matrix(-np.pi / 2, [1, 0, 0]))
    scene.add_geometry(box, node_name="Kiosk", geom_name="kiosk_mesh")
    path = tmp_path / "kiosk.glb"
    scene.export(path)
    rules = AssignmentRules.from_document({"rules": [{"field": "object", "pattern": "kiosk", "class": "stand"}]}, class_map)
    model = import_mesh(path, rules)
    (obj,) = model.objects
    assert obj.path == "Kiosk" and obj.label == "stand"
    extent = np.ptp(obj.parts[0].points, axis=0)
    assert extent == pytest.approx([1, 2, 3])  # back to Z-up: 3 m tall


@pytest.mark.parametrize("suffix", ["ply", "stl"])
def test_single_mesh_formats_use_the_file_name(tmp_path, class_map, suffix):
    path = tmp_path / f"bench_01.{suffix}"
    trimesh.creation.box(extents=(2, 0.5, 0.5)).export(path)
    rules = AssignmentRules.from_document({"rules": [{"field": "object", "pattern": "bench", "class": "furniture"}]},
                                        class_map)
    model = import_mesh(path, rules, scale=0.5)
    (obj,) = model.objects
    assert obj.path == "bench_01" and obj.label == "furniture"
    assert np.ptp(obj.parts[0].points, axis=0) == pytest.approx([1.0, 0.25, 0.25])


@pytest.mark.parametrize("name,text", [
    ("garbage.obj", "no geometry"),
    ("street.fbx", "unsupported mesh format '.fbx'"),
    ("missing.obj", "file not found"),
])
def test_bad_mesh_inputs(rules, tmp_path, name, text):
    path = DATA / "invalid" / name if name == "garbage.obj" else tmp_path / name
    if name == "street.fbx":
        path.write_text("x")
    with pytest.raises(InputError, match=text):
        import_mesh(path, rules)


def test_cli_mesh_import_needs_rules(run_cli, tmp_path):
    code, _, err = run_cli("twin", "import", "mesh", DATA / "valid" / "street.obj", "--out", tmp_path / "o")
    assert code == 2 and "mesh import needs --rules FILE" in err
    assert not (tmp_path / "o").exists()
