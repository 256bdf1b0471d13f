"""Stage validation: OpenUSD's validators plus synthua's rules, each finding naming where, what and the rule."""

import pytest

from conftest import DATA
from synthua_usd.errors import SynthuaError
from synthua_usd.findings import Severity
from synthua_usd.pipeline.frame import FrameRequest, run_frames
from synthua_usd.usd.stage_checks import validate_stage
from synthua_usd.usd.stage_io import open_stage


def findings_of(name, class_map, folder="invalid"):
    return validate_stage(open_stage(DATA / folder / name), class_map)


@pytest.mark.parametrize("name", ["tiny_scene.usda", "tiny_lit_scene.usda"])
def test_tiny_valid_scenes_are_clean(class_map, name):
    assert findings_of(name, class_map, "valid") == []


def test_shipped_scenario_is_clean(demo_stage, class_map):
    assert validate_stage(demo_stage, class_map) == []


@pytest.mark.parametrize("name,rule,where,text", [
    ("unknown_label.usda", "label-in-class-map", "/World/Ground", "label 'spaceship' is not a class"),
    ("two_labels.usda", "gprim-has-one-class", "/World/Ground", "has 2 labels ['road', 'sidewalk']"),
    ("unlabelled_gprim.usda", "gprim-has-one-class", "/World/Ground", "has no class"),
    ("nested_labels.usda", "gprim-has-one-class", "/World/Box", "inherits labels from 2 prims"),
    ("bad_camera.usda", "camera-lens", "/World/Cam", "focalLength is 0.0; expected a finite value > 0"),
    ("bad_camera.usda", "camera-lens", "/World/Cam", "clippingRange is (10, 1); expected 0 < near < far"),
    ("bad_topology.usda", "mesh-topology", "/World/Short", "faceVertexCounts sum to 4 but there are 3 faceVertexIndices"),
    ("bad_topology.usda", "mesh-topology", "/World/Far", "faceVertexIndices reach 7 but there are 4 points"),
    ("unsupported_gprim.usda", "supported-prim", "/World/Dust", "gprim type 'Points' is not supported; supported "
                                                                "types: Capsule, Cone, Cube, Cylinder, Mesh, Sphere"),
    ("missing_metadata.usda", "stage-metadata", None, "timeCodesPerSecond is not stated"),
    ("missing_metadata.usda", "usdGeomValidators:StageMetadataChecker", None, "metersPerUnit"),
])
def test_rule_reports_where_and_what(class_map, name, rule, where, text):
    findings = findings_of(name, class_map)
    hits = [f for f in findings if f.rule == rule and text in f.message and (where is None or f.where == where)]
    assert hits, [f.format() for f in findings]
    assert all(f.severity is Severity.ERROR for f in hits)


def test_lens_in_millimetres_on_metre_stage_warns_with_the_unit(class_map):
    findings = findings_of("camera_mm_on_metre_stage.usda", class_map)
    warnings = [f for f in findings if f.rule == "camera-lens"]
    assert warnings and all(f.severity is Severity.WARNING for f in warnings)
    assert "focalLength = 20 is 2000 mm" not in warnings[0].message  # 2000 mm is the edge of plausible
    assert any("horizontalAperture = 36 is 3600 mm" in f.message and "tenths of a scene unit" in f.message
               for f in warnings)


def test_findings_format_names_rule(class_map):
    (finding,) = [f for f in findings_of("unknown_label.usda", class_map) if f.rule == "label-in-class-map"]
    assert finding.format().startswith("error: /World/Ground: label 'spaceship'")
    assert finding.format().endswith("(label-in-class-map)")


@pytest.mark.parametrize("name", ["unknown_label.usda", "two_labels.usda", "bad_camera.usda", "bad_topology.usda",
                                  "unsupported_gprim.usda"])
def test_what_render_refuses_validation_reports_in_the_same_words(class_map, tmp_path, name):
    stage = open_stage(DATA / "invalid" / name)
    findings = [f for f in validate_stage(stage, class_map) if f.severity is Severity.ERROR]
    with pytest.raises(SynthuaError) as refused:
        run_frames(FrameRequest(stage_path=DATA / "invalid" / name, out_dir=tmp_path / "out",
                                camera_paths=("/World/Cam",)))
    assert any(str(refused.value).endswith(f"{f.where}: {f.message}") for f in findings), \
        (str(refused.value), [f.format() for f in findings])
    assert not (tmp_path / "out").exists()
