"""`synthua render` end to end on tiny images, and every kind of bad input it must refuse."""

import json

import numpy as np
import pytest

from conftest import DATA, SCENARIO
from synthua_usd.core.images import read_image
from synthua_usd.core.outputs import file_names
from synthua_usd.core.schemas import validate_document


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    from synthua_usd.cli.main import main

    out = tmp_path_factory.mktemp("render") / "cctv"
    code = main(["render", str(SCENARIO), "--camera", "/World/Cameras/CCTV", "--frame", "12", "--width", "64",
                 "--height", "48", "--spp", "2", "--out", str(out)])
    assert code == 0
    return out


def test_writes_every_file(rendered):
    assert sorted(p.name for p in rendered.iterdir()) == sorted(file_names())


def test_frame_json_is_schema_valid_and_describes_the_images(rendered, class_map):
    doc = json.loads((rendered / "frame.json").read_text())
    validate_document(doc, "frame", "frame.json")
    assert doc["image"] == {"width": 64, "height": 48}
    assert doc["time_code"] == 12 and doc["render"]["spp"] == 2
    assert doc["files"]["depth"]["kind"] == "z"
    assert len(doc["class_map"]["classes"]) == 37
    classes, _ = read_image(rendered / "class.png")
    ids, counts = np.unique(classes, return_counts=True)
    assert doc["class_pixel_counts"] == {class_map.by_id(int(i)).name: int(n) for i, n in zip(ids, counts)}
    inst, spec = read_image(rendered / "instance.png")
    assert inst.dtype == np.uint16
    for entry in doc["instances"]:
        assert entry["pixel_count"] == int((inst == entry["id"]).sum())


def test_instance_preview_gives_each_instance_its_own_colour(rendered):
    """The raw 16-bit id map looks black in a viewer; the preview beside it is one colour per id, black only
    where there is none, and as many colours as instances."""
    inst, _ = read_image(rendered / "instance.png")
    preview, _ = read_image(rendered / "instance_preview.png")
    ids = inst[..., 0].astype(np.int64)
    assert preview.shape == ids.shape + (3,) and preview.dtype == np.uint8
    assert not preview[ids == 0].any() and (preview[ids > 0].max(axis=1) > 0).all()
    colours = {i: np.unique(preview[ids == i], axis=0) for i in np.unique(ids[ids > 0])}
    assert all(len(c) == 1 for c in colours.values())  # one colour per id
    assert len({tuple(c[0]) for c in colours.values()}) == len(colours) >= 3  # and ids do not share one


def test_semantic_png_is_the_class_palette(rendered, class_map):
    classes, _ = read_image(rendered / "class.png")
    semantic, _ = read_image(rendered / "semantic.png")
    assert np.array_equal(semantic, class_map.palette()[classes[..., 0]])


def test_intrinsics_match_the_camera(rendered):
    doc = json.loads((rendered / "frame.json").read_text())
    k = np.array(doc["camera"]["K"])
    hfov = doc["camera"]["fov_deg"][0]
    assert k[0, 0] == pytest.approx(32 / np.tan(np.radians(hfov) / 2))


def test_render_defaults_come_from_render_settings(run_cli, tmp_path):
    # No --camera: the UsdRender settings' camera is used; size and spp given to keep it tiny.
    code, out, _ = run_cli("render", SCENARIO, "--width", "16", "--height", "12", "--spp", "1", "--out", tmp_path / "o")
    assert code == 0 and "rendered /World/Cameras/CCTV at time code 1:" in out


BAD = {
    "missing stage": (lambda tmp: [tmp / "nope.usda"], "nope.usda: file not found"),
    "malformed stage": (lambda tmp: [DATA / "invalid" / "malformed.usda"], "not a readable USD stage"),
    "unknown camera": (lambda tmp: [SCENARIO, "--camera", "/World/Cameras/Nope"],
                       "no camera at '/World/Cameras/Nope'; cameras in the stage: /World/Cameras/CCTV"),
    "not a camera": (lambda tmp: [SCENARIO, "--camera", "/World/Twin/Road/Mesh"],
                     "/World/Twin/Road/Mesh: prim of type 'Mesh' is not a UsdGeom.Camera"),
    "time code out of range": (lambda tmp: [SCENARIO, "--time-code", "500"], "time code 500 is outside the stage's time range [1, 48]"),
    "label not in class map": (lambda tmp: [DATA / "invalid" / "unknown_label.usda", "--camera", "/World/Cam"],
                               "/World/Ground: label 'spaceship' is not a class of"),
    "class map fails schema": (lambda tmp: [SCENARIO, "--class-map", DATA / "invalid" / "schema_missing_color.json"],
                               "schema_missing_color.json: classes[1]: 'color' is a required property"),
    "bad spp": (lambda tmp: [SCENARIO, "--spp", "0"], "--spp: 0 is not in the range"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_exits_2_with_one_line_and_writes_nothing(run_cli, tmp_path, case):
    make_args, text = BAD[case]
    out = tmp_path / "out"
    code, stdout, err = run_cli("render", *make_args(tmp_path), "--width", "8", "--height", "6", "--spp", "1",
                                "--out", out) if case != "bad spp" else \
        run_cli("render", *make_args(tmp_path), "--width", "8", "--height", "6", "--out", out)
    assert code == 2, (stdout, err)
    assert text in err, err
    if case != "bad spp":
        assert len(err.strip().splitlines()) == 1 and err.startswith("synthua: error: ")
    assert not out.exists()


def test_two_cameras_and_a_time_code_range_write_one_folder_per_frame(run_cli, tmp_path):
    out = tmp_path / "sweep"
    code, stdout, err = run_cli("render", SCENARIO, "--camera", "/World/Cameras/CCTV", "--camera",
                                "/World/Cameras/PedestrianEye", "--time-code", "1:48:47", "--width", "16", "--height", "12",
                                "--spp", "1", "--out", out)
    assert code == 0, err
    assert "for 4 frames" in stdout and "(1 scene load)" in stdout
    folders = sorted(str(p.relative_to(out)) for p in out.glob("*/*"))
    assert folders == ["CCTV/0001", "CCTV/0048", "PedestrianEye/0001", "PedestrianEye/0048"]
    for folder in folders:
        assert sorted(p.name for p in (out / folder).iterdir()) == sorted(file_names()), folder
        doc = json.loads((out / folder / "frame.json").read_text())
        assert (doc["camera"]["prim_path"].rsplit("/", 1)[-1], doc["time_code"]) == (folder.split("/")[0],
                                                                                      int(folder.split("/")[1]))
    assert not list(tmp_path.glob(".*"))  # no staging folder left beside the output


@pytest.mark.parametrize("frames,text", [
    ("1:48:0", "STEP > 0"),
    ("48:1", "END >= START"),
    ("one", "'one' is not a time code"),
    ("1,500", "time code 500 is outside the stage's time range [1, 48]"),
])
def test_bad_time_codes_exit_2_and_write_nothing(run_cli, tmp_path, frames, text):
    code, _, err = run_cli("render", SCENARIO, "--frame", frames, "--width", "8", "--height", "6", "--spp", "1",
                           "--out", tmp_path / "o")
    assert code == 2 and text in err, err
    assert not (tmp_path / "o").exists()


def test_rerender_replaces_files_in_place(run_cli, tmp_path):
    out = tmp_path / "o"
    args = ("render", SCENARIO, "--width", "8", "--height", "6", "--spp", "1", "--out", out)
    assert run_cli(*args)[0] == 0
    first = (out / "frame.json").read_text()
    assert run_cli(*args)[0] == 0
    assert sorted(p.name for p in out.iterdir()) == sorted(file_names())  # no temporary files left behind
    assert json.loads(first)["instances"] == json.loads((out / "frame.json").read_text())["instances"]


def test_scalar_variant_on_request(run_cli, tmp_path):
    code, out, err = run_cli("render", SCENARIO, "--variant", "scalar_rgb", "--width", "32", "--height", "24",
                             "--spp", "1", "--out", tmp_path / "s")
    assert code == 0, err
    doc = json.loads((tmp_path / "s" / "frame.json").read_text())
    assert doc["render"]["variant"] == "scalar_rgb"
    code, _, err = run_cli("render", SCENARIO, "--variant", "teapot_rgb", "--out", tmp_path / "t")
    assert code == 2 and "variant 'teapot_rgb' is not in this Mitsuba build" in err and not (tmp_path / "t").exists()
