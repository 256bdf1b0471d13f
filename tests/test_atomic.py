"""Output sets: a command's files move into place together, or not at all."""

import pytest

from synthua_usd.atomic import output_set
from synthua_usd.errors import OutputError


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
