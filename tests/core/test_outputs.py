"""The output table: which render var writes which files."""

import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.core.outputs import FILE_NAMES, FRAME_DOCUMENT, OUTPUT_NAMES, OUTPUTS, file_names, select_outputs


def test_every_file_has_one_key_and_one_name():
    files = [f for o in OUTPUTS for f in o.files]
    assert len({f.key for f in files}) == len({f.name for f in files}) == len(files)
    assert FRAME_DOCUMENT not in {f.name for f in files}


def test_file_names_end_with_the_frame_document():
    assert file_names() == ("rgb.exr", "rgb.png", "class.png", "semantic.png", "instance.png", "instance_preview.png",
                            "depth.exr",
                            FRAME_DOCUMENT)
    assert file_names(select_outputs(["depth"])) == ("depth.exr", FRAME_DOCUMENT)


def test_selection_keeps_table_order_and_no_names_means_all():
    assert [o.var for o in select_outputs(["depth", "rgb"])] == ["rgb", "depth"]
    assert select_outputs([]) == OUTPUTS and OUTPUT_NAMES == ("rgb", "class_id", "instance_id", "depth")


def test_unknown_var_is_refused_with_the_known_ones():
    with pytest.raises(InputError, match=r"render vars \['normals'\] are not outputs synthua writes; expected some of "
                                         r"rgb, class_id, instance_id, depth"):
        select_outputs(["rgb", "normals"])


def test_file_names_by_key_come_from_the_table():
    """FILE_NAMES is the one place a frame's file names are written: the table's files and the dataset's one-hot
    masks; a dataset image's frame folder names its files by it."""
    from synthua_usd.dataset.layout import Layout

    assert FILE_NAMES == {"rgb_exr": "rgb.exr", "rgb_png": "rgb.png", "class": "class.png", "semantic": "semantic.png",
                          "instance": "instance.png", "instance_preview": "instance_preview.png",
                          "depth": "depth.exr", "onehot": "onehot.npz"}
    assert Layout.frame_file("000001_CCTV", "class") == "frames/000001_CCTV/class.png"
