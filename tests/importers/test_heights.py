"""Building heights from OpenStreetMap-style tags: lengths with units, and the order of sources."""

import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.importers.heights import building_height, parse_length


@pytest.mark.parametrize("value, metres", [
    (12, 12.0), (12.5, 12.5), ("12", 12.0), ("12.13 m", 12.13), ("12,5", 12.5), ("12.5m", 12.5), (" 7 metres ", 7.0),
    ("40 ft", 12.192), ("40'", 12.192), ("40'6\"", 12.3444), ("1250 cm", 12.5), (".5", 0.5),
])
def test_lengths_with_units(value, metres):
    assert parse_length(value) == pytest.approx(metres)


@pytest.mark.parametrize("value", ["tall", "12;15", "~12", "12 m 3", "inf", "nan", "", True, None, [12], {"m": 1}, "12 parsecs"])
def test_what_is_no_length(value):
    assert parse_length(value) is None


def _height(tags, **kw):
    return building_height(tags, "city.osm: way/7", storey_height_m=3.0, default_height_m=6.0, field="tag ", **kw)


@pytest.mark.parametrize("tags, top, base, source", [
    ({"height": "12.13 m", "building:levels": "9"}, 12.13, 0.0, "height"),
    ({"building:levels": "4"}, 12.0, 0.0, "building:levels"),
    ({"building:levels": "4", "roof:levels": "1"}, 15.0, 0.0, "building:levels"),
    ({"building:levels": "4", "roof:height": "2,5", "roof:levels": "1"}, 14.5, 0.0, "building:levels"),
    ({"roof:height": "3", "min_height": "10"}, 13.0, 10.0, "roof:height"),
    ({"building": "yes"}, 6.0, 0.0, "default"),
    ({"min_height": "4"}, 10.0, 4.0, "default"),
    ({"building:levels": "5", "building:min_level": "2"}, 15.0, 6.0, "building:levels"),
])
def test_sources_in_order(tags, top, base, source):
    h = _height(tags)
    assert (h.top_m, h.base_m, h.source, h.ignored) == (pytest.approx(top), pytest.approx(base), source, ())


def test_unusable_values_are_skipped_and_recorded_or_refused_when_strict():
    h = _height({"height": "tall", "building:levels": "3"})
    assert (h.top_m, h.source) == (9.0, "building:levels")
    assert h.ignored == ("tag height: 'tall' is not a length; expected a number in [0.1, 1000] m (a number of metres, "
                         "or with a unit: '12.5 m', '12,5', '40 ft')",)
    assert _height({"height": "-5", "building:levels": "many"}).source == "default"
    assert _height({"height": "12", "roof:height": "steep"}, strict=True).ignored == ()  # not needed: not read
    with pytest.raises(InputError, match=r"^city.osm: way/7: tag height: 'tall' is not a length"):
        _height({"height": "tall", "building:levels": "3"}, strict=True)
    with pytest.raises(InputError, match="no height"):
        _height({"building": "yes"}, strict=True)


def test_a_min_height_above_the_top_is_dropped():
    h = _height({"height": "10", "min_height": "12"})
    assert (h.base_m, h.top_m, h.source) == (0.0, 10.0, "height") and "min_height 12 m" in h.ignored[0]
