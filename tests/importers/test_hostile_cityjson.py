"""Hostile CityJSON for ``synthua twin import cityjson``: every case is refused with one line naming the
file and the field, and the earlier import in --out stays as it was."""

from __future__ import annotations

import pytest

from importers.hostile_corpus import CITYJSON, doc, write


def _set(d: dict, path: tuple, value) -> dict:
    node = d
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return d


def _drop(d: dict, path: tuple) -> dict:
    node = d
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]
    return d


HOUSE = ("CityObjects", "house-1", "geometry", 0)
ROAD = ("CityObjects", "road-1", "geometry", 0)

#: case -> (spoil the valid document, words the message must contain besides the file name)
CASES = {
    "vertices-2d": (lambda d: _set(d, ("vertices",), [[0, 0], [1, 1], [2, 2]]), ("vertices[0]", "3")),
    "vertices-ragged": (lambda d: _set(d, ("vertices", 5), [1, 2]), ("vertices[5]",)),
    "vertices-text": (lambda d: _set(d, ("vertices", 2, 1), "north"), ("vertices[2]",)),
    "vertices-object": (lambda d: _set(d, ("vertices",), {"a": [0, 0, 0]}), ("vertices",)),
    "vertices-huge": (lambda d: _set(d, ("vertices", 3), [10**300, 0, 0]), ("vertices",)),
    "transform-missing": (lambda d: _drop(d, ("transform",)), ("transform",)),
    "transform-no-scale": (lambda d: _drop(d, ("transform", "scale")), ("transform.scale",)),
    "transform-no-translate": (lambda d: _drop(d, ("transform", "translate")), ("transform.translate",)),
    "transform-scale-zero": (lambda d: _set(d, ("transform", "scale"), [0, 0.001, 0.001]), ("transform.scale",)),
    "transform-scale-negative": (lambda d: _set(d, ("transform", "scale"), [0.001, -0.001, 0.001]),
                                 ("transform.scale",)),
    "transform-scale-2": (lambda d: _set(d, ("transform", "scale"), [0.001, 0.001]), ("transform.scale",)),
    "transform-scale-text": (lambda d: _set(d, ("transform", "scale"), "0.001"), ("transform.scale",)),
    "transform-translate-huge": (lambda d: _set(d, ("transform", "translate"), [1e300, 0, 0]),
                                 ("transform.translate",)),
    "transform-list": (lambda d: _set(d, ("transform",), [0.001, 0.001, 0.001]), ("transform",)),
    "cityobjects-list": (lambda d: _set(d, ("CityObjects",), [d["CityObjects"]["house-1"]]), ("CityObjects",)),
    "cityobject-number": (lambda d: _set(d, ("CityObjects", "house-1"), 5), ("house-1",)),
    "cityobject-type-list": (lambda d: _set(d, ("CityObjects", "house-1", "type"), ["Building"]), ("house-1",)),
    "geometry-object": (lambda d: _set(d, ("CityObjects", "house-1", "geometry"), {"type": "Solid"}),
                        ("house-1", "geometry")),
    "geometry-entry-number": (lambda d: _set(d, HOUSE, 7), ("house-1", "geometry[0]")),
    "geometry-type-list": (lambda d: _set(d, HOUSE + ("type",), []), ("house-1", "geometry type")),
    "geometry-type-point": (lambda d: _set(d, HOUSE + ("type",), "MultiPoint"), ("house-1", "MultiPoint")),
    "boundary-negative": (lambda d: _set(d, HOUSE + ("boundaries", 0, 0, 0, 0), -1), ("house-1", "-1")),
    "boundary-past-end": (lambda d: _set(d, HOUSE + ("boundaries", 0, 0, 0, 0), 10_000), ("house-1", "10000")),
    "boundary-float": (lambda d: _set(d, HOUSE + ("boundaries", 0, 0, 0, 0), 1.5), ("house-1", "1.5")),
    "boundary-bool": (lambda d: _set(d, HOUSE + ("boundaries", 0, 0, 0, 0), True), ("house-1", "True")),
    "boundary-too-shallow": (lambda d: _set(d, ROAD + ("boundaries",), [0, 1, 2]), ("road-1", "boundaries")),
    "boundary-too-deep": (lambda d: _set(d, ROAD + ("boundaries",), [[[[[12, 13, 14]]]]]), ("road-1", "boundaries")),
    "boundary-object": (lambda d: _set(d, ROAD + ("boundaries",), {"a": 1}), ("road-1", "boundaries")),
    "semantics-value-negative": (lambda d: _set(d, HOUSE + ("semantics", "values", 0, 0), -1),
                                 ("house-1", "semantics")),
    "semantics-value-past-end": (lambda d: _set(d, HOUSE + ("semantics", "values", 0, 0), 99),
                                 ("house-1", "semantics")),
    "semantics-value-text": (lambda d: _set(d, HOUSE + ("semantics", "values", 0, 0), "roof"),
                             ("house-1", "semantics")),
    "semantics-surfaces-object": (lambda d: _set(d, HOUSE + ("semantics", "surfaces"), {"type": "RoofSurface"}),
                                  ("house-1", "semantics")),
    "semantics-surface-number": (lambda d: _set(d, HOUSE + ("semantics", "surfaces", 0), 3),
                                 ("house-1", "semantics")),
    "semantics-values-shorter-than-the-shell": (lambda d: _set(d, HOUSE + ("semantics", "values", 0),
                                                               d["CityObjects"]["house-1"]["geometry"][0]["semantics"]
                                                               ["values"][0][:2]), ("house-1", "semantics.values[0]")),
    "semantics-values-shorter-than-the-shells": (lambda d: _set(d, HOUSE + ("semantics", "values"), []),
                                                 ("house-1", "semantics.values")),
    "semantics-values-longer-than-the-shell": (lambda d: _set(d, HOUSE + ("semantics", "values", 0),
                                                              d["CityObjects"]["house-1"]["geometry"][0]["semantics"]
                                                              ["values"][0] + [0]), ("house-1", "semantics.values[0]")),
        "metadata-list": (lambda d: _set(d, ("metadata",), ["EPSG:7415"]), ("metadata",)),
    "crs-number": (lambda d: _set(d, ("metadata", "referenceSystem"), 7415), ("referenceSystem",)),
    "crs-geographic": (lambda d: _set(d, ("metadata", "referenceSystem"),
                                      "https://www.opengis.net/def/crs/EPSG/0/4326"), ("geographic",)),
    "version-number": (lambda d: _set(d, ("version",), 2.0), ("version",)),
    "no-cityobjects": (lambda d: _set(d, ("CityObjects",), {}), ("CityObjects",)),
    "no-geometry-at-all": (lambda d: _set(d, ("CityObjects",), {"a": {"type": "Building"}}), ("geometry",)),
}


@pytest.mark.parametrize("case", CASES)
def test_hostile_cityjson(refuse, workdir, case):
    spoil, words = CASES[case]
    path = write(workdir / "city.json", spoil(doc(CITYJSON)))
    refuse("twin", "import", "cityjson", path, "--out", workdir / "out", mentions=("city.json", *words))


@pytest.mark.parametrize("lod", ["9", "3", "x", "2.22"])
def test_lod_nobody_has_is_refused_listing_present(refuse, workdir, lod):
    path = write(workdir / "city.json", doc(CITYJSON))
    message = refuse("twin", "import", "cityjson", path, "--lod", lod, "--out", workdir / "out",
                     mentions=("--lod", "1", "2.2"))
    assert lod in message


def test_present_lod_is_imported(run_cli, workdir):
    path = write(workdir / "city.json", doc(CITYJSON))
    code, out, err = run_cli("twin", "import", "cityjson", path, "--lod", "2.2", "--out", workdir / "new")
    assert code == 0, err
