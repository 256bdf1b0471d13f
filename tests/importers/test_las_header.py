"""LAS/LAZ headers checked against the file's size before laspy reads them."""

import struct
import time

import numpy as np
import pytest

from conftest import SHARED
from las_files import write_las
from synthua_usd.core.errors import InputError
from synthua_usd.importers.las_header import check_las_layout

THIRD_PARTY = SHARED / "data" / "third_party" / "las"


@pytest.mark.parametrize("suffix,wkt", [(".las", False), (".laz", False), (".las", True), (".laz", True)])
def test_files_laspy_writes_pass(tmp_path, suffix, wkt):
    path = write_las(tmp_path / f"c{suffix}", np.random.default_rng(0).uniform(0, 9, (300, 3)), wkt=wkt)
    check_las_layout(path, path.stat().st_size, path.name)


@pytest.mark.parametrize("name", ["simple.las", "plane.laz"])
def test_third_party_files_pass(name):
    path = THIRD_PARTY / name
    if not path.exists():
        pytest.skip(f"{path} not present")
    check_las_layout(path, path.stat().st_size, name)


def test_a_count_of_4e9_vlrs_is_refused_without_walking_them(tmp_path):
    path = write_las(tmp_path / "c.las", np.zeros((3, 3)), crs=None)
    data = bytearray(path.read_bytes())
    struct.pack_into("<I", data, 100, 2**32 - 1)
    path.write_bytes(bytes(data))
    t0 = time.perf_counter()
    with pytest.raises(InputError, match="4294967295 VLRs"):
        check_las_layout(path, len(data), "c.las")
    assert time.perf_counter() - t0 < 1.0


def test_a_truncated_las_is_refused_by_its_point_count(tmp_path):
    path = write_las(tmp_path / "c.las", np.zeros((100, 3)), crs=None)
    data = path.read_bytes()[:-200]
    path.write_bytes(data)
    with pytest.raises(InputError, match="announces 100 points but the file holds"):
        check_las_layout(path, len(data), "c.las")
