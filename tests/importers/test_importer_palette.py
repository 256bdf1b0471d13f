"""The importers take their materials from the one palette (synthua_usd/model/materials.py): every material key a
CityJSON, footprint or point-cloud import uses is a palette key with the palette's values, and each class
gets the palette's material for it. Real third-party files import as before (counts from docs/twins.md)."""

from __future__ import annotations

import pytest

from conftest import DATA, third_party
from synthua_usd.importers.cityjson import import_cityjson
from synthua_usd.importers.footprints import import_footprints
from synthua_usd.importers.pointcloud import import_pointcloud
from synthua_usd.model.materials import PALETTE, class_material


def _check_palette(model) -> None:
    assert model.materials, "an import without materials"
    for key, material in model.materials.items():
        assert PALETTE.get(key) == material, key
    used = {p.material for o in model.objects for p in o.parts}
    assert used == set(model.materials)


def test_cityjson_materials_are_palette_entries():
    model = import_cityjson(DATA / "valid" / "lod2_house.city.json")
    _check_palette(model)
    roofs = [p for o in model.objects if o.label == "building" for p in o.parts if p.name == "Roof"]
    assert roofs and all(p.material == class_material("roof").key for p in roofs)
    doors = [p for o in model.objects if o.label == "door" for p in o.parts]
    assert doors and all(p.material == class_material("door").key for p in doors)


def test_footprint_materials_are_palette_entries():
    model = import_footprints(DATA / "valid" / "footprints.geojson")
    _check_palette(model)
    assert set(model.materials) == {class_material("building").key, class_material("roof").key}


def test_pointcloud_materials_are_palette_entries():
    model = import_pointcloud(third_party("las", "simple.las"), units="m")
    _check_palette(model)
    # Its 789 unclassified points, scattered over 3 x 5 km, fit no surface: reported, not triangulated.
    assert {o.label for o in model.objects} == {"road"}
    assert [len(o.parts[0].triangles) for o in model.objects] == [532]
    assert model.report["segmentation"]["unfit_points"] == 789


@pytest.mark.slow
def test_delft_imports_as_before():
    model = import_cityjson(third_party("cityjson", "delft.json"))
    _check_palette(model)
    assert len(model.objects) == 570 and model.triangle_count() == 36271
    assert model.label_counts() == {"building": 160, "grass": 81, "road": 143, "unlabelled": 60, "vegetation": 126}
    assert model.report["lods_present"] == ["1"]
