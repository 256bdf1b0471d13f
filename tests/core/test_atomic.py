"""Output sets: a command's files move into place together, or not at all."""

import pytest

from synthua_usd.core.atomic import output_set
from synthua_usd.core.errors import OutputError


def folder(path, **files):
    """``path`` made with ``files`` (name -> text) in it."""
    path.mkdir()
    for name, text in files.items():
        (path / name).write_text(text)
    return path


def test_a_new_folder_appears_complete(tmp_path):
    with output_set(tmp_path / "out") as staging:
        folder(staging / "a", **{"f.txt": "new"})
        assert not (tmp_path / "out").exists()
    assert (tmp_path / "out" / "a" / "f.txt").read_text() == "new"
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no staging folder left


def test_files_are_replaced_and_others_kept(tmp_path):
    out = folder(tmp_path / "out", **{"f.txt": "old", "mine.txt": "keep"})
    with output_set(out) as staging:
        (staging / "f.txt").write_text("new")
    assert (out / "f.txt").read_text() == "new" and (out / "mine.txt").read_text() == "keep"


@pytest.mark.parametrize("staged,error,text", [
    ({"f.txt": "new"}, RuntimeError, "boom"),  # the command fails after staging
    ({"f.txt": "new", "CCTV/frame.json": "{}"}, OutputError, "is a file where an output folder goes"),
])
def test_a_failure_leaves_the_folder_as_it_was(tmp_path, staged, error, text):
    out = folder(tmp_path / "out", **{"f.txt": "old", "CCTV": "a file"})
    with pytest.raises(error, match=text):
        with output_set(out) as staging:
            for name, content in staged.items():
                (staging / name).parent.mkdir(exist_ok=True)
                (staging / name).write_text(content)
            if error is RuntimeError:
                raise RuntimeError("boom")
    assert {p.name: p.read_text() for p in out.iterdir()} == {"f.txt": "old", "CCTV": "a file"}
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


# --- failures name what the user asked for, never a temporary file ---------------------------------------

def test_a_failed_write_names_the_target_not_its_temporary_file(tmp_path):
    import errno

    from synthua_usd.core.atomic import atomic_path

    target = tmp_path / "dir.png"
    with pytest.raises(OSError) as info:
        with atomic_path(target) as tmp:
            raise OSError(errno.ENOSPC, "No space left on device", str(tmp))
    assert info.value.errno == errno.ENOSPC and info.value.filename == str(target)
    assert [p.name for p in tmp_path.iterdir()] == []


def test_a_folder_where_the_file_goes_is_named_not_the_temporary_file(tmp_path):
    from synthua_usd.core.atomic import atomic_path

    target = tmp_path / "dir.png"
    target.mkdir()
    with pytest.raises(OSError) as info:
        with atomic_path(target) as tmp:
            tmp.write_bytes(b"x")
    assert str(target) in (info.value.filename, info.value.filename2)
    assert all(".dir." not in str(name) for name in (info.value.filename, info.value.filename2) if name)
    assert [p.name for p in tmp_path.iterdir()] == ["dir.png"]


def test_a_missing_folder_is_named_by_the_target(tmp_path):
    from synthua_usd.core.atomic import atomic_path

    target = tmp_path / "nope" / "x.json"
    with pytest.raises(FileNotFoundError) as info:
        with atomic_path(target):
            pass
    assert info.value.filename == str(target)


def test_output_set_failures_name_the_output_folder_not_the_staging_folder(tmp_path):
    import errno

    from synthua_usd.core.errors import StageError

    out = tmp_path / "ro"
    with pytest.raises(OSError) as info:
        with output_set(out) as staging:
            raise OSError(errno.EROFS, "Read-only file system", str(staging / "class.png"))
    assert info.value.filename == str(out / "class.png")
    with pytest.raises(StageError, match=r"^.*/ro/frame.json: bad$") as caught:
        with output_set(out) as staging:
            raise StageError(f"{staging / 'frame.json'}: bad")
    assert ".partial" not in str(caught.value)
    assert [p.name for p in tmp_path.iterdir()] == []


def _size_limited(limit: int):
    """Lower this process's file-size limit (soft) to ``limit`` bytes, SIGXFSZ ignored; returns the undo."""
    import resource
    import signal

    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, hard))

    def undo():
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
        signal.signal(signal.SIGXFSZ, handler)
    return undo


def test_write_failure_tells_a_full_file_from_another_failure(tmp_path):
    import errno

    from synthua_usd.core.atomic import write_failure

    tmp = tmp_path / ".x.abc.usdc"
    tmp.write_bytes(bytes(4096))
    undo = _size_limited(4096)  # the library's write stopped at the limit: one more byte fails with EFBIG
    try:
        full = write_failure(tmp_path / "x.usdc", tmp, "OpenUSD could not write the layer")
    finally:
        undo()
    assert full.errno == errno.EFBIG and full.filename == str(tmp_path / "x.usdc")
    other = write_failure(tmp_path / "x.usdc", tmp, f"could not open {tmp}")
    assert other.errno == errno.EIO and other.strerror == f"could not open {tmp_path / 'x.usdc'}"
    assert write_failure(tmp_path / "x.usdc", tmp, "", size=2**62).errno == errno.ENOSPC


@pytest.mark.parametrize("marker", ["manifest.json", "generate.json"])
def test_no_output_set_lands_in_a_dataset(tmp_path, marker):
    """Only generate writes into a dataset: a render or a report there would be files its manifest does not
    list."""
    dataset = folder(tmp_path / "ds", **{marker: "{}"})
    with output_set(dataset / "web"):  # a manifest.json or generate.json alone is another tool's file
        pass
    (dataset / "records").mkdir()
    for out in (dataset, dataset / "frames" / "mine"):
        with pytest.raises(OutputError, match="dataset folder"):
            with output_set(out):
                pass
    assert sorted(p.name for p in dataset.iterdir()) == sorted([marker, "records", "web"])
