"""Hostile meshes and point clouds for ``synthua twin import mesh`` and ``pointcloud``. Binary files whose
headers lie run under the in-process runner's memory cap: a build that believes a header's point count
fails the case with MemoryError instead of exhausting the machine."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from importers.hostile_corpus import RULES, write

OBJ_CASES = {
    "empty": ("", ("triangles",)),
    "points-only": ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", ("triangles",)),
    "two-vertex-faces": ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 2 3\n", ("triangles",)),
    "face-past-end": ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n", ()),
    "nan-vertex": ("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", ("NaN",)),
    "huge-vertex": ("v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n", ("coordinates",)),
    "5000-digit-index": ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 " + "3" * 5000 + "\n", ()),
    "binary-garbage": (bytes(range(256)) * 40, ()),
}


@pytest.mark.parametrize("case", OBJ_CASES)
def test_hostile_obj(refuse, workdir, case):
    content, words = OBJ_CASES[case]
    path = write(workdir / "city.obj", content)
    refuse("twin", "import", "mesh", path, "--rules", RULES, "--out", workdir / "out", mentions=("city.obj", *words))


def _ply(vertices: int, faces: int, body: bytes = b"") -> bytes:
    return (f"ply\nformat ascii 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\n"
            f"property float z\nelement face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
            ).encode() + body


PLY_CASES = {
    "negative-faces": _ply(3, -1, b"0 0 0\n1 0 0\n0 1 0\n"),
    "negative-vertices": _ply(-3, 1, b"3 0 1 2\n"),
    "zero-everything": _ply(0, 0),
    "claims-1e12-vertices": _ply(10**12, 1, b"0 0 0\n"),
    "two-vertex-face": _ply(3, 1, b"0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
}


@pytest.mark.parametrize("case", PLY_CASES)
def test_hostile_ply_mesh(refuse, workdir, case):
    path = write(workdir / "city.ply", PLY_CASES[case])
    refuse("twin", "import", "mesh", path, "--rules", RULES, "--out", workdir / "out", mentions=("city.ply",))


def test_binary_stl_header_lies(refuse, workdir):
    path = write(workdir / "city.stl", b"\0" * 80 + struct.pack("<I", 2**32 - 1) + b"\0" * 100)
    refuse("twin", "import", "mesh", path, "--rules", RULES, "--out", workdir / "out", mentions=("city.stl",))


@pytest.mark.parametrize("suffix", [".obj", ".glb", ".stl"])
def test_mesh_input_is_dev_zero(refuse, workdir, suffix):
    link = workdir / f"zero{suffix}"
    link.symlink_to("/dev/zero")
    refuse("twin", "import", "mesh", link, "--rules", RULES, "--out", workdir / "out",
           mentions=(link.name, "regular file"))


# --- point clouds ------------------------------------------------------------------------------------------

def _las_header(point_count: int, record_length: int = 20, fmt: int = 0, scale: float = 0.01,
                minor: int = 2) -> bytearray:
    """A LAS 1.2 public header block (227 bytes)."""
    h = bytearray(227)
    h[0:4] = b"LASF"
    h[24], h[25] = 1, minor
    struct.pack_into("<H", h, 94, 227)            # header size
    struct.pack_into("<I", h, 96, 227)            # offset to point data
    struct.pack_into("<I", h, 100, 0)             # number of VLRs
    h[104] = fmt
    struct.pack_into("<H", h, 105, record_length)
    struct.pack_into("<I", h, 107, point_count)
    struct.pack_into("<3d", h, 131, scale, scale, scale)
    struct.pack_into("<3d", h, 155, 0.0, 0.0, 0.0)
    return h


def _las14_header(point_count: int, evlrs: int, evlr_start: int) -> bytearray:
    """A LAS 1.4 public header block (375 bytes) of point format 6 (30-byte records)."""
    h = bytearray(375)
    h[0:4], h[24], h[25] = b"LASF", 1, 4
    struct.pack_into("<HIIBH", h, 94, 375, 375, 0, 6, 30)
    struct.pack_into("<3d", h, 131, 0.01, 0.01, 0.01)
    struct.pack_into("<QIQ", h, 235, evlr_start, evlrs, point_count)
    return h


def _patched(block: bytearray, fmt: str, offset: int, *values) -> bytes:
    """``block`` with ``values`` packed as ``fmt`` at ``offset``."""
    block = bytearray(block)
    struct.pack_into(fmt, block, offset, *values)
    return bytes(block)


def _with_vlrs(h: bytearray, vlrs: int, data: bytes) -> bytes:
    """``h`` announcing ``vlrs`` VLRs, followed by ``data`` (the VLR bytes), the points starting after it."""
    h = bytearray(h)
    struct.pack_into("<II", h, 96, len(h) + len(data), vlrs)
    return bytes(h) + data


def _vlr(length: int, body: bytes = b"") -> bytes:
    """A VLR header (54 bytes) announcing ``length`` bytes after it, then ``body``."""
    head = bytearray(54)
    head[2:18] = b"someone".ljust(16, b"\0")
    struct.pack_into("<HH", head, 18, 1, length)
    return bytes(head) + body


def _las_points(n: int, rng) -> bytes:
    xyz = rng.integers(0, 1000, size=(n, 3), dtype=np.int32)
    records = np.zeros(n, dtype=[("xyz", "<i4", 3), ("rest", "V8")])
    records["xyz"] = xyz
    return records.tobytes()


def _random_laz(rng) -> bytes:
    """A LAZ-looking file: LAS signature, a point format with the compression bit, then random bytes."""
    h = _las_header(50_000, 20, fmt=0 | 0x80)
    return bytes(h) + rng.integers(0, 256, 20_000, dtype=np.uint8).tobytes()


POINTCLOUD_CASES = {
    "laz-random-bytes": ("cloud.laz", lambda rng: _random_laz(rng)),
    "las-random-body": ("cloud.las", lambda rng: bytes(_las_header(1000)) + rng.integers(0, 256, 20_000,
                                                                                          dtype=np.uint8).tobytes()),
    "las-claims-4e9-points": ("cloud.las", lambda rng: bytes(_las_header(2**32 - 1)) + _las_points(10, rng)),
    "las-short-body": ("cloud.las", lambda rng: bytes(_las_header(1000)) + _las_points(10, rng)),
    "las-scale-zero": ("cloud.las", lambda rng: bytes(_las_header(100, scale=0.0)) + _las_points(100, rng)),
    "las-scale-nan": ("cloud.las", lambda rng: bytes(_las_header(100, scale=float("nan"))) + _las_points(100, rng)),
    "las-scale-huge": ("cloud.las", lambda rng: bytes(_las_header(100, scale=1e300)) + _las_points(100, rng)),
    "las-zero-points": ("cloud.las", lambda rng: bytes(_las_header(0))),
    "las-signature-only": ("cloud.las", lambda rng: b"LASF"),
    "las-same-point": ("cloud.las", lambda rng: bytes(_las_header(100)) + bytes(20) * 100),
    # Header fields checked against the file's size before laspy reads (it believes them: hours of looping)
    "laz-signature-then-random": ("cloud.laz", lambda rng: b"LASF" + rng.integers(0, 256, 4000, np.uint8).tobytes()),
    "las-version-9": ("cloud.las", lambda rng: bytes(_las_header(10, minor=9)) + _las_points(10, rng)),
    "las-header-size-past-end": ("cloud.las", lambda rng: _patched(_las_header(10), "<H", 94, 60000)
                                 + _las_points(10, rng)),
    "las-point-offset-past-end": ("cloud.las", lambda rng: _patched(_las_header(10), "<I", 96, 2**32 - 1)
                                  + _las_points(10, rng)),
    "las-4e9-vlrs": ("cloud.las", lambda rng: _with_vlrs(_las_header(10), 2**32 - 1, _vlr(0)) + _las_points(10, rng)),
    "las-vlr-past-point-data": ("cloud.las", lambda rng: _with_vlrs(_las_header(10), 1, _vlr(65535, bytes(100)))
                                + _las_points(10, rng)),
    "laz-4e9-vlrs": ("cloud.laz", lambda rng: _with_vlrs(_las_header(10, fmt=0x80), 2**32 - 1, b"")
                     + rng.integers(0, 256, 4000, np.uint8).tobytes()),
    "las14-4e9-evlrs": ("cloud.las", lambda rng: bytes(_las14_header(10, 2**32 - 1, 375 + 300)) + bytes(300)
                        + bytes(60)),
    "las14-evlrs-past-end": ("cloud.las", lambda rng: bytes(_las14_header(10, 1, 2**40)) + bytes(300)),
    "las14-evlr-longer-than-file": ("cloud.las", lambda rng: bytes(_las14_header(10, 1, 375 + 300)) + bytes(300)
                                    + _patched(bytearray(60), "<Q", 20, 2**62)),
    "las14-2e19-points": ("cloud.las", lambda rng: bytes(_las14_header(2**64 - 1, 0, 0)) + bytes(300)),
    "ply-two-points": ("cloud.ply", lambda rng: (b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                                 b"property float y\nproperty float z\nend_header\n0 0 0\n1 1 1\n")),
}


@pytest.mark.parametrize("case", POINTCLOUD_CASES)
def test_hostile_pointcloud(refuse, workdir, case):
    name, make = POINTCLOUD_CASES[case]
    path = write(workdir / name, make(np.random.default_rng(7)))
    refuse("twin", "import", "pointcloud", path, "--out", workdir / "out", mentions=(name,))


@pytest.mark.parametrize("verbose, shown", [([], ()), (["-v"], ("info",)), (["-vv"], ("info", "debug"))])
def test_mesh_import_prints_trimesh_notes_only_when_asked(run_cli, tmp_path, verbose, shown):
    """trimesh's "triangulating faces" (info) and "`trimesh.load(force='scene')` is a compatibility wrapper" (debug)
    were printed without -v, even on success: synthua lowered trimesh's logger to collect its notes of textures it
    could not load, and the root handler printed whatever reached it."""
    from importers.hostile_corpus import mesh_input

    code, _, err = run_cli(*verbose, "twin", "import", "mesh", mesh_input(tmp_path), "--rules", RULES, "--out",
                           tmp_path / "out")
    assert code == 0, err
    levels = {line.split(":")[1].strip() for line in err.splitlines() if line.startswith("synthua: ")}
    assert levels - {"warning"} == set(shown), err
