"""Hostile GeoJSON for ``synthua twin import footprints``, and building outlines of no area in OpenStreetMap extracts."""

from __future__ import annotations

import json

import pytest

from importers.hostile_corpus import GEOJSON, doc, write

SQUARE = [[-49.2712, -25.4270], [-49.2710, -25.4270], [-49.2710, -25.4268], [-49.2712, -25.4268], [-49.2712, -25.4270]]
BOWTIE = [[-49.2712, -25.4270], [-49.2710, -25.4268], [-49.2710, -25.4270], [-49.2712, -25.4268], [-49.2712, -25.4270]]
LINE = [[-49.2712, -25.4270], [-49.2711, -25.4270], [-49.2710, -25.4270], [-49.2712, -25.4270]]
SLIVER = [[-49.2712, -25.4270], [-49.2710, -25.4270], [-49.2710, -25.42699999999], [-49.2712, -25.4270]]
POINT_RING = [[-49.2712, -25.4270]] * 4
#: A hole inside SQUARE whose positions lie on one line: a courtyard of no area.
FLAT_HOLE = [[-49.27115, -25.4269], [-49.27112, -25.4269], [-49.27108, -25.4269], [-49.27115, -25.4269]]


def _feature(d: dict, **changes) -> dict:
    f = d["features"][0]
    for key, value in changes.items():
        if key == "geometry":
            f["geometry"] = value
        elif key == "coordinates":
            f["geometry"]["coordinates"] = value
        else:
            f["properties"][key] = value
    return d


def _props(d: dict, props) -> dict:
    d["features"][0]["properties"] = props
    return d


CASES = {
    "features-object": (lambda d: {**d, "features": {"a": d["features"][0]}}, ("features",)),
    "features-string": (lambda d: {**d, "features": "all"}, ("features",)),
    "feature-number": (lambda d: {**d, "features": [5]}, ("features[0]",)),
    "feature-list": (lambda d: {**d, "features": [[1, 2]]}, ("features[0]",)),
    "properties-list": (lambda d: _props(d, [14]), ("features[0]", "properties")),
    "geometry-null": (lambda d: _feature(d, geometry=None), ("features[0]", "geometry")),
    "geometry-point": (lambda d: _feature(d, geometry={"type": "Point", "coordinates": [0, 0]}),
                       ("features[0]", "Point")),
    "coordinates-1d": (lambda d: _feature(d, coordinates=[[[0], [1], [2], [0]]]), ("features[0]",)),
    "coordinates-text": (lambda d: _feature(d, coordinates=[[["a", "b"]] * 4]), ("features[0]",)),
    "coordinates-number": (lambda d: _feature(d, coordinates=5), ("features[0]",)),
    "coordinates-deep": (lambda d: _feature(d, coordinates=[[[SQUARE]]]), ("features[0]",)),
    "bow-tie": (lambda d: _feature(d, coordinates=[BOWTIE]), ("features[0]", "self-intersect")),
    "zero-area-line": (lambda d: _feature(d, coordinates=[LINE]), ("features[0]", "area")),
    "zero-area-point": (lambda d: _feature(d, coordinates=[POINT_RING]), ("features[0]", "area")),
    "sliver": (lambda d: _feature(d, coordinates=[SLIVER]), ("features[0]", "area")),
    "hole-of-zero-area": (lambda d: _feature(d, coordinates=[SQUARE, FLAT_HOLE]), ("features[0]", "hole", "area")),
    "shell-not-closed": (lambda d: _feature(d, coordinates=[SQUARE[:-1]]), ("features[0]", "not closed")),
    "hole-not-closed": (lambda d: _feature(d, coordinates=[SQUARE, FLAT_HOLE[:-1] + [[-49.27111, -25.42691]]]),
                        ("features[0]", "coordinates[1]", "not closed")),
    "hole-outside": (lambda d: _feature(d, coordinates=[SQUARE, [[x + 0.01, y] for x, y in SQUARE]]),
                     ("features[0]",)),
    "height-1e308": (lambda d: _feature(d, height=1e308), ("features[0]", "height", "1000")),
    "height-negative": (lambda d: _feature(d, height=-5), ("features[0]", "height")),
    "height-zero": (lambda d: _feature(d, height=0), ("features[0]", "height")),
    "height-1e-10": (lambda d: _feature(d, height=2.6e-10), ("features[0]", "height")),
    "min-height-just-below": (lambda d: _feature(d, min_height=13.99999), ("features[0]", "min_height")),
    "height-text": (lambda d: _feature(d, height="tall"), ("features[0]", "height")),
    "height-string-inf": (lambda d: _feature(d, height="inf"), ("features[0]", "height")),
    "height-bool": (lambda d: _feature(d, height=True), ("features[0]", "height")),
    "height-list": (lambda d: _feature(d, height=[14]), ("features[0]", "height")),
    "levels-huge": (lambda d: _props(d, {"levels": 10**6}), ("features[0]", "levels")),
    "levels-negative": (lambda d: _props(d, {"levels": -2}), ("features[0]", "levels")),
    "min-height-text": (lambda d: _feature(d, min_height="low"), ("features[0]", "min_height")),
    "min-height-huge": (lambda d: _feature(d, min_height=1e308), ("features[0]", "min_height")),
    "min-height-above": (lambda d: _feature(d, min_height=20), ("features[0]", "min_height")),
    "lonlat-out-of-range": (lambda d: _feature(d, coordinates=[[[x * 1e6, y] for x, y in SQUARE]]), ("lon/lat",)),
    "crs-string": (lambda d: {**d, "crs": "EPSG:31982"}, ("crs",)),
    "crs-name-number": (lambda d: {**d, "crs": {"type": "name", "properties": {"name": 31982}}}, ("crs",)),
    "crs-projected-huge": (lambda d: _feature({**d, "crs": {"type": "name", "properties": {"name": "EPSG:31982"}}},
                                              coordinates=[[[1e300, 0], [1e300 + 1e290, 0], [1e300, 1e290],
                                                            [1e300, 0]]]), ("features[0]",)),
    "type-missing": (lambda d: {"features": d["features"]}, ("FeatureCollection",)),
    "no-features": (lambda d: {**d, "features": []}, ("features",)),
}


@pytest.mark.parametrize("case", CASES)
def test_hostile_geojson(refuse, workdir, case):
    """Refused with --strict (without it, a height that is not a length is skipped for the next source:
    tests/importers/test_heights.py)."""
    spoil, words = CASES[case]
    path = write(workdir / "blocks.geojson", spoil(doc(GEOJSON)))
    refuse("twin", "import", "footprints", path, "--out", workdir / "out", "--strict",
           mentions=("blocks.geojson", *words))


#: Positions on one line of latitude 2 km long: no area in lon/lat, as GeoJSON's straight lines between positions
#: have none; projected to metres the parallel curves, and the ring became a sliver of some 30 m² that was imported.
LONG_LINE = [[-49.30, -25.4270], [-49.29, -25.4270], [-49.28, -25.4270], [-49.30, -25.4270]]
DIAGONAL_LINE = [[-49.30, -25.43], [-49.29, -25.42], [-49.28, -25.41], [-49.30, -25.43]]


@pytest.mark.parametrize("ring", [LONG_LINE, DIAGONAL_LINE])
@pytest.mark.parametrize("strict", [[], ["--strict"]])
def test_a_ring_of_no_area_in_lon_lat_is_refused(refuse, workdir, ring, strict):
    path = write(workdir / "blocks.geojson", _feature(doc(GEOJSON), coordinates=[ring]))
    refuse("twin", "import", "footprints", path, "--out", workdir / "out", *strict,
           mentions=("blocks.geojson", "features[0]", "area 0 in the file's coordinates"))


def _osm(path, rings: list) -> str:
    """An OpenStreetMap extract of one building way per ring of (lon, lat) positions (closed here)."""
    import osmium
    from osmium.osm.mutable import Node, Way

    writer = osmium.SimpleWriter(str(path))
    node = 0
    for k, ring in enumerate(rings):
        ids = []
        for lon, lat in ring[:-1]:
            node += 1
            writer.add_node(Node(id=node, location=(lon, lat)))
            ids.append(node)
        writer.add_way(Way(id=100 + k, nodes=ids + ids[:1], tags={"building": "yes", "height": "9"}))
    writer.close()
    return path


@pytest.mark.parametrize("ring", [LINE, LONG_LINE])
def test_an_osm_extract_whose_only_building_has_no_area_is_refused(refuse, workdir, ring):
    """ValueError in geometry/ground.py: the building was skipped, and the ground was made of nothing."""
    path = _osm(workdir / "zero_area.osm", [ring])
    refuse("twin", "import", "osm", path, "--out", workdir / "out", mentions=("zero_area.osm", "way/100", "0.01 m²"))


def test_an_osm_building_of_no_area_beside_others_is_skipped_and_reported(run_cli, tmp_path):
    path = _osm(tmp_path / "city.osm", [LONG_LINE, SQUARE])
    code, out, err = run_cli("twin", "import", "osm", path, "--out", tmp_path / "out")
    assert code == 0, err
    report = json.loads((tmp_path / "out" / "import_report.json").read_text())
    assert report["buildings"] == 1 and report["osm"]["skipped_ids"] == ["way/100"], report["osm"]
