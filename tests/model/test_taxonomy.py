import json

import numpy as np
import pytest

from conftest import DATA, REPO
from synthua_usd.core.errors import InputError, SchemaError
from synthua_usd.model.taxonomy import ClassMap

# Verbatim from the paper's Table 1/2 (../shared/reference/paper-facts.md).
PAPER_CLASSES = ["Railings", "Buildings", "People", "Windows", "Vegetation", "Cars", "Furniture", "Chairs",
                 "Mechanical wheelchair", "Umbrella", "Street Road", "Luminaires", "Crutch", "Tables", "Wheelchair",
                 "Sidewalk", "Cover", "Doors", "Walker", "Smart Cane", "Murals", "Wooden Cane", "Bicycles",
                 "Animals", "Orthopedic Cane", "Tripod Cane", "Road", "Tents", "Grass", "Stands", "Motorcycle",
                 "Senialetics", "Light Poles", "Buses"]

# Cityscapes' own colours (cityscapesScripts labels.py) for the classes that exist there.
CITYSCAPES = {"road": (128, 64, 128), "sidewalk": (244, 35, 232), "building": (70, 70, 70),
              "light_pole": (153, 153, 153), "signage": (220, 220, 0), "vegetation": (107, 142, 35),
              "grass": (152, 251, 152), "person": (220, 20, 60), "car": (0, 0, 142), "bus": (0, 60, 100),
              "motorcycle": (0, 0, 230), "bicycle": (119, 11, 32), "railing": (180, 165, 180)}


def test_bundled_map_has_37_classes_with_void_zero(class_map):
    assert len(class_map.classes) == 37
    assert [c.id for c in class_map.classes] == list(range(37))
    void = class_map.by_id(0)
    assert (void.name, void.color, void.isthing) == ("unlabelled", (0, 0, 0), False)


def test_every_paper_class_resolves_to_a_distinct_class(class_map):
    resolved = [class_map.resolve(name) for name in PAPER_CLASSES]
    assert all(resolved), [n for n, c in zip(PAPER_CLASSES, resolved) if c is None]
    assert len({c.id for c in resolved}) == 34
    assert class_map.resolve("Senialetics").name == "signage"
    # The two classes the issue adds beyond the paper's table.
    assert class_map.resolve("curb_ramp").group == "accessibility"
    assert class_map.resolve("crosswalk") is not None


def test_eight_mobility_aid_classes_are_accessibility_things(class_map):
    aids = ["Mechanical wheelchair", "Wheelchair", "Crutch", "Walker", "Smart Cane", "Wooden Cane",
            "Orthopedic Cane", "Tripod Cane"]
    for name in aids:
        cls = class_map.resolve(name)
        assert cls.group == "accessibility" and cls.isthing, name


@pytest.mark.parametrize("name,color", sorted(CITYSCAPES.items()))
def test_cityscapes_colours_reused(class_map, name, color):
    assert class_map.resolve(name).color == color


def test_palette_maps_ids_to_colours(class_map):
    lut = class_map.palette()
    assert lut.shape == (256, 3) and lut.dtype == np.uint8
    for c in class_map.classes:
        assert tuple(lut[c.id]) == c.color
    assert not lut[37:].any()


def test_resolve_is_case_insensitive_for_aliases_only_where_unique(class_map):
    assert class_map.resolve("BUS").name == "bus"
    assert class_map.resolve("no such class") is None


def test_load_rejects_schema_violation_naming_file_and_field():
    path = DATA / "invalid" / "schema_color_out_of_range.json"
    with pytest.raises(SchemaError) as err:
        ClassMap.load(path)
    assert str(path) in str(err.value) and "classes[1].color" in str(err.value)


def test_load_rejects_rule_errors_but_not_warnings():
    with pytest.raises(InputError, match="id 1 is already used"):
        ClassMap.load(DATA / "invalid" / "rule_duplicate_id.json")
    # Close colours are a warning: the map is usable.
    assert len(ClassMap.load(DATA / "invalid" / "rule_close_colors.json").classes) == 3


def test_load_rejects_malformed_json():
    with pytest.raises(InputError, match="not valid JSON"):
        ClassMap.load(DATA / "invalid" / "not_json.json")


def test_bundled_file_is_the_one_in_schemas_folder(class_map):
    doc = json.loads((REPO / "schemas" / "classmap.json").read_text())
    assert [c["name"] for c in doc["classes"]] == [c.name for c in class_map.classes]
