import re
import numpy as np
import pytest
import trimesh

from conftest import third_party
from las_files import write_las
from synthua_usd.core.errors import InputError
from synthua_usd.importers.pointcloud import import_pointcloud
from synthua_usd.importers.segmentation import fit_plane


def street_corner(rng, n_ground=3000, n_wall=2000, noise=0.002):
    """A 20 x 20 m ground at z = 100 (tilted 2 %) and a façade x = 510 m, 8 m tall; millimetre noise."""
    g = np.column_stack([rng.uniform(490, 510, n_ground), rng.uniform(0, 20, n_ground), np.zeros(n_ground)])
    g[:, 2] = 100.0 + 0.02 * (g[:, 0] - 490) + rng.normal(0, noise, n_ground)
    w = np.column_stack([510.0 + rng.normal(0, noise, n_wall), rng.uniform(0, 20, n_wall), rng.uniform(100.5, 108, n_wall)])
    return g, w


@pytest.fixture(scope="module")
def corner(tmp_path_factory):
    rng = np.random.default_rng(7)
    g, w = street_corner(rng)
    path = write_las(tmp_path_factory.mktemp("las") / "corner.las", np.concatenate([g, w]))
    return path, g, w, import_pointcloud(path, max_deviation_m=0.005, plane_threshold_m=0.01)


def test_ransac_finds_ground_and_facade(corner):
    _, g, w, model = corner
    segs = {s["name"]: s for s in model.report["segments"]}
    assert {"Ground_01", "Facade_01"} <= set(segs)
    assert segs["Ground_01"]["label"] == "road" and segs["Facade_01"]["label"] == "building"
    assert segs["Ground_01"]["points"] == pytest.approx(len(g), rel=0.01)
    assert segs["Facade_01"]["points"] == pytest.approx(len(w), rel=0.02)


def test_least_squares_plane_matches_an_independent_fit():
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(0, 10, 500), rng.uniform(0, 10, 500), np.zeros(500)])
    pts[:, 2] = 0.1 * pts[:, 0] - 0.05 * pts[:, 1] + 2.0 + rng.normal(0, 0.001, 500)
    normal, d = fit_plane(pts)
    # Ordinary least squares z = a x + b y + c, then n ~ (-a, -b, 1).
    (a, b, c), *_ = np.linalg.lstsq(np.column_stack([pts[:, 0], pts[:, 1], np.ones(500)]), pts[:, 2], rcond=None)
    expected = np.array([-a, -b, 1.0]) / np.linalg.norm([-a, -b, 1.0])
    assert normal == pytest.approx(expected, abs=1e-4)
    assert -d / normal[2] == pytest.approx(c, abs=1e-3)


def test_simplification_stays_within_the_deviation_and_is_measured(corner):
    _, g, w, model = corner
    for seg, obj in zip(model.report["segments"], model.objects):
        assert seg["simplification_deviation_m"] <= 0.005
        assert seg["faces"] < seg["faces_reconstructed"] / 5  # planes and smoothed ground collapse
    # Independent check with trimesh: distance from the input points to the simplified meshes (local frame).
    offset = np.array(model.origin_offset_m)
    ground = model.objects[0].parts[0]
    mesh = trimesh.Trimesh(ground.points, ground.triangles, process=False)
    _, dist, _ = trimesh.proximity.closest_point(mesh, g - offset)
    seg = model.report["segments"][0]
    # The ground segment also holds the wall's lowest centimetres (within the ground band): compare the median.
    assert np.median(dist) == pytest.approx(seg["residual_p50_m"], abs=5e-4)
    assert np.percentile(dist, 99) < 0.01  # 2 mm noise


def test_las_classification_is_used(tmp_path):
    rng = np.random.default_rng(1)
    g, w = street_corner(rng, 800, 600)
    classes = np.concatenate([np.full(len(g), 2, np.uint8), np.full(len(w), 6, np.uint8)])
    model = import_pointcloud(write_las(tmp_path / "c.las", np.concatenate([g, w]), classes))
    assert model.label_counts() == {"building": 1, "road": 1}
    assert {s["source"] for s in model.report["segments"]} == {"las:2", "las:6"}


@pytest.mark.slow
def test_third_party_las_and_laz():
    flat = import_pointcloud(third_party("las", "plane.laz"))
    big = max(flat.report["segments"], key=lambda s: s["points"])
    assert big["label"] == "road" and big["simplification_deviation_m"] <= 0.005
    assert big["faces"] < big["faces_reconstructed"]
    simple = import_pointcloud(third_party("las", "simple.las"), units="m")  # the file states no CRS
    assert any(s["source"] == "las:2" and s["label"] == "road" for s in simple.report["segments"])
    assert all(s["simplification_deviation_m"] <= 0.005 for s in simple.report["segments"])


def test_bad_point_clouds(tmp_path):
    with pytest.raises(InputError, match="unsupported point cloud format '.xyz'"):
        import_pointcloud(tmp_path / "a.xyz")
    ply = tmp_path / "nan.ply"
    trimesh.PointCloud(np.array([[0, 0, 0], [1, np.nan, 0], [0, 1, 0]], float)).export(ply)
    with pytest.raises(InputError, match="1 points have NaN or infinite coordinates"):
        import_pointcloud(ply)
    with pytest.raises(InputError, match=re.escape("max_deviation_m: 0; expected a number in [1e-05, 10] m")):
        import_pointcloud(ply, max_deviation_m=0)
    empty = write_las(tmp_path / "empty.las", np.zeros((0, 3)))
    with pytest.raises(InputError, match="has no points"):
        import_pointcloud(empty)
    broken = tmp_path / "broken.las"
    broken.write_bytes(b"LASF" + b"\x00" * 20)
    with pytest.raises(InputError, match="cannot read as LAS/LAZ"):
        import_pointcloud(broken)


# --- units -----------------------------------------------------------------------------------------------------

US_FT = 1200 / 3937


def box_cloud(rng, size_m=10.0, n=3000):
    """A flat 10 x 10 m ground plus a 4 m wall (metres), for unit tests."""
    g = np.column_stack([rng.uniform(0, size_m, n), rng.uniform(0, size_m, n), rng.normal(0, 0.001, n)])
    w = np.column_stack([np.full(n // 2, size_m) + rng.normal(0, 0.001, n // 2), rng.uniform(0, size_m, n // 2),
                         rng.uniform(0.5, 4, n // 2)])
    return np.concatenate([g, w]) + [300000.0, 60000.0, 20.0]


def extent_m(model):
    pts = np.concatenate([p.points for o in model.objects for p in o.parts])
    return pts.max(axis=0) - pts.min(axis=0)


@pytest.mark.parametrize("how", ["epsg-geokeys", "user-defined-geokeys", "wkt-compound"])
def test_las_in_us_survey_feet_imports_at_true_size(tmp_path, how):
    rng = np.random.default_rng(5)
    metres = box_cloud(rng)
    feet = metres / US_FT
    if how == "epsg-geokeys":  # NAD83 / New York Long Island (ftUS)
        path = write_las(tmp_path / "ft.las", feet, crs="EPSG:2263")
    elif how == "user-defined-geokeys":  # GTModelType projected, user-defined CRS, ProjLinearUnits 9003
        path = write_las(tmp_path / "ft.las", feet, geokeys={1024: 1, 3072: 32767, 3076: 9003})
    else:  # WKT of a compound CRS: NAD83(2011) / Washington South (ftUS) + NAVD88 height (ftUS)
        path = write_las(tmp_path / "ft.las", feet, crs="EPSG:6599+6360", wkt=True)
    model = import_pointcloud(path, max_deviation_m=0.005, plane_threshold_m=0.01)
    assert extent_m(model) == pytest.approx([10.0, 10.0, 4.0], abs=0.05)
    units = model.report["units"]
    assert units["horizontal"] == "US survey foot" and units["horizontal_m_per_unit"] == pytest.approx(US_FT)
    assert units["vertical_m_per_unit"] == pytest.approx(US_FT)
    # Thresholds are metres: the 1 cm plane threshold holds the 1 mm-noise ground in one plane.
    ground = max(model.report["segments"], key=lambda s: s["points"])
    assert ground["points"] >= 2900


def test_vertical_unit_from_its_own_key(tmp_path):
    """Horizontal metres, vertical US survey feet (VerticalUnitsGeoKey 4099 = 9003)."""
    rng = np.random.default_rng(6)
    pts = box_cloud(rng)
    pts[:, 2] /= US_FT
    model = import_pointcloud(write_las(tmp_path / "v.las", pts, geokeys={1024: 1, 3072: 32767, 3076: 9001,
                                                                         4099: 9003}))
    assert extent_m(model) == pytest.approx([10.0, 10.0, 4.0], abs=0.05)
    assert model.report["units"]["vertical"] == "US survey foot"


def test_unknown_unit_is_refused_unless_given(tmp_path):
    path = write_las(tmp_path / "nocrs.las", box_cloud(np.random.default_rng(2)), crs=None)
    with pytest.raises(InputError, match=r"nocrs.las: the unit of the coordinates cannot be determined \(the file "
                                         r"states no CRS\); expected a CRS in the file, or --crs"):
        import_pointcloud(path)
    assert extent_m(import_pointcloud(path, units="ft"))[0] == pytest.approx(10.0 * 0.3048, abs=0.02)
    assert extent_m(import_pointcloud(path, crs="EPSG:2263"))[0] == pytest.approx(10.0 * US_FT, abs=0.02)
    assert extent_m(import_pointcloud(path, crs="EPSG:32633"))[0] == pytest.approx(10.0, abs=0.02)
    with pytest.raises(InputError, match="is geographic"):
        import_pointcloud(path, crs="EPSG:4326")
    with pytest.raises(InputError, match="--crs: unknown CRS 'nonsense'"):
        import_pointcloud(path, crs="nonsense")


# --- residuals -------------------------------------------------------------------------------------------------

def test_residual_distribution_is_reported_and_a_segment_over_its_bound_is_a_finding(tmp_path):
    """A rough ground (sigma 8 cm): its smoothed surface explains the points to ~16 cm (p95), over a 0.1 m
    bound; the distribution agrees with trimesh's distances of the generating points."""
    rng = np.random.default_rng(9)
    n = 4000
    g = np.column_stack([rng.uniform(0, 30, n), rng.uniform(0, 30, n), rng.normal(0, 0.08, n)]) + [500, 500, 10]
    path = write_las(tmp_path / "rough.las", g)
    model = import_pointcloud(path, max_residual_m=0.1)
    seg = model.report["segments"][0]
    surface = model.objects[0].parts[0]
    mesh = trimesh.Trimesh(surface.points, surface.triangles, process=False)
    assert seg["name"] == "Ground_01" and seg["points"] >= 0.99 * n
    _, dist, _ = trimesh.proximity.closest_point(mesh, g - model.origin_offset_m)
    assert seg["residual_p95_m"] == pytest.approx(np.percentile(dist, 95), abs=0.01)
    assert seg["residual_p50_m"] == pytest.approx(np.percentile(dist, 50), abs=0.01)
    assert seg["residual_max_m"] <= dist.max() + 0.01  # the 1 % outside the ground band are not in it
    assert seg["points_beyond_bound"] == pytest.approx(int((dist > 0.1).sum()), abs=n * 0.005)
    findings = model.report["findings"]
    assert [f["rule"] for f in findings] == ["residual-bound"] and seg["name"] in findings[0]["where"]
    assert not import_pointcloud(path, max_residual_m=1.0).report["findings"]


def _ground_and_crown(rng, hollow: bool) -> np.ndarray:
    """A 20 x 20 m flat ground and a tree crown of radius 2.5 m, 5 m up: points on its sphere (hollow) or
    filling its ball (inner branches)."""
    ground = np.column_stack([rng.uniform(0, 20, 1600), rng.uniform(0, 20, 1600), rng.normal(0, 0.005, 1600)])
    crown = rng.normal(size=(900, 3))
    crown /= np.linalg.norm(crown, axis=1, keepdims=True)
    crown *= 2.5 if hollow else 2.5 * rng.random((900, 1)) ** (1 / 3)
    return np.concatenate([ground, crown + [10, 10, 5]]) + [500, 500, 10]


def test_a_tree_hull_is_reported_against_its_own_bound(tmp_path):
    """A filled crown's points lie up to its radius inside its hull (p95 about 0.63 x 2.5 m = 1.6 m): over the
    hull bound, a finding; a hollow crown's hull explains its points, and the looser bound admits the filled one."""
    rng = np.random.default_rng(4)
    filled = import_pointcloud(write_las(tmp_path / "filled.las", _ground_and_crown(rng, hollow=False)))
    (tree,) = [s for s in filled.report["segments"] if s.get("kind") == "tree"]
    assert tree["surface"] == "convex hull" and tree["residual_bound_m"] == 1.0
    assert tree["residual_p95_m"] == pytest.approx(1.58, abs=0.15)
    assert [f["where"].rsplit(" ", 1)[-1] for f in filled.report["findings"]] == [tree["name"]]
    assert "--max-hull-residual-m" in filled.report["findings"][0]["message"]
    hollow = import_pointcloud(write_las(tmp_path / "hollow.las", _ground_and_crown(rng, hollow=True)))
    assert [s["kind"] for s in hollow.report["segments"]].count("tree") == 1 and not hollow.report["findings"]
    looser = import_pointcloud(tmp_path / "filled.las", max_hull_residual_m=2.5)
    assert not looser.report["findings"]
