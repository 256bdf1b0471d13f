import pytest

from conftest import DATA
from synthua_usd.core.errors import InputError, SchemaError
from synthua_usd.model.class_assignment import AssignmentRules


def test_first_match_wins_and_default(class_map):
    rules = AssignmentRules.from_document({"rules": [
        {"field": "material", "pattern": "glass", "class": "window"},
        {"field": "object", "pattern": "^build", "class": "Buildings"},
        {"field": "any", "pattern": "lamp", "class": "light_pole"},
    ]}, class_map)
    assert rules.classify({"object": "Building_01", "material": "Glass"}) == ("window", 0)
    assert rules.classify({"object": "Building_01", "material": "plaster"}) == ("building", 1)
    assert rules.classify({"object": "x", "material": "streetlamp_metal"}) == ("light_pole", 2)
    assert rules.classify({"object": "bench"}) == ("unlabelled", None)


@pytest.mark.parametrize("name,error,text", [
    ("rules_bad_regex.json", InputError, "rules[0].pattern 'road(' is not a valid regular expression"),
    ("rules_unknown_class.json", InputError, "rules[0].class 'highway' is not a class"),
    ("rules_bad_field.json", SchemaError, "rules[0].field: 'colour' is not one of"),
])
def test_bad_rules_files(class_map, name, error, text):
    with pytest.raises(error) as err:
        AssignmentRules.load(DATA / "invalid" / name, class_map)
    assert text in str(err.value) and name in str(err.value)
