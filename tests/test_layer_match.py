"""tests/layer_match.py: a last-bit difference of a number passes, a stale layer does not."""

from pxr import Sdf

from layer_match import mismatch

LAYER = """#usda 1.0
def Xform "World"
{
    double3 xformOp:translate = (%r, 2, 3)
    uniform token[] xformOpOrder = ["xformOp:translate"]
}
"""


def write(path, text, binary=False):
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(text)
    if binary:
        assert layer.Export(str(path), args={"format": "usdc"})
    else:
        path.write_text(layer.ExportToString())
    return path


def test_last_bits_pass_and_a_changed_value_or_prim_fails(tmp_path):
    for binary in (False, True):
        suffix = ".usdc" if binary else ".usda"
        committed = write(tmp_path / f"committed{suffix}", LAYER % -0.8096104433943876, binary)
        assert mismatch(committed, committed) is None
        last_bit = write(tmp_path / f"last_bit{suffix}", LAYER % -0.8096104433943875, binary)
        assert mismatch(last_bit, committed) is None
        moved = write(tmp_path / f"moved{suffix}", LAYER % -0.8096105, binary)
        assert "1 numbers differ" in mismatch(moved, committed)
        renamed = write(tmp_path / f"renamed{suffix}", (LAYER % -0.8096104433943876).replace("World", "Welt"), binary)
        assert "text differs" in mismatch(renamed, committed)


def test_other_files_must_be_the_same_bytes(tmp_path):
    (tmp_path / "a.png").write_bytes(b"\x89PNG 1")
    (tmp_path / "b.png").write_bytes(b"\x89PNG 2")
    assert mismatch(tmp_path / "a.png", tmp_path / "a.png") is None
    assert "bytes differ" in mismatch(tmp_path / "a.png", tmp_path / "b.png")
