"""Point-cloud segmentation against the labels that generated a synthetic cloud: ground on rising terrain, two
buildings whose flat roofs lie in one plane, and a tree."""

import numpy as np
import pytest
import trimesh

from las_files import write_las
from synthua_usd.importers.pointcloud import import_pointcloud
from synthua_usd.importers.segmentation import segment

GROUND, BUILDING, TREE = 0, 1, 2
SLOPE = 0.05  # terrain rises 5 m per 100 m in x
ROOF_Z = 10.0  # both roofs at the same height: one RANSAC plane, two connected regions


def _surface(rng, density, corners_uv, origin, u, v):
    """Points on the parallelogram origin + s*u + t*v, s, t in [0, 1], ``density`` points per m²."""
    area = np.linalg.norm(np.cross(u, v))
    n = int(density * area)
    s, t = rng.random(n), rng.random(n)
    return origin + s[:, None] * u + t[:, None] * v


def city_block(seed=0, density=4.0, noise=0.01):
    """(points (n, 3) metres, labels (n,)): 80 x 60 m terrain rising along x, buildings A (x 15-27, y 20-30)
    and B (x 50-60, y 15-29) with flat roofs at z = 10 and walls down to the terrain, a tree (crown radius
    2.5 m, 5 m above the terrain at (40, 45)); terrain under the buildings is not seen."""
    rng = np.random.default_rng(seed)
    parts = []
    g = np.column_stack([rng.uniform(0, 80, int(80 * 60 * density)), rng.uniform(0, 60, int(80 * 60 * density))])
    inside = ((g[:, 0] > 15) & (g[:, 0] < 27) & (g[:, 1] > 20) & (g[:, 1] < 30)) | \
             ((g[:, 0] > 50) & (g[:, 0] < 60) & (g[:, 1] > 15) & (g[:, 1] < 29))
    g = g[~inside]
    parts.append((np.column_stack([g, SLOPE * g[:, 0]]), GROUND))
    for x0, x1, y0, y1 in ((15, 27, 20, 30), (50, 60, 15, 29)):
        parts.append((_surface(rng, density, None, np.array([x0, y0, ROOF_Z]), np.array([x1 - x0, 0, 0]),
                               np.array([0, y1 - y0, 0])), BUILDING))
        for a, b in (((x0, y0), (x1, y0)), ((x1, y0), (x1, y1)), ((x1, y1), (x0, y1)), ((x0, y1), (x0, y0))):
            base = SLOPE * min(a[0], b[0])
            wall = _surface(rng, density, None, np.array([a[0], a[1], base]), np.array([b[0] - a[0], b[1] - a[1], 0]),
                            np.array([0, 0, ROOF_Z - base]))
            wall = wall[wall[:, 2] >= SLOPE * wall[:, 0] + 0.05]  # walls start at the terrain
            parts.append((wall, BUILDING))
    crown = rng.normal(size=(900, 3))
    crown = crown / np.linalg.norm(crown, axis=1, keepdims=True) * (2.5 * rng.random((900, 1)) ** (1 / 3))
    parts.append((crown + [40, 45, SLOPE * 40 + 5.0], TREE))
    trunk = np.column_stack([40 + rng.normal(0, 0.1, 60), 45 + rng.normal(0, 0.1, 60),
                             SLOPE * 40 + rng.uniform(0.3, 2.6, 60)])
    parts.append((trunk, TREE))
    points = np.concatenate([p for p, _ in parts])
    labels = np.concatenate([np.full(len(p), k) for p, k in parts])
    points = points + rng.normal(0, noise, points.shape)
    return points, labels


def predicted(regions, n):
    out = np.full(n, -1)
    for region in regions:
        out[region.indices] = {"ground": GROUND, "ground_plane": GROUND, "roof": BUILDING, "facade": BUILDING,
                               "tree": TREE}[region.kind]
    return out


def precision_recall(pred, truth, k):
    tp = np.sum((pred == k) & (truth == k))
    return tp / max(np.sum(pred == k), 1), tp / max(np.sum(truth == k), 1)


@pytest.fixture(scope="module")
def block():
    points, labels = city_block()
    return points, labels, segment(points, None, np.random.default_rng(0), threshold_m=0.05)


def test_building_points_precision_and_recall(block):
    points, labels, found = block
    pred = predicted(found.regions, len(points))
    p, r = precision_recall(pred, labels, BUILDING)
    assert p >= 0.95 and r >= 0.95, (p, r)
    gp, gr = precision_recall(pred, labels, GROUND)
    assert gp >= 0.95 and gr >= 0.95, (gp, gr)
    assert found.ground_source.startswith("morphological filter")


def test_roofs_are_connected_regions_and_told_from_rising_ground_by_local_height(block):
    points, labels, found = block
    roofs = [r for r in found.regions if r.kind == "roof"]
    assert len(roofs) == 2  # one plane, two connected regions
    centres = sorted(points[r.indices, 0].mean() for r in roofs)
    assert centres == [pytest.approx(21, abs=1), pytest.approx(55, abs=1)]
    # Height above the local ground: ~9 m over A, ~7.3 m over B (terrain 0.75-1.35 m and 2.5-3 m under them).
    hag = [float(np.median(found.height_above_ground_m[r.indices])) for r in sorted(roofs, key=lambda r: r.indices[0])]
    assert sorted(hag) == [pytest.approx(ROOF_Z - SLOPE * 55, abs=0.5), pytest.approx(ROOF_Z - SLOPE * 21, abs=0.5)]
    # No ground region spans the roofs.
    ground = np.concatenate([r.indices for r in found.regions if r.kind == "ground"])
    assert np.mean(labels[ground] == GROUND) >= 0.99


def test_tree_is_one_cluster(block):
    points, labels, found = block
    trees = [r for r in found.regions if r.kind == "tree"]
    assert len(trees) == 1
    p, r = precision_recall(predicted(found.regions, len(points)), labels, TREE)
    assert p >= 0.9 and r >= 0.9, (p, r)
    assert len(found.unfit) < 0.02 * len(points)


@pytest.mark.slow
def test_import_gives_connected_roofs_a_tree_hull_and_counts(tmp_path):
    points, labels = city_block()
    path = write_las(tmp_path / "block.las", points + [600000.0, 5000000.0, 100.0])
    model = import_pointcloud(path, plane_threshold_m=0.05, max_deviation_m=0.01)
    segs = {s["name"]: s for s in model.report["segments"]}
    roofs = [s for s in segs.values() if s.get("kind") == "roof"]
    assert len(roofs) == 2 and all(s["label"] == "building" for s in roofs)
    (tree,) = [o for o in model.objects if o.label == "vegetation"]
    hull = trimesh.Trimesh(tree.parts[0].points, tree.parts[0].triangles, process=False)
    assert hull.is_watertight and hull.is_volume  # a closed hull, not shards
    seg = model.report["segmentation"]
    building = seg["points_by_kind"].get("roof", 0) + seg["points_by_kind"].get("facade", 0)
    assert building == pytest.approx(np.sum(labels == BUILDING), rel=0.05)
    assert seg["unfit_share"] == pytest.approx(seg["unfit_points"] / len(points))
    # Simplification simplifies: planes collapse, and the faces before and after are reported.
    for s in roofs:
        assert s["faces"] < s["faces_reconstructed"] / 10
