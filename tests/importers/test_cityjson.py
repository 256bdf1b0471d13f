import json

import numpy as np
import pytest

from conftest import DATA, third_party
from synthua_usd.core.errors import InputError
from synthua_usd.importers.cityjson import import_cityjson
from synthua_usd.model.class_assignment import AssignmentRules


def test_lod2_semantic_surfaces_and_holes():
    model = import_cityjson(DATA / "valid" / "lod2_house.city.json")
    objs = {o.path: o for o in model.objects}
    house = objs["Building/house_1"]
    assert house.label == "building"
    assert sorted(p.name for p in house.parts) == ["Ground", "Roof", "Walls"]
    door = objs["Building/house_1_door"]
    assert door.label == "door" and door.attributes["cityjson_id"] == "house-1"
    road = objs["Road/road_1"]
    # A 20 x 7 m quad with a 2 x 3 m hole: earcut's triangles cover exactly the difference.
    tris = road.parts[0].points[road.parts[0].triangles]
    area = 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1).sum()
    assert area == pytest.approx(20 * 7 - 2 * 3)
    # Upward faces for roofs and roads.
    roof = next(p for p in house.parts if p.name == "Roof")
    n = np.cross(*(roof.points[roof.triangles[:, k]] - roof.points[roof.triangles[:, 0]] for k in (1, 2)))
    assert (n[:, 2] > 0).all()
    assert objs["WaterBody/water_1"].label == "unlabelled"
    assert model.report["unlabelled_types"] == {"WaterBody": 1}


def test_origin_and_crs_are_kept():
    model = import_cityjson(DATA / "valid" / "lod2_house.city.json")
    # Extent x -5..25 m, y -10..8 m, z 0..6 m above 676000, 7186000, 900: centre of x/y, lowest z.
    assert model.origin_offset_m == pytest.approx((676010.0, 7185999.0, 900.0))
    assert model.crs.endswith("/EPSG/0/31982")
    pts = np.concatenate([p.points for o in model.objects for p in o.parts])
    assert pts.min(axis=0)[2] == pytest.approx(0.0)


def test_rules_override_the_type_table(class_map):
    rules = AssignmentRules.from_document({"rules": [{"field": "type", "pattern": "^WaterBody$", "class": "grass"}]},
                                        class_map)
    model = import_cityjson(DATA / "valid" / "lod2_house.city.json", rules)
    assert {o.path: o.label for o in model.objects}["WaterBody/water_1"] == "grass"


@pytest.mark.parametrize("name,text", [
    ("cityjson_v1_0", "CityJSON version 1.0 is not supported; expected one of 1.1, 2.0"),
    ("cityjson_no_crs", "metadata.referenceSystem is missing"),
    ("cityjson_geographic_crs", "is geographic (degrees); expected a projected CRS"),
    ("cityjson_nan_vertex", "NaN is not JSON; expected finite numbers"),
    ("cityjson_bad_boundary", "CityObjects['road-1'].geometry[0].boundaries[0][0][2]: vertex index 999"),
])
def test_broken_cityjson(name, text):
    path = DATA / "invalid" / f"{name}.city.json"
    with pytest.raises(InputError) as err:
        import_cityjson(path)
    assert str(path) in str(err.value) and text in str(err.value)


@pytest.mark.slow
def test_delft():
    path = third_party("cityjson", "delft.json")
    model = import_cityjson(path)
    doc = json.loads(path.read_text())
    assert len(model.objects) == len(doc["CityObjects"]) == 570
    counts = model.label_counts()
    assert counts["building"] == 160 and counts["road"] == 143 and counts["vegetation"] == 126
    assert model.report["unlabelled_types"] == {"Bridge": 3, "GenericCityObject": 54, "WaterBody": 3}
    assert model.crs == "https://www.opengis.net/def/crs/EPSG/0/7415"
    # Independent: the origin is the centre of the decoded vertices' x/y extent and their lowest z.
    v = np.asarray(doc["vertices"], float) * doc["transform"]["scale"] + doc["transform"]["translate"]
    expected = ((v[:, 0].min() + v[:, 0].max()) / 2, (v[:, 1].min() + v[:, 1].max()) / 2, v[:, 2].min())
    assert model.origin_offset_m == pytest.approx(expected)
    pts = np.concatenate([p.points for o in model.objects for p in o.parts])
    assert np.abs(pts[:, :2]).max() < 300 and pts[:, 2].min() >= 0


def _house_doc():
    return json.loads((DATA / "valid" / "lod2_house.city.json").read_text())


def _extent(model):
    pts = np.concatenate([p.points for o in model.objects for p in o.parts])
    return pts.max(axis=0) - pts.min(axis=0)


def test_cityjson_without_crs_imports_with_crs_option(tmp_path):
    doc = _house_doc()
    del doc["metadata"]["referenceSystem"]
    path = tmp_path / "nocrs.city.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError, match="metadata.referenceSystem is missing"):
        import_cityjson(path)
    metres = import_cityjson(path, crs="EPSG:31982")
    assert metres.crs == "EPSG:31982" and metres.report["units"]["source"] == "--crs"
    assert _extent(metres) == pytest.approx([30.0, 18.0, 6.0])
    assert _extent(import_cityjson(path, units="m")) == pytest.approx([30.0, 18.0, 6.0])


def test_cityjson_in_feet_is_converted_to_metres(tmp_path):
    """A file in EPSG:2263 (US survey feet) with the same numbers is 0.3048006 times as large in metres."""
    doc = _house_doc()
    doc["metadata"]["referenceSystem"] = "https://www.opengis.net/def/crs/EPSG/0/2263"
    path = tmp_path / "feet.city.json"
    path.write_text(json.dumps(doc))
    model = import_cityjson(path)
    assert _extent(model) == pytest.approx(np.array([30.0, 18.0, 6.0]) * 1200 / 3937)
    assert model.origin_offset_m == pytest.approx(np.array([676010.0, 7185999.0, 900.0]) * 1200 / 3937)
    assert model.report["units"]["horizontal"] == "US survey foot"
