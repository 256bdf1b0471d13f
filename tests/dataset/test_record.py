"""The typed records of a dataset: their keys are the schema's, every record a run writes validates (images of a
plain and of a randomised dataset; the sequence frames are checked in tests/pipeline/test_sequences.py), and a
record that does not is named with its field."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from synthua_usd.core.errors import SchemaError
from synthua_usd.core.schemas import load_schema, schema_problem
from synthua_usd.dataset.record import (COMPOSITE, IMAGE, SEQUENCE_FRAME, CompositeEntry, CompositeRecord, FileEntry,
                                        ImageRecord, InstanceEntry, PanopticSegment, PhotoCameraEntry, QAResult,
                                        RecordCamera, RecordRender, SequenceFrameRecord, check_record, image_kind,
                                        record_problem)


def _keys(typed) -> set[str]:
    return set(typed.__required_keys__) | set(typed.__optional_keys__)


@pytest.mark.parametrize("typed, definition", [
    (ImageRecord, IMAGE), (SequenceFrameRecord, SEQUENCE_FRAME), (RecordCamera, "camera"), (RecordRender, "render"),
    (InstanceEntry, "instance"), (PanopticSegment, "panoptic_segment"), (QAResult, "qa"),
    (CompositeRecord, COMPOSITE), (PhotoCameraEntry, "photo_camera"), (CompositeEntry, "composite"),
])
def test_typed_keys_are_the_schema_properties(typed, definition):
    assert _keys(typed) == set(load_schema("record")["$defs"][definition]["properties"])


def test_file_entries_are_the_manifest_schema_ones():
    assert _keys(FileEntry) == set(load_schema("manifest")["$defs"]["file"]["properties"])


def _records(root: Path) -> list[dict]:
    paths = sorted((root / "records").glob("*.json"))
    assert paths
    return [json.loads(p.read_text(encoding="utf-8")) for p in paths]


@pytest.mark.parametrize("dataset", ["generated", "generated_random"])
def test_every_record_of_a_dataset_validates(dataset, request):
    records = _records(request.getfixturevalue(dataset))
    for record in records:
        assert record_problem(record, IMAGE) is None, record["name"]
        assert schema_problem(record, "record") is None, record["name"]  # the schema as a whole takes it too
        assert record_problem(record, SEQUENCE_FRAME) is not None
    if dataset == "generated_random":
        assert all("randomisation" in r for r in records)


def test_a_bad_record_is_named_with_its_field():
    with pytest.raises(SchemaError, match=r"^records/x\.json: \(document\): 'camera' is a required property; expected "
                                          r"a document matching \$defs/image of record\.schema\.json"):
        check_record({"id": 1}, IMAGE, "records/x.json")


def test_a_wrong_field_is_named(generated):
    record = _records(generated)[0]
    record["qa"]["verdict"] = "maybe"
    assert record_problem(record, IMAGE).startswith("qa.verdict: 'maybe' is not one of")
    record = _records(generated)[0]
    del record["instances"][0]["segmentation"]
    assert record_problem(record, IMAGE).startswith("instances[0]: 'segmentation' is a required property")


def test_a_record_is_a_composite_when_it_says_so(generated):
    record = _records(generated)[0]
    assert image_kind(record) == IMAGE
    assert image_kind({**record, "composite": {}}) == COMPOSITE
    # the schema as a whole sends a record with 'composite' to $defs/composite_image, which has no render
    problem = schema_problem({**record, "composite": {}}, "record")
    assert "not a key of the document" in problem and problem.split(":")[0] in ("render", "time_code", "layer_stack")
