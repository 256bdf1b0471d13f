"""The bundled JSON Schemas: each a valid Draft 2020-12 schema (the package does not re-check them when it loads
them), and references between them resolve."""

import jsonschema
import pytest

from synthua_usd.core.schemas import bundled_schema_names, load_schema, schema_errors


def test_every_schema_file_is_found():
    assert set(bundled_schema_names()) >= {"classmap", "frame", "generate", "manifest", "record", "semantic_rules",
                                           "camera_rigs_report"}


@pytest.mark.parametrize("name", bundled_schema_names())
def test_every_bundled_schema_is_a_valid_schema(name):
    jsonschema.Draft202012Validator.check_schema(load_schema(name))


def test_a_broken_schema_would_be_caught():
    with pytest.raises(jsonschema.SchemaError):
        jsonschema.Draft202012Validator.check_schema({"type": "objekt"})


def test_a_reference_into_another_schema_resolves():
    # generate's randomise block is reached by file name from a $ref, as record.schema.json refers to others
    assert schema_errors({"seed": 1}, "generate", "randomise") == []
    assert schema_errors({"seed": -1}, "generate", "randomise")
