"""OpenStreetMap extracts (.osm, .osm.pbf) written by pyosmium itself: buildings with and without heights,
a multipolygon with a hole, an outline with a part, a way cut at the extract's edge, a bow-tie."""

import json

import numpy as np
import pytest
import trimesh

from synthua_usd.core.errors import InputError
from synthua_usd.importers.osm import import_osm

LON0, LAT0 = 11.0, 48.0
#: Metres per degree near (11 E, 48 N): longitude 111,320 x cos(48 deg) (WGS84 ellipsoid: 74,625), latitude 111,200.
M_PER_DEG = (74_625.0, 111_200.0)


def _square(x0, y0, size):
    """Corner (lon, lat) of an axis-aligned square ``size`` metres wide, ``x0``, ``y0`` metres from (LON0, LAT0)."""
    return [(LON0 + (x0 + dx) / M_PER_DEG[0], LAT0 + (y0 + dy) / M_PER_DEG[1])
            for dx, dy in ((0, 0), (size, 0), (size, size), (0, size))]


def write_city(path):
    """The extract of the module docstring; returns ``path``."""
    import osmium
    from osmium.osm.mutable import Node, Relation, Way

    nodes, ways, rels = [], [], []

    def ring(corners):
        ids = []
        for lon, lat in corners:
            nodes.append(Node(id=len(nodes) + 1, location=(lon, lat)))
            ids.append(len(nodes))
        return ids + ids[:1]

    ways.append(Way(id=10, nodes=ring(_square(0, 0, 10)), tags={"building": "yes", "height": "12.13 m"}))
    ways.append(Way(id=11, nodes=ring(_square(20, 0, 10)), tags={"building": "apartments", "building:levels": "4"}))
    ways.append(Way(id=12, nodes=ring(_square(40, 0, 10)), tags={"building": "yes", "name": "Kiosk"}))
    ways.append(Way(id=13, nodes=ring(_square(60, 0, 10)), tags={"building": "yes", "height": "12,5"}))
    ways.append(Way(id=21, nodes=ring(_square(0, 30, 20))))
    ways.append(Way(id=22, nodes=ring(_square(5, 35, 10))))
    rels.append(Relation(id=20, members=[("w", 21, "outer"), ("w", 22, "inner")],
                         tags={"type": "multipolygon", "building": "yes", "height": "40 ft"}))
    ways.append(Way(id=30, nodes=ring(_square(40, 30, 20)), tags={"building": "yes", "height": "9"}))
    ways.append(Way(id=31, nodes=ring(_square(45, 35, 10)), tags={"building:part": "yes", "height": "20"}))
    ways.append(Way(id=40, nodes=ring(_square(80, 0, 10))[:3], tags={"building": "yes"}))  # cut at the edge
    a, b, c, d = _square(80, 30, 10)
    ways.append(Way(id=50, nodes=ring([a, c, b, d]), tags={"building": "yes", "height": "6"}))  # a bow-tie
    ways.append(Way(id=60, nodes=ring(_square(0, 60, 90)), tags={"highway": "pedestrian", "area": "yes"}))
    writer = osmium.SimpleWriter(str(path))
    for n in nodes:
        writer.add_node(n)
    for w in ways:
        writer.add_way(w)
    for r in rels:
        writer.add_relation(r)
    writer.close()
    return path


@pytest.fixture(scope="module")
def city(tmp_path_factory):
    folder = tmp_path_factory.mktemp("osm")
    return {fmt: import_osm(write_city(folder / f"city.{fmt}")) for fmt in ("osm", "osm.pbf")}


def test_every_building_gets_a_height_and_its_source(city):
    model = city["osm.pbf"]
    heights = model.report["heights"]["buildings"]
    by_id = {o.attributes["osm_id"]: o for o in model.objects}
    assert sorted(by_id) == ["relation/20", "way/10", "way/11", "way/12", "way/13", "way/31", "way/50"]
    expected = {"way/10": (12.13, "height"), "way/11": (12.0, "building:levels"), "way/12": (6.0, "default"),
                "way/13": (12.5, "height"), "relation/20": (12.192, "height"), "way/31": (20.0, "height"),
                "way/50": (6.0, "height")}
    for osm_id, (top, source) in expected.items():
        obj = by_id[osm_id]
        assert heights[obj.path]["height_source"] == source and obj.attributes["height_source"] == source
        roof = next(p for p in obj.parts if p.name.startswith("Roof"))
        assert roof.points[:, 2] == pytest.approx(top, abs=1e-9)
    assert model.report["heights"]["sources"] == {"height": 5, "building:levels": 1, "roof:height": 0, "default": 1}
    assert by_id["way/12"].path == "Buildings/Kiosk"


def test_projected_to_local_metres(city):
    model = city["osm"]
    assert model.crs.startswith("+proj=tmerc") and model.report["projection"]["to"] == model.crs
    walls = next(o for o in model.objects if o.attributes["osm_id"] == "way/10").parts[0].points
    assert np.ptp(walls[:, 0]) == pytest.approx(10.0, rel=0.005) and np.ptp(walls[:, 1]) == pytest.approx(10.0, rel=0.005)
    ring = next(o for o in model.objects if o.attributes["osm_id"] == "relation/20")
    mesh = trimesh.Trimesh(*(lambda p: (p.points, p.triangles))(next(p for p in ring.parts if p.name == "Roof")))
    assert mesh.area == pytest.approx(20 * 20 - 10 * 10, rel=0.01)  # the hole is kept


def test_outlines_with_parts_cut_ways_and_bow_ties_are_reported(city):
    osm = city["osm"].report["osm"]
    assert osm["outlines_replaced_by_parts"] == 1 and osm["not_assembled_ids"] == ["way/40"]
    assert osm["repaired_ids"] == ["way/50"] and osm["skipped"] == 0
    rules = [(f["rule"], f["message"].split(" (e.g.")[0]) for f in city["osm"].report["findings"]]
    assert [r for r, _ in rules] == ["osm-building", "osm-building", "building-height"]


def test_xml_and_pbf_agree(city):
    xml, pbf = city["osm"], city["osm.pbf"]
    assert [o.path for o in xml.objects] == [o.path for o in pbf.objects]
    assert all(np.array_equal(a.parts[0].points, b.parts[0].points) for a, b in zip(xml.objects, pbf.objects))


def test_strict_refuses_what_would_be_guessed_or_repaired(tmp_path):
    path = write_city(tmp_path / "city.osm")
    with pytest.raises(InputError, match=r"city.osm: way/50: the footprint self-intersects"):
        import_osm(path, strict=True)


@pytest.mark.parametrize("name, content, words", [
    ("broken.osm", b"<osm><node id=", "cannot be read as OpenStreetMap data"),
    ("broken.osm.pbf", b"\x00\x00\xff\xffnonsense", "cannot be read as OpenStreetMap data"),
    ("city.txt", b"<osm/>", "expected an OpenStreetMap extract"),
    ("empty.osm", b"<?xml version='1.0'?><osm version='0.6'></osm>", "no building areas"),
])
def test_unreadable_extracts_are_refused_in_one_line(tmp_path, name, content, words):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(InputError) as err:
        import_osm(path)
    assert str(err.value).startswith(str(path)) and words in str(err.value) and "\n" not in str(err.value)


def test_cli_imports_every_building_with_its_source(tmp_path, run_cli):
    path = write_city(tmp_path / "city.osm.pbf")
    code, out, err = run_cli("twin", "import", "osm", path, "--out", tmp_path / "out", "--default-height-m", "7")
    assert code == 0, err
    report = json.loads((tmp_path / "out" / "import_report.json").read_text())
    assert len(report["heights"]["buildings"]) == report["objects"] == 7
    assert report["heights"]["sources"]["default"] == 1 and report["heights"]["default_height_m"] == 7.0
    assert report["crs"].startswith("+proj=tmerc")
    code, _, err = run_cli("twin", "import", "osm", path, "--out", tmp_path / "strict", "--strict")
    assert code == 2 and err.count("\n") == 1 and "way/50" in err and not (tmp_path / "strict").exists()
