import numpy as np
import pytest

from conftest import DATA
from synthua_usd.core.errors import InputError
from synthua_usd.importers.footprints import import_footprints


def test_extrudes_heights_and_levels():
    model = import_footprints(DATA / "valid" / "footprints.geojson")
    church, house = model.objects
    assert (church.path, church.label, house.path) == ("Buildings/Igreja", "building", "Buildings/Casa")
    assert [p.name for p in church.parts] == ["Walls", "Roof"]
    assert church.parts[0].attributes == {"surface": "wall"} and church.parts[1].attributes == {"surface": "roof"}
    assert church.parts[1].points[:, 2] == pytest.approx(14.0)  # height 14 m
    assert house.parts[1].points[:, 2] == pytest.approx(6.0)    # 2 levels x 3 m
    # 0.0002 degrees of longitude at 25.4 S is ~20.1 m; of latitude ~22.1 m.
    extent = np.ptp(church.parts[0].points, axis=0)
    assert extent[0] == pytest.approx(0.0002 * 111320 * np.cos(np.radians(25.427)), rel=0.01)
    assert extent[1] == pytest.approx(0.0002 * 110780, rel=0.01)
    assert model.crs.startswith("+proj=tmerc")


@pytest.mark.parametrize("name,text", [
    ("footprint_point", "features[1] (Casa): geometry type 'Point' is not a footprint; expected Polygon or MultiPolygon"),
    ("footprint_no_height", "features[1] (Casa): no height; expected a 'height' (m), 'building:levels' or "
                            "'roof:height' property (without --strict, --default-height-m is used)"),
    ("footprint_nan", "NaN is not JSON; expected finite numbers (NaN and Infinity are not allowed)"),
    ("footprint_empty", "the FeatureCollection has no features"),
])
def test_broken_footprints(name, text):
    path = DATA / "invalid" / f"{name}.geojson"
    with pytest.raises(InputError) as err:
        import_footprints(path, strict=True)
    assert str(err.value) == f"{path}: {text}"


def test_a_footprint_without_a_height_takes_the_default_and_says_so():
    """One building without a height does not refuse the import: it takes --default-height-m, and the report
    gives every building's source and one finding naming the defaulted ones."""
    model = import_footprints(DATA / "invalid" / "footprint_no_height.geojson", default_height_m=7.5)
    church, house = model.objects
    assert house.parts[1].points[:, 2] == pytest.approx(7.5) and church.parts[1].points[:, 2] == pytest.approx(14.0)
    heights = model.report["heights"]
    assert heights["sources"] == {"height": 1, "building:levels": 0, "roof:height": 0, "default": 1}
    assert heights["buildings"]["Buildings/Casa"] == {"height_m": 7.5, "min_height_m": 0.0, "height_source": "default"}
    assert (church.attributes["height_source"], house.attributes["height_source"]) == ("height", "default")
    (finding,) = model.report["findings"]
    assert finding["rule"] == "building-height" and "1 of 2 buildings (e.g. Buildings/Casa)" in finding["message"]
