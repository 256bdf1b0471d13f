"""Numeric options of the importers and helper commands: every one has a finite, stated range; a value
outside it (NaN, infinities, zero or negative where nonsense, absurdly large or small) is refused with one
line naming the option as typed. GCP CSV files are refused like any other input."""

from __future__ import annotations

import pytest

from importers.hostile_corpus import GCP_MODEL, GCP_SURVEYED, GEOJSON, RULES, mesh_input, write

FLIGHT = {"--altitude-m": "150", "--fov-deg": "84", "--area-width-m": "1225", "--area-length-m": "1225"}
GSD = {"--sensor-width-mm": "13.2", "--focal-length-mm": "10.26", "--image-width-px": "5472"}
FLIGHT_FLOATS = ["--altitude-m", "--fov-deg", "--frontal-overlap", "--lateral-overlap", "--area-width-m",
                 "--area-length-m", "--sensor-width-mm", "--focal-length-mm"]
BAD_FLOATS = ["nan", "inf", "-inf", "-1", "0", "1e308", "1e-300", "abc"]


def _flight(**override) -> list[str]:
    options = {**FLIGHT, **GSD, **override}
    return ["survey", "flight-plan"] + [x for k, v in options.items() if v is not None for x in (k, v)]


@pytest.mark.parametrize("option", FLIGHT_FLOATS)
@pytest.mark.parametrize("value", BAD_FLOATS)
def test_flight_plan_float_out_of_range(refuse, option, value):
    if option.endswith("overlap") and value in ("0", "1e-300"):
        pytest.skip("no overlap is a valid (if poor) survey")
    refuse(*_flight(**{option: value}), mentions=(option,))


@pytest.mark.parametrize("value", ["0", "-5", "10000000", "9" * 5000, "1.5"])
def test_flight_plan_image_width_out_of_range(refuse, value):
    refuse(*_flight(**{"--image-width-px": value}), mentions=("--image-width-px",))


def test_flight_plan_too_many_images(refuse):
    refuse(*_flight(**{"--altitude-m": "1", "--area-width-m": "100000", "--area-length-m": "100000"}),
           mentions=("images", "1000000"))


@pytest.mark.parametrize("missing", list(GSD))
def test_flight_plan_gsd_options_go_together(refuse, missing):
    message = refuse(*_flight(**{missing: None}), mentions=(missing,))
    assert "altitude_m" not in message and "sensor_width_mm" not in message


def test_flight_plan_names_options_not_fields(refuse):
    message = refuse(*_flight(**{"--altitude-m": "-3"}), mentions=("--altitude-m",))
    assert "altitude_m" not in message


# --- gcp -----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("value", ["nan", "inf", "-1", "1e308"])
def test_gcp_threshold_out_of_range(refuse, value):
    refuse("survey", "gcp", GCP_SURVEYED, GCP_MODEL, "--threshold-m", value, mentions=("--threshold-m",))


GCP_CASES = {
    "not-utf8": (b"id,x,y,z\nGCP1,1,2,\xff\n", ("UTF-8",)),
    "utf16": ("id,x,y,z\nGCP1,1,2,3\n".encode("utf-16"), ("UTF-8",)),
    "nul-bytes": (b"id,x,y,z\nGCP1,1,2,3\0\n", ()),
    "field-over-csv-limit": (b"id,x,y,z\n" + b"G" * 200_000 + b",1,2,3\n", ()),
    "huge-coordinate": (b"id,x,y,z\nGCP1,1e308,2,3\nGCP2,1,2,3\nGCP3,1,2,3\n", ("1e308",)),
    "inf-coordinate": (b"id,x,y,z\nGCP1,inf,2,3\n", ("line 2",)),
    "5000-digit-coordinate": (b"id,x,y,z\nGCP1," + b"9" * 5000 + b",2,3\n", ("line 2",)),
    "empty-id": (b"id,x,y,z\n,1,2,3\n", ("line 2", "id")),
    "short-row": (b"id,x,y,z\nGCP1,1\n", ("line 2",)),
    "no-header": (b"", ("id,x,y,z",)),
    "header-only": (b"id,x,y,z\n", ("no GCP",)),
    "duplicate-id": (b"id,x,y,z\nA,1,2,3\nA,1,2,3\n", ("twice",)),
    "binary": (bytes(range(256)) * 10, ()),
}


@pytest.mark.parametrize("case", GCP_CASES)
def test_hostile_gcp_csv(refuse, workdir, case):
    content, words = GCP_CASES[case]
    path = write(workdir / "gcp.csv", content)
    refuse("survey", "gcp", path, GCP_MODEL, mentions=("gcp.csv", *words))


@pytest.mark.parametrize("which", ["surveyed", "model"])
def test_gcp_csv_is_dev_zero_or_fifo(refuse, workdir, which):
    import os

    fifo = workdir.parent / f"{workdir.name}.gcp.pipe"
    os.mkfifo(fifo)
    for bad in ("/dev/zero", fifo):
        files = (bad, GCP_MODEL) if which == "surveyed" else (GCP_SURVEYED, bad)
        refuse("survey", "gcp", *files, mentions=(str(bad), "regular file"))


def test_gcp_csv_over_size_limit(refuse, workdir):
    path = workdir / "big.csv"
    with open(path, "wb") as fh:
        fh.truncate(65 * 2**20)
    refuse("survey", "gcp", path, GCP_MODEL, mentions=("big.csv", "MiB"))


# --- twin import / twin demo ------------------------------------------------------------------------------

TWIN_FLOATS = {"--scale": "mesh", "--max-deviation-m": "pointcloud", "--plane-threshold-m": "pointcloud",
               "--storey-height-m": "footprints"}


@pytest.mark.parametrize("option", TWIN_FLOATS)
@pytest.mark.parametrize("value", BAD_FLOATS[:7] + ["1e-9"])
def test_twin_import_float_out_of_range(refuse, workdir, option, value):
    kind = TWIN_FLOATS[option]
    extra = ["--rules", RULES] if kind == "mesh" else []
    refuse("twin", "import", kind, workdir / "absent.input", *extra, option, value, "--out", workdir / "out",
           mentions=(option,))


@pytest.mark.parametrize("option, value, kind", [("--lod", "2", "footprints"), ("--scale", "2", "cityjson"),
                                                 ("--up-axis", "Y", "pointcloud"),
                                                 ("--storey-height-m", "3", "mesh"),
                                                 ("--max-deviation-m", "0.01", "cityjson")])
def test_option_of_another_kind_is_refused(refuse, workdir, option, value, kind):
    extra = ["--rules", RULES] if kind == "mesh" else []
    refuse("twin", "import", kind, GEOJSON, *extra, option, value, "--out", workdir / "out", mentions=(option, kind))


@pytest.mark.parametrize("value", [str(2**64), str(2**32), "-1", "1e3", "9" * 5000])
def test_twin_demo_seed_out_of_range(refuse, workdir, value):
    refuse("twin", "demo", "--seed", value, "--out", workdir / "out", mentions=("--seed",))


def test_twin_import_out_is_a_file(refuse, workdir):
    target = write(workdir / "taken", "keep me")
    refuse("twin", "import", "footprints", GEOJSON, "--out", target, mentions=("taken",))


def test_twin_import_input_is_a_folder(refuse, workdir):
    folder = workdir / "blocks.geojson"
    folder.mkdir()
    refuse("twin", "import", "footprints", folder, "--out", workdir / "out", mentions=("blocks.geojson",))


def test_mesh_import_without_rules(refuse, workdir):
    refuse("twin", "import", "mesh", mesh_input(workdir), "--out", workdir / "out", mentions=("--rules",))
