"""Output sets: a command's files move into place together, or not at all."""

import pytest

from synthua_usd.atomic import output_set
from synthua_usd.errors import InputError


def test_a_new_folder_appears_complete(tmp_path):
    with output_set(tmp_path / "out") as staging:
        (staging / "a").mkdir()
        (staging / "a" / "f.txt").write_text("new")
        assert not (tmp_path / "out").exists()
    assert (tmp_path / "out" / "a" / "f.txt").read_text() == "new"
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no staging folder left


def test_files_are_replaced_and_others_kept(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "f.txt").write_text("old")
    (out / "mine.txt").write_text("keep")
    with output_set(out) as staging:
        (staging / "f.txt").write_text("new")
    assert (out / "f.txt").read_text() == "new" and (out / "mine.txt").read_text() == "keep"


def test_a_failure_leaves_the_folder_as_it_was(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "f.txt").write_text("old")
    with pytest.raises(RuntimeError, match="boom"):
        with output_set(out) as staging:
            (staging / "f.txt").write_text("new")
            raise RuntimeError("boom")
    assert (out / "f.txt").read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_file_where_a_folder_goes_is_refused_before_anything_moves(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "CCTV").write_text("a file")
    with pytest.raises(InputError, match="is a file where an output folder goes"):
        with output_set(out) as staging:
            (staging / "a.txt").write_text("new")
            (staging / "CCTV").mkdir()
            (staging / "CCTV" / "frame.json").write_text("{}")
    assert sorted(p.name for p in out.iterdir()) == ["CCTV"]
