"""Stage validation: OpenUSD's validators plus synthua's rules, each finding naming where, what and the rule."""

import pytest

from conftest import DATA
from synthua_usd.core.errors import SynthuaError
from synthua_usd.core.findings import Severity
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


def test_lens_in_millimetres_on_metre_stage_is_an_error_with_the_unit(class_map):
    """It renders the right field of view (only ratios reach the image) but every intrinsic in millimetres would be
    100 times too large: an error, which render refuses too."""
    findings = findings_of("camera_mm_on_metre_stage.usda", class_map)
    lens = [f for f in findings if f.rule == "camera-lens"]
    assert lens and all(f.severity is Severity.ERROR for f in lens)
    assert not any("focalLength = 20 is 2000 mm" in f.message for f in lens)  # 2000 mm is the edge of plausible
    assert any("horizontalAperture = 36 is 3600 mm" in f.message and "tenths of a scene unit" in f.message
               and "authored as 0.36" in f.message for f in lens)


TINY = (DATA / "valid" / "tiny_scene.usda").read_text()

#: name -> (change of the tiny scene, rule, where, words of the finding).
BROKEN = {
    "NaN translate": (("(0, 0, 0.5)", "(nan, 0, 0.5)"), "finite-values", "/World/Box", "xformOp:translate"),
    "NaN translate at a time sample": (("double3 xformOp:translate = (0, 0, 0.5)",
                                        "double3 xformOp:translate.timeSamples = {1: (0, 0, 0.5), 2: (0, nan, 0.5)}"),
                                       "finite-values", "/World/Box", "at time code 2"),
    "infinite light intensity": (("float inputs:intensity = 1", "float inputs:intensity = inf"), "finite-values",
                                 "/World/Sky", "inputs:intensity"),
    "NaN cube size": (("double size = 1", "double size = nan"), "gprim-shape", "/World/Box", "size is nan"),
    "negative sphere radius": (('def Cube "Box"', 'def Sphere "Box"', "double size = 1", "double radius = -1"),
                               "gprim-shape", "/World/Box", "radius is -1.0"),
    "zero cylinder height": (('def Cube "Box"', 'def Cylinder "Box"', "double size = 1", "double height = 0"),
                             "gprim-shape", "/World/Box", "height is 0.0"),
    "unknown lamp role": (("double size = 1", 'double size = 1\n        custom token synthua:lamp = "disco"'),
                          "render-reads", "/World/Box", "synthua:lamp is 'disco'"),
}


def _broken(tmp_path, name):
    change = BROKEN[name][0]
    text = TINY
    for old, new in zip(change[::2], change[1::2]):
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / "broken.usda"
    path.write_text(text)
    return path


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_broken_values_are_errors(class_map, tmp_path, name):
    _, rule, where, words = BROKEN[name]
    findings = validate_stage(open_stage(_broken(tmp_path, name)), class_map)
    hits = [f for f in findings if f.rule == rule and f.where == where and words in f.message]
    assert hits and all(f.severity is Severity.ERROR for f in hits), [f.format() for f in findings]


@pytest.mark.parametrize("name", ["NaN cube size", "negative sphere radius", "zero cylinder height", "unknown lamp role"])
def test_render_refuses_a_broken_shape_in_the_words_of_validation(class_map, tmp_path, name):
    path = _broken(tmp_path, name)
    findings = [f for f in validate_stage(open_stage(path), class_map) if f.severity is Severity.ERROR]
    with pytest.raises(SynthuaError) as refused:
        run_frames(FrameRequest(stage_path=path, out_dir=tmp_path / "out", camera_paths=("/World/Cam",)))
    assert any(str(refused.value).endswith(f"{f.where}: {f.message}") for f in findings), \
        (str(refused.value), [f.format() for f in findings])
    assert not (tmp_path / "out").exists()


def test_the_reader_runs_only_when_the_rules_find_no_error(class_map, tmp_path):
    """The reader stops at its first refusal: after a rule's error it would only repeat it."""
    findings = validate_stage(open_stage(_broken(tmp_path, "negative sphere radius")), class_map)
    assert [f.rule for f in findings] == ["gprim-shape"]


@pytest.mark.parametrize("metadata,words", [("startTimeCode = 1", "startTimeCode = nan"),
                                            ("endTimeCode = 2", "endTimeCode = inf"),
                                            ("startTimeCode = 1", "startTimeCode = 5")])
def test_a_time_range_that_is_not_finite_or_backwards_is_refused(tmp_path, metadata, words):
    path = tmp_path / "s.usda"
    path.write_text(TINY.replace(metadata, words))
    with pytest.raises(SynthuaError, match="time range|after endTimeCode"):
        open_stage(path)


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


def test_usds_fallback_lens_on_a_metre_stage_is_a_warning_not_an_error(class_map, tmp_path):
    """A camera that authors no lens has USD's 50 x 20.955 (5 m on a metre stage): render takes it, validation warns."""
    path = tmp_path / "s.usda"
    path.write_text(TINY.replace("float focalLength = 0.2\n", "").replace("float horizontalAperture = 0.36\n", "")
                    .replace("float verticalAperture = 0.24\n", ""))
    lens = [f for f in validate_stage(open_stage(path), class_map) if f.rule == "camera-lens"]
    assert lens and all(f.severity is Severity.WARNING and "not authored" in f.message for f in lens)
