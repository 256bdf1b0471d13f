"""Hostile input to the stage commands (render, validate stage, inspect, compose, agents populate, create):
broken compositions, malformed and nonsensical stages, impossible parameters, outputs that cannot be
written. Every case is refused with one line and exit 2 (``validate stage`` reports what render would
refuse as findings, exit 1), leaves an earlier output folder exactly as it was, writes nothing outside
it, and finishes within the harness's time limit.

The corpus is generated here from the tiny scene in tests/data/valid, so every file is a small, readable
variation of a stage that renders.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import DATA, SCENARIO
from hostile import assert_refused, run_synthua, small_disk, tree_state

TINY = (DATA / "valid" / "tiny_scene.usda").read_text()
CAM = "/World/Cam"


def _variant(old: str, new: str) -> str:
    assert old in TINY, old
    return TINY.replace(old, new)


#: name -> (file text or bytes, words the error must mention). Each is a stage `render` must refuse.
BROKEN_STAGES: dict[str, tuple[str | bytes, tuple[str, ...]]] = {
    "missing sublayer": ('#usda 1.0\n(\n    subLayers = [@./nope.usda@, @./tiny.usda@]\n)\n', ("nope.usda",)),
    "cyclic sublayers": ('#usda 1.0\n(\n    subLayers = [@./cycle.usda@, @./tiny.usda@]\n)\n', ("cycle",)),
    "sublayer is a system file": ('#usda 1.0\n(\n    subLayers = [@/etc/passwd@, @./tiny.usda@]\n)\n', ("/etc/passwd",)),
    "truncated crate sublayer": ('#usda 1.0\n(\n    subLayers = [@./truncated.usdc@, @./tiny.usda@]\n)\n',
                                 ("truncated.usdc",)),
    "missing reference": (_variant('def Xform "World" (\n    kind = "assembly"\n)',
                                   'def Xform "World" (\n    kind = "assembly"\n    references = @./gone.usda@\n)'),
                          ("gone.usda",)),
    "missing payload": (_variant('def Xform "World" (\n    kind = "assembly"\n)',
                                 'def Xform "World" (\n    kind = "assembly"\n    payload = @./gone.usda@</World>\n)'),
                        ("gone.usda",)),
    "layer outside the folder": ('#usda 1.0\n(\n    subLayers = [@../outside/tiny.usda@]\n)\n',
                                 ("outside", "--allow-external-assets")),
    "texture is a system file": ((DATA / "valid" / "textured_quads.usda").read_text().replace(
        "@./textures/quadrants.png@", "@/etc/passwd@"), ("/World/Looks/Quadrants/Image", "/etc/passwd",
                                                        "--allow-external-assets")),
    "not UTF-8": (TINY.encode("utf-8").replace(b'"Ground"', b'"Gr\xff\xfeund"'), ("not a readable usd",)),
    "syntax error": (TINY[: len(TINY) // 2], ("not a readable usd",)),
    "empty file": ("", ("not a readable usd",)),
    "no geometry": ('#usda 1.0\n(\n    metersPerUnit = 1\n    upAxis = "Z"\n)\ndef Xform "World" {\n    def Camera "Cam" {}\n}\n',
                    ("no renderable geometry",)),
    "NaN points": (_variant("(-5, -5, 0), (5, -5, 0)", "(nan, -5, 0), (5, -5, 0)"), ("/World/Ground", "finite")),
    "face counts do not match": (_variant("int[] faceVertexCounts = [4]", "int[] faceVertexCounts = [5]"),
                                 ("/World/Ground", "faceVertexCounts")),
    "two-vertex face": (_variant("int[] faceVertexCounts = [4]\n        int[] faceVertexIndices = [0, 1, 2, 3]",
                                 "int[] faceVertexCounts = [2, 2]\n        int[] faceVertexIndices = [0, 1, 2, 3]"),
                        ("/World/Ground", "at least 3")),
    "index out of range": (_variant("int[] faceVertexIndices = [0, 1, 2, 3]", "int[] faceVertexIndices = [0, 1, 2, 9]"),
                           ("/World/Ground", "faceVertexIndices")),
    "negative index": (_variant("int[] faceVertexIndices = [0, 1, 2, 3]", "int[] faceVertexIndices = [0, 1, 2, -1]"),
                       ("/World/Ground", "faceVertexIndices")),
    "unsupported gprim": (_variant('def Cube "Box"', 'def BasisCurves "Box"'), ("/World/Box", "not supported")),
    "unsupported light": (_variant('def DomeLight "Sky"', 'def SphereLight "Sky"'), ("/World/Sky", "not supported")),
    "camera with a zero transform": (_variant("( (1, 0, 0, 0), (0, 0, 1, 0), (0, -1, 0, 0), (0, -6, 1.5, 1) )",
                                              "( (0, 0, 0, 0), (0, 0, 0, 0), (0, 0, 0, 0), (0, 0, 0, 0) )"),
                                     (CAM, "transform")),
    "camera focal length 0": (_variant("float focalLength = 0.2", "float focalLength = 0"), (CAM, "focalLength")),
    "orthographic camera": (_variant("float focalLength = 0.2", 'float focalLength = 0.2\n        token projection = "orthographic"'),
                            (CAM, "perspective")),
    "metersPerUnit 0": (_variant("metersPerUnit = 1", "metersPerUnit = 0"), ("metersPerUnit",)),
    "metersPerUnit negative": (_variant("metersPerUnit = 1", "metersPerUnit = -1"), ("metersPerUnit",)),
    "metersPerUnit NaN": (_variant("metersPerUnit = 1", "metersPerUnit = nan"), ("metersPerUnit",)),
    "upAxis X": (_variant('upAxis = "Z"', 'upAxis = "X"'), ("upAxis",)),
    "label not in the class map": (_variant('["road"]', '["spaceship"]'), ("/World/Ground", "spaceship")),
    "two labels": (_variant('["road"]', '["road", "sidewalk"]'), ("/World/Ground", "2 labels")),
    "NaN translate": (_variant("(0, 0, 0.5)", "(nan, 0, 0.5)"), ("/World/Box", "finite")),
    "NaN cube size": (_variant("double size = 1", "double size = nan"), ("/World/Box", "size")),
    "negative sphere radius": (_variant('def Cube "Box"', 'def Sphere "Box"').replace("double size = 1",
                                                                                    "double radius = -1"),
                               ("/World/Box", "radius")),
    "NaN startTimeCode": (_variant("startTimeCode = 1", "startTimeCode = nan"), ("time range",)),
    "lens in millimetres on a metre stage": (_variant("focalLength = 0.2", "focalLength = 24").replace(
        "horizontalAperture = 0.36", "horizontalAperture = 36").replace("verticalAperture = 0.24", "verticalAperture = 24"),
        (CAM, "tenths of a scene unit")),
    # each value alone looks plausible, so validate called them clean: 2000 mm over 36 mm, 2 mm over 36 mm
    "focal length alone in millimetres": (_variant("focalLength = 0.2", "focalLength = 20"), (CAM, "field of view")),
    "focal length alone in metres": (_variant("focalLength = 0.2", "focalLength = 0.02"), (CAM, "field of view")),
}

#: Cases `validate stage` reports as findings (exit 1) rather than refusing to read (exit 2).
FINDINGS = {"NaN points": "mesh-topology", "face counts do not match": "mesh-topology",
            "two-vertex face": "mesh-topology", "index out of range": "mesh-topology",
            "negative index": "mesh-topology", "unsupported gprim": "supported-prim",
            "unsupported light": "supported-prim", "camera with a zero transform": "camera-lens",
            "camera focal length 0": "camera-lens", "orthographic camera": "camera-lens",
            "label not in the class map": "label-in-class-map", "two labels": "gprim-has-one-class",
            "no geometry": "renderable", "NaN translate": "finite-values", "NaN cube size": "gprim-shape",
            "negative sphere radius": "gprim-shape", "lens in millimetres on a metre stage": "camera-lens",
            "focal length alone in millimetres": "camera-lens", "focal length alone in metres": "camera-lens"}


@pytest.fixture(scope="module")
def corpus(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("hostile")
    folder = root / "stages"
    folder.mkdir()
    (folder / "tiny.usda").write_text(TINY)
    (folder / "cycle.usda").write_text('#usda 1.0\n(\n    subLayers = [@./cycle.usda@]\n)\n')
    from pxr import Sdf

    layer = Sdf.Layer.FindOrOpen(str(folder / "tiny.usda"))
    layer.Export(str(folder / "whole.usdc"))
    data = (folder / "whole.usdc").read_bytes()
    (folder / "truncated.usdc").write_bytes(data[: len(data) // 2])
    (root / "outside").mkdir()
    (root / "outside" / "tiny.usda").write_text(TINY)
    for name, (content, _) in BROKEN_STAGES.items():
        path = folder / (name.replace(" ", "_") + ".usda")
        path.write_bytes(content if isinstance(content, bytes) else content.encode())
    return folder


def _stage(corpus: Path, name: str) -> Path:
    return corpus / (name.replace(" ", "_") + ".usda")


@pytest.fixture
def earlier_output(tmp_path) -> Path:
    """An output folder holding an earlier render's files (and a symlink that must stay a symlink)."""
    out = tmp_path / "out"
    out.mkdir()
    for name in ("rgb.png", "class.png", "frame.json"):
        (out / name).write_bytes(f"earlier {name}".encode())
    (out / "link.png").symlink_to(out / "rgb.png")
    return out


@pytest.mark.filterwarnings("error::RuntimeWarning")  # a NaN transform once reached numpy's det before the check
@pytest.mark.parametrize("name", sorted(BROKEN_STAGES))
def test_render_refuses_a_broken_stage_and_keeps_earlier_results(name, corpus, earlier_output, run_cli):
    before, around = tree_state(earlier_output), set(os.listdir(earlier_output.parent))
    code, _, err = run_cli("render", _stage(corpus, name), "--camera", CAM, "--width", "16", "--height", "12",
                           "--spp", "1", "--out", earlier_output)
    message = err.strip().splitlines()[-1] if err.strip() else ""
    assert code == 2 and "Traceback" not in err, err
    assert message.startswith("synthua: error: ") and len([l for l in err.splitlines() if "error:" in l]) == 1, err
    for word in BROKEN_STAGES[name][1]:
        assert word.lower() in message.lower(), (word, message)
    assert tree_state(earlier_output) == before
    assert set(os.listdir(earlier_output.parent)) == around  # nothing written beside it either


@pytest.mark.parametrize("name", sorted(BROKEN_STAGES))
def test_validate_stage_reports_or_refuses_what_render_refuses(name, corpus, run_cli):
    code, out, err = run_cli("validate", "stage", _stage(corpus, name))
    assert "Traceback" not in err
    if name in FINDINGS:
        assert code == 1, (out, err)
        assert f"({FINDINGS[name]})" in out, out
    else:
        assert code == 2 and err.strip().startswith("synthua: error: "), err


@pytest.mark.parametrize("name", ["missing sublayer", "truncated crate sublayer", "cyclic sublayers",
                                  "layer outside the folder", "not UTF-8"])
def test_inspect_refuses_a_broken_composition(name, corpus, run_cli):
    code, _, err = run_cli("inspect", _stage(corpus, name))
    assert code == 2 and err.count("synthua: error:") == 1 and "Traceback" not in err, err


def test_external_layers_are_accepted_when_allowed(corpus, run_cli):
    code, out, _ = run_cli("inspect", _stage(corpus, "layer outside the folder"), "--allow-external-assets")
    assert code == 0 and "outside/tiny.usda" in out


#: (arguments after the stage, words the error mentions); the stage is the tiny scene.
BAD_PARAMETERS = {
    "unknown camera": (["--camera", "/World/Nope"], ("/World/Nope",)),
    "camera path with a newline": (["--camera", "/World/Ca\nm"], ("\\n",)),
    "a camera's path, a newline and more": (["--camera", "/World/Cam\nX"], ("/World/Cam\\nX", "not a prim path")),
    "camera path with a trailing slash": (["--camera", "/World/Cam/"], ("/World/Cam/", "not a prim path")),
    "camera path with a space": (["--camera", "/World/Cam "], ("not a prim path",)),
    "relative camera path": (["--camera", "World/Cam"], ("World/Cam", "not a prim path")),
    "camera path of a property": (["--camera", "/World/Cam.focalLength"], ("not a prim path",)),
    "camera path with a variant selection": (["--camera", "/World{v=a}Cam"], ("not a prim path",)),
    "time code out of range": (["--time-code", "500"], ("time code 500",)),
    "time code NaN": (["--time-code", "nan"], ("--time-code",)),
    "time code infinite": (["--time-code", "inf"], ("--time-code",)),
    "time range of 2^63": (["--time-code", "1:9223372036854775808"], ("--time-code",)),
    "time step 0": (["--time-code", "1:2:0"], ("--time-code",)),
    "spp 0": (["--spp", "0"], ("--spp",)),
    "width 0": (["--width", "0"], ("--width",)),
    "too large to fit in memory": (["--width", "16384", "--height", "16384"], ("16384x16384", "memory")),
    "seed 2^64": (["--seed", str(2**64)], ("--seed",)),
    "unknown variant": (["--variant", "teapot_rgb"], ("teapot_rgb",)),
    "class map is not JSON": (["--class-map", str(DATA / "invalid" / "not_json.json")], ("not_json.json",)),
}


def test_paths_echoed_on_stdout_are_escaped(corpus, tmp_path, run_cli):
    """What stdout echoes of the user's input is escaped as the error messages are: one line each, no control
    characters (a newline in --out cannot forge a line, an escape sequence cannot reach the terminal)."""
    stage = tmp_path / "ti\x1b[2Jny.usda"
    stage.write_text(TINY)
    runs = [run_cli("render", corpus / "tiny.usda", "--camera", CAM, "--width", "8", "--height", "6", "--spp", "1",
                    "--out", tmp_path / "o\nut"),
            run_cli("compose", tmp_path / "ro\not.usda", corpus / "tiny.usda", "--allow-external-assets"),
            run_cli("inspect", stage)]
    for code, out, err in runs:
        assert code == 0, err
        assert not any(c in out.replace("\n", "") for c in "\x1b\r\x00"), out
        assert "o\\nut" in out or "ro\\not.usda" in out or "ti\\x1b[2Jny.usda" in out, out
    assert all(line.startswith(("rendered ", "wrote ")) for line in runs[0][1].splitlines()), runs[0][1]
    assert runs[1][1].count("\n") == 1, runs[1][1]


@pytest.mark.parametrize("name", sorted(BAD_PARAMETERS))
def test_render_refuses_impossible_parameters(name, corpus, earlier_output, run_cli):
    args, words = BAD_PARAMETERS[name]
    before = tree_state(earlier_output)
    camera = [] if "--camera" in args else ["--camera", CAM]
    code, _, err = run_cli("render", corpus / "tiny.usda", *camera, *args, "--out", earlier_output)
    assert code == 2 and err.count("synthua: error:") == 1 and "Traceback" not in err, err
    assert all(w.lower() in err.lower() for w in words), (words, err)
    assert len(err.strip().splitlines()) == 1
    assert tree_state(earlier_output) == before


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(width=st.one_of(st.integers(-10, 0), st.integers(16385, 2**70), st.floats(allow_nan=True).map(str),
                       st.text(min_size=1, max_size=8).filter(lambda s: not s.strip().isdigit())))
def test_any_bad_width_is_one_line(width, corpus, tmp_path, run_cli):
    code, _, err = run_cli("render", corpus / "tiny.usda", "--camera", CAM, "--width", width, "--out", tmp_path / "o")
    assert code == 2 and err.count("\n") == 1 and err.startswith("synthua: error:") and "--width" in err, err
    assert not (tmp_path / "o").exists()


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(spec=st.text(alphabet="0123456789:,.-einfa ", min_size=1, max_size=12))
def test_any_time_code_spec_renders_or_is_refused_in_one_line(spec, corpus, tmp_path, run_cli):
    code, _, err = run_cli("render", corpus / "tiny.usda", "--camera", CAM, "--time-code", spec, "--width", "8",
                           "--height", "6", "--spp", "1", "--out", tmp_path / "o")
    assert "Traceback" not in err
    assert code in (0, 2), err
    if code == 2:
        assert err.count("synthua: error:") == 1 and err.strip().count("\n") == 0, err


def test_output_folder_is_a_file(corpus, tmp_path, run_cli):
    target = tmp_path / "out"
    target.write_text("a file")
    code, _, err = run_cli("render", corpus / "tiny.usda", "--camera", CAM, "--width", "8", "--height", "6",
                           "--spp", "1", "--out", target)
    assert code == 2 and "is a file" in err and target.read_text() == "a file"


def test_output_parent_is_a_file(corpus, tmp_path, run_cli):
    (tmp_path / "blocker").write_text("a file")
    code, _, err = run_cli("render", corpus / "tiny.usda", "--camera", CAM, "--width", "8", "--height", "6",
                           "--spp", "1", "--out", tmp_path / "blocker" / "out")
    assert code == 2 and err.count("synthua: error:") == 1 and "blocker" in err, err


def test_output_name_over_255_bytes(corpus, tmp_path, run_cli):
    code, _, err = run_cli("render", corpus / "tiny.usda", "--camera", CAM, "--width", "8", "--height", "6",
                           "--spp", "1", "--out", tmp_path / ("x" * 300))
    assert code == 2 and err.count("synthua: error:") == 1 and "255" in err, err
    assert os.listdir(tmp_path) == []


def test_a_file_that_became_a_folder_fails_before_anything_is_replaced(corpus, tmp_path, run_cli):
    out = tmp_path / "out"
    assert run_cli("render", corpus / "tiny.usda", "--camera", CAM, "--width", "8", "--height", "6", "--spp", "1",
                   "--out", out)[0] == 0
    (out / "instance.png").unlink()
    (out / "instance.png").mkdir()
    before = tree_state(out)
    code, _, err = run_cli("render", corpus / "tiny.usda", "--camera", CAM, "--width", "8", "--height", "6",
                           "--spp", "2", "--out", out)
    assert code == 2 and "instance.png" in err and "is a folder" in err, err
    assert tree_state(out) == before  # rgb.exr, depth.exr and frame.json all still the earlier ones
    assert sorted(os.listdir(tmp_path)) == ["out"]


def test_a_full_disk_leaves_the_earlier_results(corpus, tmp_path):
    with small_disk(tmp_path, "size=160k") as disk:
        out = disk / "out"
        first = run_synthua("render", corpus / "tiny.usda", "--camera", CAM, "--width", "16", "--height", "12",
                            "--spp", "1", "--out", out)
        assert first.code == 0, first.stderr
        before = tree_state(out)
        result = run_synthua("render", corpus / "tiny.usda", "--camera", CAM, "--width", "256", "--height", "192",
                             "--spp", "1", "--out", out)
        assert_refused(result, "no space left on device")
        assert tree_state(out) == before
        assert sorted(os.listdir(disk)) == ["out"]  # the staging folder is gone too


def test_a_read_only_disk_is_one_line(corpus, tmp_path):
    with small_disk(tmp_path, "size=64k,ro") as disk:
        result = run_synthua("render", corpus / "tiny.usda", "--camera", CAM, "--width", "8", "--height", "6",
                             "--spp", "1", "--out", disk / "out")
        assert_refused(result, "read-only")


def test_native_usd_diagnostics_become_one_line_warnings(tmp_path):
    """A stage that renders but makes OpenUSD print a multi-line warning on fd 2."""
    stage = tmp_path / "s.usda"
    stage.write_text(TINY.replace('def Cube "Box" (', 'def Cube "Box" (\n        bogusMetadata = 1'))
    result = run_synthua("render", stage, "--camera", CAM, "--width", "8", "--height", "6", "--spp", "1",
                         "--out", tmp_path / "o")
    assert all(line.startswith("synthua: ") for line in result.stderr.splitlines() if line.strip()), result.stderr


def test_compose_refuses_nonsense(corpus, tmp_path, run_cli):
    code, _, err = run_cli("compose", tmp_path / "x.usda", _stage(corpus, "metersPerUnit 0"))
    assert code == 2 and "metersPerUnit" in err, err
    code, _, err = run_cli("compose", corpus / "tiny.usda", corpus / "tiny.usda")
    assert code == 2 and "itself" in err, err
    code, _, err = run_cli("compose", tmp_path / "y.usda", tmp_path / "nope.usda")
    assert code == 2 and "nope.usda" in err and not (tmp_path / "y.usda").exists()
    for name in ("out.txt", "out", "out.usdz", "out.usda.bak"):  # OpenUSD wrote USDA text under any of them
        code, _, err = run_cli("compose", tmp_path / name, corpus / "tiny.usda")
        assert code == 2 and name in err and "USD file name" in err, err
        assert not (tmp_path / name).exists()


def test_populate_refuses_nonsense(corpus, tmp_path, run_cli):
    for args, word in ((["--walk-on", ""], "walk"), (["--walk-on", "lava"], "lava"), (["--density", "nan"], "--density"),
                       (["--time-codes", str(2**63)], "--time-codes"), (["--cell-m", "1e-9"], "--cell-m"),
                       (["--seed", str(2**64)], "--seed")):
        code, _, err = run_cli("agents", "populate", SCENARIO, *args, "--out", tmp_path / "a.usdc")
        assert code == 2 and err.count("synthua: error:") == 1 and word in err, (args, err)
    code, _, err = run_cli("agents", "populate", corpus / "tiny.usda", "--out", corpus / "tiny.usda")
    assert code == 2 and "is the input TWIN_OR_SCENARIO itself" in err
    assert not (tmp_path / "a.usdc").exists()


def test_populate_on_a_surface_nobody_walks_on_ends(tmp_path):
    result = run_synthua("agents", "populate", SCENARIO, "--walk-on", "door", "--out", tmp_path / "a.usdc", timeout=60)
    assert_refused(result, "walkable surface")


@pytest.mark.parametrize("args", [
    ["render", "{corpus}/NaN_translate.usda", "--camera", CAM, "--width", "8", "--height", "6", "--spp", "1"],
    ["cameras", "author", str(SCENARIO), "--rig", "cctv:k1=1e308", "--width", "16", "--height", "16"],
], ids=["NaN translate", "k1=1e308"])
def test_numpy_warnings_about_the_refused_value_do_not_come_before_the_error(args, corpus, tmp_path):
    """numpy's "invalid value encountered" about the NaN being refused would only repeat the error line."""
    result = run_synthua(*[a.format(corpus=corpus) for a in args], "--out", tmp_path / "out.usda")
    assert_refused(result)
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr
