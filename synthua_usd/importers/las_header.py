"""LAS/LAZ headers checked against the file they describe, before laspy reads them.

A LAS file's public header block says where everything is: the size of the block, how many variable-length
records (VLRs, 54-byte headers each) follow it and how long each is, where the point data starts, how many
points of how many bytes it holds, and (LAS 1.4) where the extended VLRs (60-byte headers) lie and how many
there are. laspy believes these numbers: a count of 4,294,967,295 VLRs in a 4 KB file makes it loop
for hours on an exhausted stream, a point count makes it allocate. :func:`check_las_layout` reads the header
bytes itself and walks the record headers (at most one per 54 bytes of the file, so the walk is bounded by
the file's size) and refuses any number the file cannot hold; :func:`check_las_header` checks the
header laspy parsed (counts against the limits, scales and offsets).
"""

from __future__ import annotations

import struct

import numpy as np

from synthua_usd.core.errors import InputError, echo
from synthua_usd.importers.limits import MAX_POINTS
from synthua_usd.model.ranges import COORDINATE

#: Largest point data a LAS/LAZ header may announce (points x record length), decompressed in memory.
MAX_POINT_DATA_BYTES = 2 * 2**30
#: Size of the public header block by minor version of LAS 1.x (the ASPRS specifications).
HEADER_BYTES = {0: 227, 1: 227, 2: 227, 3: 235, 4: 375}
VLR_HEADER_BYTES, EVLR_HEADER_BYTES = 54, 60


def check_las_layout(path, size: int, where: str) -> None:
    """Refuse a LAS/LAZ file (``size`` bytes) whose header places any block outside the file: header size,
    offset to point data, every VLR and EVLR, the point records of an uncompressed file."""
    with open(path, "rb") as fh:
        head = fh.read(HEADER_BYTES[4])
        if head[:4] != b"LASF":
            raise InputError(f"{where}: cannot read as LAS/LAZ: it does not start with the 'LASF' signature; "
                             f"expected a LAS or LAZ file")
        if len(head) < HEADER_BYTES[0]:
            raise InputError(f"{where}: cannot read as LAS/LAZ: {size} bytes, fewer than the {HEADER_BYTES[0]} of a "
                             f"LAS header; expected a complete LAS or LAZ file")
        major, minor = head[24], head[25]
        if major != 1 or minor not in HEADER_BYTES:
            raise InputError(f"{where}: LAS version {major}.{minor}; expected 1.0 to 1.4")
        header_size, to_points, vlrs = struct.unpack_from("<HII", head, 94)
        if not HEADER_BYTES[minor] <= header_size <= to_points <= size:
            raise InputError(f"{where}: the header says its block is {header_size} bytes and the points start at "
                             f"byte {to_points}, in a file of {size} bytes; expected {HEADER_BYTES[minor]} <= "
                             f"header size <= offset to point data <= file size")
        fh.seek(header_size)
        _walk_records(fh.read(to_points - header_size), vlrs, VLR_HEADER_BYTES, "<H", 20, where, "VLR",
                      f"before the point data at byte {to_points}")
        record = struct.unpack_from("<H", head, 105)[0]
        count = struct.unpack_from("<Q", head, 247)[0] if minor >= 4 else struct.unpack_from("<I", head, 107)[0]
        check_point_count(count, record, where)
        compressed = head[104] & 0x80 != 0
        if compressed:
            _check_chunk_table(fh, to_points, size, where)
        elif to_points + count * record > size:
            held = (size - to_points) // max(record, 1)
            raise InputError(f"{where}: the header announces {count} points but the file holds {held}; expected a "
                             f"complete LAS file")
        if minor >= 4:
            start, evlrs = struct.unpack_from("<QI", head, 235)
            if evlrs:
                if not to_points <= start <= size:
                    raise InputError(f"{where}: the header puts {evlrs} extended VLRs at byte {start}, in a file of "
                                     f"{size} bytes; expected them after the point data, inside the file")
                fh.seek(start)
                _walk_records(fh.read(size - start), evlrs, EVLR_HEADER_BYTES, "<Q", 20, where, "extended VLR",
                              "inside the file")


def _check_chunk_table(fh, to_points: int, size: int, where: str) -> None:
    """A LAZ file's point data starts with the offset of its chunk table (-1: in the file's last 8 bytes),
    whose header gives a version (0) and the number of chunks, each of at least one byte of compressed
    data; LASzip allocates the table by that number before it reads a point."""
    fh.seek(to_points)
    first = fh.read(8)
    if len(first) < 8:
        raise InputError(f"{where}: the LAZ point data at byte {to_points} is shorter than its 8-byte chunk table "
                         f"offset; expected a complete LAZ file")
    table = struct.unpack("<q", first)[0]
    if table == -1 and size >= 8:
        fh.seek(size - 8)
        table = struct.unpack("<q", fh.read(8))[0]
    if not to_points + 8 <= table <= size - 8:
        raise InputError(f"{where}: the LAZ chunk table is at byte {table}, outside the point data (bytes "
                         f"{to_points + 8} to {size - 8}); expected a complete LAZ file")
    fh.seek(table)
    version, chunks = struct.unpack("<II", fh.read(8))
    if version != 0 or chunks > table - to_points - 8:
        raise InputError(f"{where}: the LAZ chunk table (version {version}) announces {chunks} chunks in "
                         f"{table - to_points - 8} bytes of compressed points; expected version 0 and at most one "
                         f"chunk per byte")


def _walk_records(data: bytes, count: int, header_bytes: int, length_format: str, length_at: int, where: str,
                  kind: str, bound: str) -> None:
    """Each of ``count`` records (a ``header_bytes`` header whose length field, ``length_format`` at byte
    ``length_at``, gives the bytes after it) must end within ``data``."""
    if count * header_bytes > len(data):
        raise InputError(f"{where}: the header announces {count} {kind}s, more than the {len(data)} bytes {bound} can "
                         f"hold; expected a complete file")
    pos = 0
    for k in range(count):
        if pos + header_bytes > len(data):
            raise InputError(f"{where}: {kind} {k} of {count} starts past the end of its block ({bound}); expected a "
                             f"complete file")
        pos += header_bytes + struct.unpack_from(length_format, data, pos + length_at)[0]
        if pos > len(data):
            raise InputError(f"{where}: {kind} {k} of {count} runs {pos - len(data)} bytes past the end of its block "
                             f"({bound}); expected a complete file")


def check_point_count(count: int, record: int, where: str) -> None:
    """At most :data:`MAX_POINTS` points and :data:`MAX_POINT_DATA_BYTES` of point data."""
    if count > MAX_POINTS:
        raise InputError(f"{where}: the header announces {count} points; expected at most {MAX_POINTS} (thin or tile "
                         f"the cloud)")
    if count * record > MAX_POINT_DATA_BYTES:
        raise InputError(f"{where}: the header announces {count} points of {record} bytes ({count * record} bytes); "
                         f"expected at most {MAX_POINT_DATA_BYTES} bytes of point data")


def check_las_header(header, where: str) -> None:
    """Refuse a LAS/LAZ header (laspy's) whose point count, record size, scales or offsets cannot be true
    (before any point is read, so that a lying header cannot make us allocate what it claims)."""
    check_point_count(int(header.point_count), int(header.point_format.size), where)
    scales, offsets = np.asarray(header.scales, float), np.asarray(header.offsets, float)
    if not (np.all(np.isfinite(scales)) and np.all(scales > 0) and np.all(scales <= 1e3)):
        raise InputError(f"{where}: header scale factors {echo(scales.tolist())}; expected numbers in (0, 1000]")
    if not np.all(np.abs(offsets) <= COORDINATE.high):  # NaN fails too
        raise InputError(f"{where}: header offsets {echo(offsets.tolist())}; expected numbers within "
                         f"±{COORDINATE.high:g} m")
