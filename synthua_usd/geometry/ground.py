"""The ground an imported twin stands on, beyond what the source modelled, so that no camera sees under the world.

Imports rarely carry terrain for their whole surroundings: a CityJSON file has buildings and roads, perhaps a
``TINRelief``; a point cloud ends at its tile. :func:`ground_object` makes a height field that follows the
model's own ground and reaches far past it:

* ground samples (x, y, z), local metres: the vertices of ground-like surfaces (roads, sidewalks, grass,
  CityJSON ``TINRelief`` and ``LandUse``), and the base of every other object (its lowest point, where it
  meets the ground; a floating roof segment of a point cloud gives its own base, which is why ground
  surfaces come first: the lowest sample of a cell wins);
* a rectilinear grid over the model's extent plus a margin (at most :data:`GRID_CELLS` cells a side) whose
  heights interpolate the cells' lowest samples linearly (nearest sample outside their hull), lowered by
  :data:`BELOW_M` so that the model's own surfaces stay on top in every label pass;
* one more ring of vertices :data:`REACH_M` away, at the height of the grid's edge, so that the ground
  reaches the horizon of any camera near the model.

The ground is labelled ``unlabelled`` (class 0): nobody measured it, and a label pass must not count it as
the twin. Where the source has its own terrain (TINRelief, LAS ground) that terrain is drawn as imported, on
top of this surface.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.model.materials import class_material
from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart

#: Classes whose surfaces lie on the ground.
GROUND_CLASSES = ("road", "street_road", "sidewalk", "crosswalk", "curb_ramp", "grass", "cover")
#: CityJSON types that are ground whatever class a rule gave them.
GROUND_TYPES = ("TINRelief", "LandUse", "TransportSquare")
#: Name of the ground object under ``/World/Twin``.
GROUND_PATH = "Ground/Surroundings"
#: Cells of the inner grid along its longer side.
GRID_CELLS = 96
#: How far the outer ring lies from the model's centre (metres): past any automatic camera's far plane.
REACH_M = 20_000.0
#: How far the generated ground lies below the samples it interpolates (metres).
BELOW_M = 0.05


def is_ground(obj: TwinObject) -> bool:
    """Whether an imported object lies on the ground (its vertices are ground samples)."""
    return obj.label in GROUND_CLASSES or obj.attributes.get("cityjson_type") in GROUND_TYPES


def ground_samples(model: TwinModel) -> np.ndarray:
    """(n, 3) float64 local metres: vertices of ground objects, and the lowest point of every other object."""
    samples = []
    for obj in model.objects:
        pts = np.concatenate([p.points for p in obj.parts]) if obj.parts else np.zeros((0, 3))
        if not len(pts):
            continue
        samples.append(pts if is_ground(obj) else pts[[int(np.argmin(pts[:, 2]))]])
    return np.concatenate(samples) if samples else np.zeros((0, 3))


def ground_heights(samples: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """(len(ys), len(xs)) float64: the ground height at the grid nodes from ``samples`` (n, 3): lowest sample
    per node cell, interpolated linearly, nearest outside the samples' hull."""
    from scipy.interpolate import griddata

    ix = np.clip(np.searchsorted(xs, samples[:, 0]), 0, len(xs) - 1)
    iy = np.clip(np.searchsorted(ys, samples[:, 1]), 0, len(ys) - 1)
    lowest = np.full((len(ys), len(xs)), np.inf)
    np.minimum.at(lowest, (iy, ix), samples[:, 2])
    known = np.isfinite(lowest)
    gx, gy = np.meshgrid(xs, ys)
    nodes = np.column_stack([gx[known], gy[known]])
    values = lowest[known]
    if len(values) < 3:
        return np.full(gx.shape, float(values.min()))
    z = griddata(nodes, values, (gx, gy), method="linear") if len(values) >= 4 else np.full(gx.shape, np.nan)
    missing = ~np.isfinite(z)
    if missing.any():
        z[missing] = griddata(nodes, values, (gx[missing], gy[missing]), method="nearest")
    return z


def ground_object(model: TwinModel) -> TwinObject:
    """The generated ground of ``model`` as an ``unlabelled`` object at :data:`GROUND_PATH`; its attributes say
    what it was made from."""
    samples = ground_samples(model)
    lo, hi = samples[:, :2].min(axis=0), samples[:, :2].max(axis=0)
    size = float(max((hi - lo).max(), 1.0))
    margin = max(0.25 * size, 20.0)
    step = (size + 2 * margin) / GRID_CELLS
    xs = np.arange(lo[0] - margin, hi[0] + margin + step, step)
    ys = np.arange(lo[1] - margin, hi[1] + margin + step, step)
    z = ground_heights(samples, xs, ys) - BELOW_M
    centre = (lo + hi) / 2
    # The outer ring: the grid's border nodes pushed out radially to REACH_M, at their own heights.
    xs_all = np.concatenate([[centre[0] - REACH_M], xs, [centre[0] + REACH_M]])
    ys_all = np.concatenate([[centre[1] - REACH_M], ys, [centre[1] + REACH_M]])
    z_all = np.pad(z, 1, mode="edge")
    gx, gy = np.meshgrid(xs_all, ys_all)
    points = np.column_stack([gx.ravel(), gy.ravel(), z_all.ravel()])
    nx = len(xs_all)
    i, j = np.meshgrid(np.arange(len(ys_all) - 1), np.arange(nx - 1), indexing="ij")
    a = (i * nx + j).ravel()
    b, c, d = a + 1, a + nx + 1, a + nx
    triangles = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])]).astype(np.int64)
    sources = sorted({o.attributes.get("cityjson_type") or o.label for o in model.objects if is_ground(o)})
    part = TwinPart("Surface", points, triangles, class_material("unlabelled").key)
    return TwinObject(GROUND_PATH, "unlabelled", (part,),
                      {"generated": "ground", "ground_samples_from": ", ".join(sources) or "object bases",
                       "reach_m": REACH_M})


def height_at(ground: TwinObject, xy: np.ndarray) -> np.ndarray:
    """(n,) float64: the generated ground's height under (n, 2) local x, y (bilinear on its grid)."""
    from scipy.interpolate import RegularGridInterpolator

    part = ground.parts[0]
    xs = np.unique(part.points[:, 0])
    ys = np.unique(part.points[:, 1])
    z = part.points[:, 2].reshape(len(ys), len(xs))
    return RegularGridInterpolator((ys, xs), z, bounds_error=False, fill_value=None)(
        np.column_stack([xy[:, 1], xy[:, 0]]))
