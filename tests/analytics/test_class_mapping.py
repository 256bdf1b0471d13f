"""--map options between a test set's classes and a model's: parsing, the defaults, and one-line refusals."""

from __future__ import annotations

import pytest

from synthua_usd.analytics.class_mapping import build_mapping, parse_map_options
from synthua_usd.core.errors import InputError

MODEL = ("person", "manual_wheelchair", "electric_wheelchair", "walker")


def test_explicit_mapping():
    m = build_mapping(["wheelchair=manual_wheelchair, electric_wheelchair", "person=person"],
                      ("person", "wheelchair", "car"), MODEL)
    assert m.pairs == (("person", ("person",)), ("wheelchair", ("manual_wheelchair", "electric_wheelchair")))
    assert m.test_class_of() == {"person": "person", "manual_wheelchair": "wheelchair",
                                 "electric_wheelchair": "wheelchair"}
    assert m.text() == "--map person=person --map wheelchair=manual_wheelchair,electric_wheelchair"


def test_default_mapping_same_names_and_wheelchair_alias():
    m = build_mapping([], ("wheelchair", "person", "bicycle"), MODEL)
    assert m.document() == {"wheelchair": ["manual_wheelchair", "electric_wheelchair"], "person": ["person"]}
    only_manual = build_mapping([], ("wheelchair",), ("person", "manual_wheelchair"))
    assert only_manual.document() == {"wheelchair": ["manual_wheelchair"]}


@pytest.mark.parametrize("options, found", [
    (["wheelchair"], "expected TEST_CLASS=MODEL_CLASS"),
    (["wheelchair=,"], "expected TEST_CLASS=MODEL_CLASS"),
    (["bus=person"], "'bus' is not a class of the test set"),
    (["person=pedestrian"], "pedestrian: not a class of the model"),
    (["person=person", "person=walker"], "mapped twice"),
    (["person=walker", "wheelchair=walker"], "mapped to both"),
])
def test_refusals(options, found):
    with pytest.raises(InputError) as info:
        build_mapping(options, ("person", "wheelchair"), MODEL)
    assert found in str(info.value) and "\n" not in str(info.value)


def test_nothing_in_common_is_refused():
    with pytest.raises(InputError, match="share no name"):
        build_mapping([], ("pedestrian", "rider"), MODEL)


def test_control_characters_do_not_split_the_line():
    with pytest.raises(InputError) as info:
        parse_map_options(["a\nb"])
    assert "\n" not in str(info.value)
