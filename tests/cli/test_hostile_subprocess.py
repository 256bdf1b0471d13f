"""The hostile cases that can hang or run away on a bad build, and a representative subset of the others, as
a user runs them: ``python -m synthua_usd`` in a subprocess, under a time limit and a memory cap."""

from __future__ import annotations

import json
import os
import shutil

import pytest

from hostile import assert_refused, tree_state
from importers.hostile_corpus import CITYJSON, CLASSMAP, GCP_MODEL, GEOJSON, doc, mesh_input, run_limited, write

#: A hang check fails long before the suite's own time limit.
HANG_S = 30


@pytest.fixture
def space(tmp_path, earlier_import):
    """The current folder of a case, holding its inputs and ``out/`` (a copy of an earlier import)."""
    space = tmp_path / "space"
    shutil.copytree(earlier_import, space / "out")
    return space


def _refused(space, *args, mentions=()):
    before = tree_state(space)
    result = run_limited(*args, cwd=space, timeout=HANG_S)
    message = assert_refused(result, *mentions)
    assert tree_state(space) == before
    return message


def test_catastrophic_regex_runs_in_linear_time(space):
    """``(a+)+$`` against 'aaa...a!' backtracks for hours in a backtracking engine; RE2 answers at once."""
    obj = write(space / "a.obj", "o " + "a" * 40 + "!\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    rules = write(space / "rules.json", {"rules": [{"field": "any", "pattern": "(a+)+$", "class": "road"}]})
    result = run_limited("twin", "import", "mesh", obj, "--rules", rules, "--out", space / "new", cwd=space,
                         timeout=HANG_S)
    assert result.code == 0 and "Traceback" not in result.stderr, result.stderr
    assert "error" not in result.stderr


def test_backreference_is_refused(space):
    rules = write(space / "rules.json", {"rules": [{"field": "any", "pattern": r"(a)\1", "class": "road"}]})
    message = _refused(space, "twin", "import", "mesh", mesh_input(space), "--rules", rules, "--out", space / "out",
                       mentions=("rules.json", "rules[0].pattern"))
    assert "re2" not in message.lower() or "backreference" in message.lower()


def _document_command(role: str, path, space) -> list:
    """The command that reads a JSON document (or CSV) ``path`` in ``role``."""
    return {"validate": ["validate", "classes", path],
            "class-map": ["twin", "import", "footprints", GEOJSON, "--class-map", path, "--out", space / "out"],
            "rules": ["twin", "import", "mesh", mesh_input(space), "--rules", path, "--out", space / "out"],
            "cityjson": ["twin", "import", "cityjson", path, "--out", space / "out"],
            "geojson": ["twin", "import", "footprints", path, "--out", space / "out"],
            "gcp": ["survey", "gcp", path, GCP_MODEL]}[role]


@pytest.mark.parametrize("role", ["validate", "gcp"])
def test_dev_zero_is_never_read(space, role):
    """A character device reads forever: refused before reading, as not a regular file."""
    _refused(space, *_document_command(role, "/dev/zero", space), mentions=("/dev/zero", "regular file"))


@pytest.mark.parametrize("role", ["validate", "cityjson", "gcp"])
def test_fifo_never_blocks(space, role):
    """Opening a FIFO with no writer blocks forever: refused before opening. (The FIFO lies beside the
    snapshotted folder: tests/hostile.py's tree_state would block reading it.)"""
    fifo = space.parent / "pipe"
    os.mkfifo(fifo)
    _refused(space, *_document_command(role, fifo, space), mentions=("pipe", "regular file"))


def test_random_laz_is_refused(space):
    import numpy as np
    import struct

    h = bytearray(227)
    h[0:4], h[24], h[25] = b"LASF", 1, 2
    struct.pack_into("<HIIBHI", h, 94, 227, 227, 0, 0x80, 20, 50_000)
    struct.pack_into("<3d", h, 131, 0.01, 0.01, 0.01)
    laz = write(space / "scan.laz", bytes(h) + np.random.default_rng(1).integers(0, 256, 30_000, np.uint8).tobytes())
    _refused(space, "twin", "import", "pointcloud", laz, "--out", space / "out", mentions=("scan.laz",))


def test_deeply_nested_cityjson(space):
    path = write(space / "deep.json", "[" * 100_000 + "]" * 100_000)
    _refused(space, "twin", "import", "cityjson", path, "--out", space / "out", mentions=("deep.json", "nested"))


def test_negative_boundary_index(space):
    d = doc(CITYJSON)
    d["CityObjects"]["house-1"]["geometry"][0]["boundaries"][0][0][0][0] = -1
    path = write(space / "city.json", d)
    _refused(space, "twin", "import", "cityjson", path, "--out", space / "out", mentions=("city.json", "-1"))


def test_bow_tie_footprint(space):
    d = doc(GEOJSON)
    d["features"][0]["geometry"]["coordinates"] = [[[-49.2712, -25.4270], [-49.2710, -25.4268], [-49.2710, -25.4270],
                                                    [-49.2712, -25.4268], [-49.2712, -25.4270]]]
    path = write(space / "b.geojson", d)
    _refused(space, "twin", "import", "footprints", path, "--out", space / "out", mentions=("b.geojson",
                                                                                             "self-intersect"))


def test_huge_height(space):
    d = doc(GEOJSON)
    d["features"][0]["properties"]["height"] = 1e308
    path = write(space / "b.geojson", d)
    _refused(space, "twin", "import", "footprints", path, "--out", space / "out", "--strict",
             mentions=("b.geojson", "height"))


def test_non_utf8_class_map(space):
    path = write(space / "classes.json", json.dumps(doc(CLASSMAP)).replace("Road", "R\udcffd").encode(
        "utf-8", "surrogateescape"))
    _refused(space, "validate", "classes", path, mentions=("classes.json", "UTF-8"))


def test_flight_plan_absurd_area(space):
    _refused(space, "survey", "flight-plan", "--altitude-m", "150", "--fov-deg", "84", "--area-width-m", "1e308",
             "--area-length-m", "1225", mentions=("--area-width-m",))


def test_plane_threshold_nan(space):
    _refused(space, "twin", "import", "pointcloud", "x.las", "--plane-threshold-m", "nan", "--out", space / "out",
             mentions=("--plane-threshold-m",))


def test_demo_seed_2_64(space):
    _refused(space, "twin", "demo", "--seed", str(2**64), "--out", space / "out", mentions=("--seed",))


def test_the_laz_of_the_issue_is_refused_at_once(space):
    """'LASF' and random bytes: laspy believed the header's 4e9 VLRs and looped past 60 s."""
    import numpy as np

    laz = write(space / "garbage.laz", b"LASF" + np.random.default_rng(24).integers(0, 256, 4000, np.uint8).tobytes())
    result = run_limited("twin", "import", "pointcloud", laz, "--units", "m", "--out", space / "out", cwd=space,
                         timeout=10)
    assert_refused(result, "garbage.laz")


@pytest.mark.parametrize("where,value", [("chunks", 2**32 - 1), ("table", 2**40), ("version", 7)])
def test_a_lying_laz_chunk_table_is_refused_before_lazrs_allocates(space, where, value):
    """A LAZ whose chunk table announces 4e9 chunks made lazrs abort the process (a 46 GB allocation)."""
    import struct

    import numpy as np
    from las_files import write_las

    path = write_las(space / "scan.laz", np.random.default_rng(0).uniform(0, 50, (500, 3)))
    data = bytearray(path.read_bytes())
    to_points = struct.unpack_from("<I", data, 96)[0]
    table = struct.unpack_from("<q", data, to_points)[0]
    if where == "table":
        struct.pack_into("<q", data, to_points, value)
    else:
        struct.pack_into("<I", data, table + (4 if where == "chunks" else 0), value)
    path.write_bytes(bytes(data))
    assert_refused(run_limited("twin", "import", "pointcloud", path, "--out", space / "new", cwd=space,
                               timeout=HANG_S), "scan.laz", "chunk")
