"""Point-cloud segmentation that respects space: ground, connected planes, trees, and what fits nothing.

Plain numpy/scipy on (n, 3) float64 local metres, Z up; no files, no meshes (:mod:`pointcloud` builds those).

1. Ground: the LAS classification's ground (class 2) where the file has one, else a progressive
   morphological filter (Zhang et al. 2003): the lowest point per cell, opened (scipy.ndimage grey opening)
   with windows doubling up to :data:`MAX_OBJECT_M`; a cell that rises above the opened surface by more than
   the slope allows is an object. The opened surface is the terrain model (DTM); every point gets its height
   above the local ground from it (bilinear), and ground points are those within :data:`GROUND_BAND_M` of it.
   A point near the terrain whose neighbourhood faces sideways (the foot of a wall) is not ground.
2. Planes: RANSAC (least-squares refit) on the points above ground, each plane's inliers split into connected
   regions (neighbours within :func:`link_radius`); one region at a time becomes a segment, so a plane shared
   by two roofs gives two roofs and no plane spans a tile. Named by normal and height above local ground:
   facade (vertical), roof (above :data:`ROOF_MIN_M`), else ground-level (a raised plaza, a ramp).
3. Trees: the remaining points above ground, split into connected clusters; a cluster at least
   :data:`TREE_MIN_M` tall and at most :data:`TREE_MAX_M` wide is vegetation (its surface is its convex hull, built by :mod:`pointcloud`).
4. What is left fits no surface: reported by count and share, not turned into shards.

Why scipy and not a point-cloud library: PDAL (SMRF/CSF ground filters) is not installable from PyPI with its
C++ core, and Open3D's wheel is ~400 MB with its own RANSAC and DBSCAN but no ground filter; pymeshlab (already
a dependency) has no ground filter or plane segmentation. The pieces here are scipy's KD-tree, sparse
connected components, grey opening and interpolation, a few lines each.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Ground points lie within this height of the terrain model (metres): scanner noise plus kerbs.
GROUND_BAND_M = 0.25
#: Points this close to the terrain model are ground whatever their neighbourhood's normal (metres).
ON_GROUND_M = 0.05
#: Planes above this height over the local ground are roofs (metres); lower horizontal planes are ground-level.
ROOF_MIN_M = 1.5
#: Clusters at least this tall, and at most this wide, are trees (metres): the widest crowns reach ~40 m.
TREE_MIN_M = 1.0
TREE_MAX_M = 40.0
#: The largest object the ground filter removes (metres): buildings wider than this need LAS classes.
MAX_OBJECT_M = 64.0
#: Terrain slope the ground filter allows between windows (rise over run), and its base height step (metres).
MAX_SLOPE = 0.5
BASE_STEP_M = 0.3


@dataclass(frozen=True)
class Region:
    """One segment: ``indices`` into the cloud, ``kind`` ('ground', 'roof', 'facade', 'ground_plane' or
    'tree'), the LAS class it came from (or None), and the fitted plane (unit normal, d) for planes."""

    kind: str
    indices: np.ndarray
    las_class: int | None = None
    plane: tuple[np.ndarray, float] | None = None


@dataclass(frozen=True)
class Segmentation:
    """The regions of a cloud, each point's height above the local ground (metres), and the points no region
    holds (``unfit``, indices)."""

    regions: tuple[Region, ...]
    height_above_ground_m: np.ndarray
    unfit: np.ndarray
    ground_source: str


def spacing(points: np.ndarray, sample: int = 20_000, seed: int = 0) -> float:
    """Median distance from a point to its nearest neighbour (metres), on a sample of at most ``sample``."""
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(seed)
    pick = points if len(points) <= sample else points[rng.choice(len(points), sample, replace=False)]
    if len(pick) < 2:
        return 1.0
    d = cKDTree(points).query(pick, k=2)[0][:, 1]
    return float(np.median(d[d > 0])) if np.any(d > 0) else 1.0


def link_radius(points: np.ndarray) -> float:
    """Neighbours within this distance (metres) are connected: 3x the median spacing, at least 5 cm."""
    return max(3.0 * spacing(points), 0.05)


def connected(points: np.ndarray, radius: float) -> np.ndarray:
    """(n,) int component label of every point: points within ``radius`` of one another, chained."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    if len(points) == 0:
        return np.zeros(0, np.int64)
    pairs = cKDTree(points).query_pairs(radius, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(points),) * 2)
    return connected_components(graph, directed=False)[1]


def terrain_model(ground_xyz: np.ndarray, lo: np.ndarray, hi: np.ndarray, cell_m: float,
                  filter_objects: bool, statistic: str = "min") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(xs, ys, z): cell centres and (len(ys), len(xs)) ground heights from ``ground_xyz``'s lowest (or, with
    ``statistic='median'``, median) point per cell (empty cells take the nearest filled one), opened by the
    morphological filter when ``filter_objects`` (the points still include objects)."""
    from scipy import ndimage
    from scipy.stats import binned_statistic_2d

    nx = max(int(np.ceil((hi[0] - lo[0]) / cell_m)), 1)
    ny = max(int(np.ceil((hi[1] - lo[1]) / cell_m)), 1)
    ix = np.clip(((ground_xyz[:, 0] - lo[0]) / cell_m).astype(int), 0, nx - 1)
    iy = np.clip(((ground_xyz[:, 1] - lo[1]) / cell_m).astype(int), 0, ny - 1)
    if statistic == "min":
        z = np.full((ny, nx), np.inf)
        np.minimum.at(z, (iy, ix), ground_xyz[:, 2])
    else:
        z = binned_statistic_2d(iy, ix, ground_xyz[:, 2], statistic, bins=[np.arange(ny + 1) - 0.5,
                                                                           np.arange(nx + 1) - 0.5])[0]
    empty = ~np.isfinite(z)
    if empty.all():
        z[:] = 0.0
    elif empty.any():
        nearest = ndimage.distance_transform_edt(empty, return_distances=False, return_indices=True)
        z = z[tuple(nearest)]
    if filter_objects:
        window, previous = 1, 1
        while window * cell_m <= MAX_OBJECT_M:
            window = 2 * window + 1
            opened = ndimage.grey_opening(z, size=(window, window))
            step = BASE_STEP_M + MAX_SLOPE * (window - previous) * cell_m
            z = np.where(z - opened > step, opened, z)
            previous = window
    xs = lo[0] + (np.arange(nx) + 0.5) * cell_m
    ys = lo[1] + (np.arange(ny) + 0.5) * cell_m
    return xs, ys, z


def height_above(points: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: np.ndarray) -> np.ndarray:
    """(n,) height of ``points`` above the terrain model (bilinear between cell centres, clamped at the edge)."""
    from scipy.interpolate import RegularGridInterpolator

    if len(xs) < 2 or len(ys) < 2:
        return points[:, 2] - float(z.mean())
    qx = np.clip(points[:, 0], xs[0], xs[-1])
    qy = np.clip(points[:, 1], ys[0], ys[-1])
    return points[:, 2] - RegularGridInterpolator((ys, xs), z)(np.column_stack([qy, qx]))


def local_normals(points: np.ndarray, k: int = 12) -> np.ndarray:
    """(n, 3) unit normals (z >= 0) of the least-squares plane through each point's ``k`` nearest neighbours."""
    from scipy.spatial import cKDTree

    if len(points) < 3:
        return np.tile([0.0, 0.0, 1.0], (len(points), 1))
    k = min(k, len(points))
    idx = cKDTree(points).query(points, k=k)[1]
    nb = points[idx] - points[idx].mean(axis=1, keepdims=True)
    cov = np.einsum("nki,nkj->nij", nb, nb)
    normals = np.linalg.eigh(cov)[1][:, :, 0]
    normals[normals[:, 2] < 0] *= -1
    return normals


def smoothed_heights(points: np.ndarray, k: int = 16) -> np.ndarray:
    """(n, 3) ``points`` with z moved onto the least-squares plane of its ``k`` nearest neighbours in x, y
    (moving least squares, degree 1): the noise leaves, slopes and terrain stay (a plane is kept exactly)."""
    from scipy.spatial import cKDTree

    if len(points) < 4:
        return points.copy()
    k = min(k, len(points))
    idx = cKDTree(points[:, :2]).query(points[:, :2], k=k)[1]
    nb = points[idx]
    centre = nb.mean(axis=1)
    rel = nb - centre[:, None, :]
    # z = cz + a (x - cx) + b (y - cy): the normal equations of each neighbourhood, solved together.
    a11 = np.einsum("nk,nk->n", rel[..., 0], rel[..., 0])
    a12 = np.einsum("nk,nk->n", rel[..., 0], rel[..., 1])
    a22 = np.einsum("nk,nk->n", rel[..., 1], rel[..., 1])
    b1 = np.einsum("nk,nk->n", rel[..., 0], rel[..., 2])
    b2 = np.einsum("nk,nk->n", rel[..., 1], rel[..., 2])
    det = a11 * a22 - a12 * a12
    ok = np.abs(det) > 1e-12
    a = np.where(ok, (b1 * a22 - b2 * a12) / np.where(ok, det, 1.0), 0.0)
    b = np.where(ok, (a11 * b2 - a12 * b1) / np.where(ok, det, 1.0), 0.0)
    out = points.copy()
    out[:, 2] = centre[:, 2] + a * (points[:, 0] - centre[:, 0]) + b * (points[:, 1] - centre[:, 1])
    return out


#: A plane's inlier must face the plane's way locally too (its neighbourhood's normal within 25 degrees):
#: a slice through a tree crown has inliers, but their neighbourhoods face every way.
NORMAL_AGREEMENT = np.cos(np.radians(25.0))


def ransac_plane(points: np.ndarray, normals: np.ndarray, rng: np.random.Generator, threshold_m: float,
                 iterations: int = 300, neighbours: int = 24):
    """(inlier mask, unit normal, d) of the plane with the most inliers among ``iterations`` random triples,
    refitted by least squares on its inliers; an inlier lies within ``threshold_m`` and its local normal agrees
    (:data:`NORMAL_AGREEMENT`). Triples are drawn locally (a point and two of its ``neighbours`` nearest), so
    that a small wall among many points is sampled as often as a big one. None when no triple spans a plane
    with 3 inliers."""
    from scipy.spatial import cKDTree

    def inliers_of(n, d):
        return (np.abs(points @ n + d) <= threshold_m) & (np.abs(normals @ n) >= NORMAL_AGREEMENT)

    k = min(neighbours, len(points))
    firsts = rng.choice(len(points), iterations)
    near = cKDTree(points).query(points[firsts], k=k)[1].reshape(iterations, k)
    best = None
    for first, around in zip(firsts, near):
        b, c = points[rng.choice(around[1:], 2, replace=False)] if k > 2 else points[rng.choice(len(points), 2)]
        a = points[first]
        n = np.cross(b - a, c - a)
        norm = np.linalg.norm(n)
        if norm < 1e-12:
            continue
        n = n / norm
        inliers = inliers_of(n, -float(n @ a))
        if best is None or inliers.sum() > best.sum():
            best = inliers
    if best is None or best.sum() < 3:
        return None
    normal, d = fit_plane(points[best])
    return inliers_of(normal, d), normal, d


def fit_plane(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares plane: unit normal n (z >= 0) and offset d minimising Σ(n·Xᵢ + d)²."""
    centroid = points.mean(axis=0)
    normal = np.linalg.svd(points - centroid, full_matrices=False)[2][-1]
    if normal[2] < 0:
        normal = -normal
    return normal, -float(normal @ centroid)


def planar_regions(points: np.ndarray, normals: np.ndarray, hag: np.ndarray, rng: np.random.Generator,
                   threshold_m: float, min_points: int, radius: float, max_regions: int = 64,
                   las_class: int | None = None) -> tuple[list[Region], np.ndarray]:
    """Connected planar regions of ``points`` (indices into them) and the indices left over. Each RANSAC plane's
    inliers (those whose local ``normals`` agree with it) are split into connected regions; the largest, if it
    has ``min_points``, becomes a region."""
    remaining = np.arange(len(points))
    regions: list[Region] = []
    failures = 0
    while len(remaining) >= max(min_points, 3) and len(regions) < max_regions and failures < 3:
        found = ransac_plane(points[remaining], normals[remaining], rng, threshold_m)
        if found is None:
            break
        inliers, normal, d = found
        idx = remaining[inliers]
        if len(idx) < min_points:
            break
        parts = connected(points[idx], radius)
        region = idx[parts == np.bincount(parts).argmax()]
        if len(region) < min_points:
            failures += 1
            continue
        # Refit on the region alone (inliers of other regions tilt the plane), and take its region again.
        normal, d = fit_plane(points[region])
        again = remaining[(np.abs(points[remaining] @ normal + d) <= threshold_m)
                          & (np.abs(normals[remaining] @ normal) >= NORMAL_AGREEMENT)]
        parts = connected(points[again], radius)
        overlap = np.bincount(parts[np.isin(again, region)], minlength=parts.max() + 1) if len(again) else [0]
        if len(again) and np.max(overlap) > 0:
            region = again[parts == int(np.argmax(overlap))]
        kind = _plane_kind(normal, float(np.median(hag[region])))
        regions.append(Region(kind, region, las_class, (normal, d)))
        remaining = np.setdiff1d(remaining, region, assume_unique=True)
    return _grown(points, regions, remaining, threshold_m, 2.0 * radius)


def _grown(points: np.ndarray, regions: list[Region], remaining: np.ndarray, threshold_m: float, radius: float
           ) -> tuple[list[Region], np.ndarray]:
    """Regions grown by the remaining points that lie on their plane and within ``radius`` of them, pass after
    pass: points at edges and corners, whose neighbourhoods mix two planes, so that their local normals agree
    with neither (the caller gives twice the link radius: such a band is as wide as a neighbourhood)."""
    from scipy.spatial import cKDTree

    for _ in range(20):  # grow outwards, one link radius per pass
        if not regions or not len(remaining):
            break
        best = np.full(len(remaining), -1)
        best_d = np.full(len(remaining), np.inf)
        for k, region in enumerate(regions):
            normal, d = region.plane
            off = np.abs(points[remaining] @ normal + d)
            near = cKDTree(points[region.indices]).query(points[remaining], distance_upper_bound=radius)[0]
            take = (off <= threshold_m) & np.isfinite(near) & (off < best_d)
            best[take], best_d[take] = k, off[take]
        if not np.any(best >= 0):
            break
        regions = [Region(r.kind, np.sort(np.concatenate([r.indices, remaining[best == k]])), r.las_class, r.plane)
                   for k, r in enumerate(regions)]
        remaining = remaining[best < 0]
    return regions, remaining


def _plane_kind(normal: np.ndarray, height_m: float) -> str:
    if abs(normal[2]) < 0.3:
        return "facade"
    return "roof" if height_m >= ROOF_MIN_M else "ground_plane"


def tree_regions(points: np.ndarray, hag: np.ndarray, radius: float, min_points: int,
                 las_class: int | None = None) -> tuple[list[Region], np.ndarray]:
    """Connected clusters of ``points`` at least :data:`TREE_MIN_M` tall, at most :data:`TREE_MAX_M` wide, with
    ``min_points``, and the rest."""
    labels = connected(points, radius)
    regions, rest = [], []
    for k in np.unique(labels):
        idx = np.flatnonzero(labels == k)
        tall = hag[idx].max() >= TREE_MIN_M and np.ptp(points[idx, 2]) >= TREE_MIN_M / 2
        narrow = np.ptp(points[idx, :2], axis=0).max() <= TREE_MAX_M
        if len(idx) >= min_points and tall and narrow:
            regions.append(Region("tree", idx, las_class))
        else:
            rest.append(idx)
    return regions, (np.concatenate(rest) if rest else np.zeros(0, np.int64))


#: LAS classes (ASPRS) of ground (ground, road surface), vegetation and buildings.
LAS_GROUND = (2, 11)
LAS_VEGETATION = (3, 4, 5)
LAS_BUILDING = (6,)


def segment(points: np.ndarray, classes: np.ndarray | None, rng: np.random.Generator, threshold_m: float,
            min_points: int = 50) -> Segmentation:
    """Segment ``points`` (n, 3) local metres; ``classes`` (n,) LAS classification or None."""
    radius = link_radius(points)
    lo, hi = points.min(axis=0), points.max(axis=0)
    cell = max(1.0, 2.0 * spacing(points))
    classified_ground = classes is not None and np.isin(classes, LAS_GROUND).any()
    if classified_ground:
        xs, ys, z = terrain_model(points[np.isin(classes, LAS_GROUND)], lo, hi, cell, filter_objects=False)
        source = "LAS classification (classes 2, 11)"
    else:
        xs, ys, z = terrain_model(points, lo, hi, cell, filter_objects=True)
        # The lowest point per cell sits at the bottom of the noise: refit on the median of the points near it.
        near = height_above(points, xs, ys, z) <= GROUND_BAND_M
        xs, ys, z = terrain_model(points[near], lo, hi, cell, filter_objects=False, statistic="median")
        source = f"morphological filter ({cell:.2g} m cells, objects up to {MAX_OBJECT_M:g} m)"
    hag = height_above(points, xs, ys, z)
    regions: list[Region] = []
    unfit: list[np.ndarray] = []
    everything = np.arange(len(points))
    if classified_ground:
        ground = np.flatnonzero(np.isin(classes, LAS_GROUND))
        groups = [(np.flatnonzero(np.isin(classes, LAS_BUILDING)), "building", 6),
                  (np.flatnonzero(np.isin(classes, LAS_VEGETATION)), "vegetation", None),
                  (np.flatnonzero(classes <= 1), "any", None)]
    else:
        # Near the terrain and facing up: the foot of a wall is near the terrain too, but faces sideways. On
        # the terrain itself (within ON_GROUND_M) the normal is not asked: quantised dense scans have noisy ones.
        flat = local_normals(points)[:, 2] >= 0.7
        is_ground = ((np.abs(hag) <= GROUND_BAND_M) & flat) | (np.abs(hag) <= ON_GROUND_M)
        ground = everything[is_ground]
        groups = [(everything[~is_ground & (hag > -GROUND_BAND_M)], "any", None)]
        unfit.append(everything[hag < -GROUND_BAND_M])  # below the terrain: noise
    if len(ground):
        regions.append(Region("ground", ground, 2 if classified_ground else None))
    for idx, what, code in groups:
        if len(idx) == 0:
            continue
        rest = idx
        if what in ("building", "any"):
            planes, left = planar_regions(points[idx], local_normals(points[idx]), hag[idx], rng, threshold_m,
                                          min_points, radius, las_class=code)
            regions += [Region(r.kind if what == "any" else ("facade" if r.kind == "facade" else "roof"),
                               idx[r.indices], r.las_class, r.plane) for r in planes]
            rest = idx[left]
        if what in ("vegetation", "any") and len(rest):
            trees, left = tree_regions(points[rest], hag[rest], radius, min_points,
                                       las_class=None if what == "any" else int(classes[rest[0]]))
            regions += [Region(r.kind, rest[r.indices], r.las_class) for r in trees]
            rest = rest[left]
        unfit.append(rest)
    if classified_ground:
        other = np.flatnonzero(~np.isin(classes, LAS_GROUND + LAS_VEGETATION + LAS_BUILDING + (0, 1)))
        unfit.append(other)
    return Segmentation(tuple(regions), hag, np.concatenate(unfit) if unfit else np.zeros(0, np.int64), source)
