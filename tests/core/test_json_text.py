"""The one JSON encoder of every written document (issue 39): NumPy scalars become their JSON types, anything
else without a JSON type is refused naming its place, and plain documents read as ``json`` writes them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from synthua_usd.core.atomic import write_json_atomic
from synthua_usd.core.json_text import NotJsonError, dumps
from synthua_usd.dataset.manifest import document_digest


def test_numpy_scalars_become_json_values_of_the_same_value():
    document = {"in_view": np.bool_(False), "visible": np.True_, "pixels": np.int64(7), "k": np.uint16(3),
                "share": np.float32(0.25), "z": np.float64(1.5), "nested": [{"v": np.int32(-2)}]}
    back = json.loads(dumps(document))
    assert back == {"in_view": False, "visible": True, "pixels": 7, "k": 3, "share": 0.25, "z": 1.5,
                    "nested": [{"v": -2}]}
    assert type(back["in_view"]) is bool and type(back["pixels"]) is int and type(back["share"]) is float
    # Python's own encoder refuses the document: the bug class this encoder closes
    with pytest.raises(TypeError, match="not JSON serializable"):
        json.dumps(document)


@pytest.mark.parametrize("value, where, what", [
    ({"camera": {"K": np.eye(3)}}, "$.camera.K", "ndarray"),
    ({"files": [1, 2, Path("a.png")]}, r"$.files[2]", "PosixPath"),
    ([{"a": {1, 2}}], r"$[0].a", "set"),
])
def test_a_value_without_a_json_type_is_refused_by_its_place(value, where, what):
    with pytest.raises(NotJsonError) as info:
        dumps(value)
    assert str(info.value).startswith(f"{where}: a value of type {what} is not a JSON type")


def test_plain_documents_read_as_json_writes_them():
    document = {"b": [1, 2.5, None, True], "a": "ü €", "c": {"d": -0.0}}
    assert dumps(document, indent=1) == json.dumps(document, indent=1, ensure_ascii=False)
    assert dumps(document, sort_keys=True, compact=True) == json.dumps(document, sort_keys=True, separators=(",", ":"),
                                                                       ensure_ascii=False)
    assert dumps(document, sort_keys=True, ascii_only=True) == json.dumps(document, sort_keys=True)
    # a digest does not depend on whether a number came from NumPy
    assert document_digest({"n": np.int64(3), "f": np.float32(0.5)}) == document_digest({"n": 3, "f": 0.5})


def test_a_written_record_with_numpy_values_is_plain_json_and_a_refused_one_leaves_nothing(tmp_path):
    path = write_json_atomic(tmp_path / "record.json", {"qa": {"ok": np.bool_(True), "blur": np.float32(12.5)}})
    assert json.loads(path.read_text(encoding="utf-8")) == {"qa": {"ok": True, "blur": 12.5}}
    with pytest.raises(NotJsonError, match=r"^\$\.qa\.mask: a value of type ndarray"):
        write_json_atomic(tmp_path / "other.json", {"qa": {"mask": np.zeros(2)}})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["record.json"]
