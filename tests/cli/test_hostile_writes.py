"""Hostile output locations for every command that writes USD layers: a full disk and a file-size limit.

OpenUSD reports a failed layer write as a Tf error without an errno; each must become the one-line "no
space left on device" (or "file too large") refusal that other writes give, naming the file the user asked
for (never a temporary file or staging folder), with nothing left behind.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import DATA
from hostile import Result, assert_refused, run_synthua, size_limited, small_disk

OBJ, RULES = DATA / "valid" / "street.obj", DATA / "valid" / "mesh_rules.json"
TINY = DATA / "valid" / "tiny_scene.usda"

#: name -> arguments writing under ``out`` (a folder that does not exist yet).
LAYER_WRITERS = {
    "create street": lambda out: ["create", "street", out],
    "twin import mesh": lambda out: ["twin", "import", "mesh", OBJ, "--rules", RULES, "--out", out],
    "compose": lambda out: ["compose", out.parent / "root.usda", TINY, "--allow-external-assets"],
}


def _fill(disk: Path) -> None:
    """Fill ``disk`` to its last byte (a file in a folder of its own, which the checks below leave out)."""
    (disk / "filler").mkdir()
    fd = os.open(disk / "filler" / "zeros", os.O_WRONLY | os.O_CREAT)
    try:
        while os.write(fd, bytes(4096)):
            pass
    except OSError:
        pass
    finally:
        os.close(fd)


@pytest.mark.parametrize("name", sorted(LAYER_WRITERS))
def test_a_usd_layer_on_a_full_disk_is_one_line_and_leaves_nothing(name, tmp_path):
    with small_disk(tmp_path, "size=64k") as disk:
        _fill(disk)
        result = run_synthua(*LAYER_WRITERS[name](disk / "out"))
        message = assert_refused(result, "no space left on device", str(disk))
        assert ".partial" not in message and "/." not in message, message  # the user's path, not a temporary one
        assert sorted(os.listdir(disk)) == ["filler"]


@pytest.mark.parametrize("name", sorted(LAYER_WRITERS))
def test_a_usd_layer_past_the_file_size_limit_is_one_line_and_leaves_nothing(name, tmp_path):
    args = LAYER_WRITERS[name](tmp_path / "out")
    proc = subprocess.run([sys.executable, "-m", "synthua_usd", *map(str, args)], capture_output=True, timeout=60,
                          preexec_fn=size_limited(300), stdin=subprocess.DEVNULL)
    result = Result(proc.returncode, proc.stdout.decode(), proc.stderr.decode(), 0.0)
    message = assert_refused(result, "file too large", str(tmp_path))
    assert ".partial" not in message and "/." not in message, message
    assert os.listdir(tmp_path) == []


def test_an_output_folder_that_cannot_take_the_files_is_named_not_the_staging_folder(tmp_path):
    """The output folder is a read-only mount in a writable folder: the staging folder is made beside it, and
    moving the files in fails; the message names out/<file>, never .out.partial-XXXX/<file>."""
    with small_disk(tmp_path, "size=64k,ro") as disk:
        result = run_synthua("render", TINY, "--camera", "/World/Cam", "--width", "8", "--height", "6", "--spp", "1",
                             "--out", disk)
        message = assert_refused(result, str(disk))
        assert ".partial" not in message, message
        assert sorted(os.listdir(tmp_path)) == ["mnt"]


#: name -> arguments writing ``out`` (relative to the current folder) inside a read-only folder.
READ_ONLY_WRITERS = {
    "compose": lambda out: ["compose", f"{out}.usda", TINY, "--allow-external-assets"],
    "agents populate": lambda out: ["agents", "populate", TINY.parent / "tiny_street_lamps.usda", "--walk-on", "road",
                                    "--out", f"{out}.usdc"],
    "render": lambda out: ["render", TINY, "--camera", "/World/Cam", "--width", "8", "--height", "6", "--spp", "1",
                           "--out", out],
    "twin import": lambda out: ["twin", "import", "mesh", OBJ, "--rules", RULES, "--out", out],
}


@pytest.mark.parametrize("name", sorted(READ_ONLY_WRITERS))
def test_a_read_only_folder_names_the_output_not_a_temporary_file(name, tmp_path):
    """compose into a folder it may not write named '/tmp/.../mnt/.root.6dkhxtu7.usda' (tempfile gives its own
    names absolute; the output was asked for relative), render its staging folder 'mnt/.out.partial-...'."""
    with small_disk(tmp_path, "size=64k,ro"):
        args = READ_ONLY_WRITERS[name]("mnt/out")
        result = run_synthua(*args, cwd=tmp_path)
        message = assert_refused(result, "mnt/out", "read-only file system")
        assert ".partial" not in message and "/." not in message and "mnt/." not in message, message
