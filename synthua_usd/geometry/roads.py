"""The road graph a dashcam drives on, and a drive along it over the animation.

The road surfaces (``road``, ``street_road`` and the ``crosswalk`` paint on them) are rasterised with the
walkable-grid machinery of :mod:`synthua_usd.agents.walkable` (a vertical Embree ray per cell, the
highest road surface with 2 m of free headroom, so parked cars and bus shelters block their cells). Each
cell knows its *clearance*, the distance to the nearest cell that is not road. The graph keeps the cells
where a car fits (clearance at least :data:`VEHICLE_HALF_WIDTH_M`) and no kerb edges; an edge costs its
length times ``1 + (CENTRE_PULL_M / clearance)^2``, so shortest paths run along the middle of the road
(the centreline) and turn at junctions. A drive follows the longest such path (a double sweep: the
farthest cell from any cell, then the farthest from that one), smoothed by a moving average that is kept
only where it stays on cells with room for the car.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from scipy import ndimage

from synthua_usd.agents.walkable import WalkableGrid, build_grid, walkable_graph
from synthua_usd.core.errors import InputError

if TYPE_CHECKING:  # imported where used (~0.2 s that most processes never need)
    import networkx as nx

ROAD_CLASSES = ("road", "street_road", "crosswalk")
VEHICLE_HALF_WIDTH_M = 0.9
CENTRE_PULL_M = 2.0
SMOOTHING_M = 3.0


@dataclass(frozen=True, eq=False)
class RoadNetwork:
    """``grid`` of road cells; ``clearance_m`` (ny, nx) float64 distance to the nearest non-road cell;
    ``graph`` over the cells where a car fits (nodes (i, j) with ``pos`` (3,) world metres)."""

    grid: WalkableGrid
    clearance_m: np.ndarray = field(repr=False)
    graph: nx.Graph = field(repr=False)

    def on_road(self, xy: np.ndarray, min_clearance_m: float = 0.0) -> np.ndarray:
        """(n,) bool: whether each (n, 2) point lies on a road cell with at least ``min_clearance_m``."""
        g = self.grid
        i = np.floor((xy[:, 1] - g.y0) / g.cell_m).astype(int)
        j = np.floor((xy[:, 0] - g.x0) / g.cell_m).astype(int)
        ny, nx_ = g.z.shape
        inside = (i >= 0) & (i < ny) & (j >= 0) & (j < nx_)
        out = np.zeros(len(xy), bool)
        ii, jj = i[inside], j[inside]
        out[inside] = g.walkable[ii, jj] & (self.clearance_m[ii, jj] >= min_clearance_m)
        return out


def road_network(vertices: np.ndarray, faces: np.ndarray, face_class: np.ndarray, cell_m: float = 0.5,
                 source: str = "scenario") -> RoadNetwork:
    """Rasterise the road surfaces of triangles ``vertices`` (n, 3), ``faces`` (m, 3) with class names
    ``face_class`` (m,). Raises :class:`InputError` naming ``source`` when there is no road a car fits on."""
    import networkx as nx
    if not np.isin(np.asarray(face_class, object), ROAD_CLASSES).any():
        raise InputError(f"{source}: has no road surfaces (classes {', '.join(ROAD_CLASSES)}); expected a twin with "
                         f"roads for a dashcam to drive on")
    grid = build_grid(vertices, faces, face_class, cell_m=cell_m, walkable=ROAD_CLASSES)
    clearance = ndimage.distance_transform_edt(grid.walkable) * cell_m
    full = walkable_graph(grid)
    graph = nx.Graph()
    fits = {n for n in full.nodes if clearance[n] >= VEHICLE_HALF_WIDTH_M}
    for u, v, data in full.edges(data=True):
        if u in fits and v in fits and not data["kerb"]:
            pull = 1.0 + (CENTRE_PULL_M / min(clearance[u], clearance[v])) ** 2
            graph.add_edge(u, v, cost=data["length_m"] * pull)
    for n in graph.nodes:
        graph.nodes[n]["pos"] = full.nodes[n]["pos"]
    if graph.number_of_nodes() < 2:
        raise InputError(f"{source}: its road surfaces leave no room for a car ({VEHICLE_HALF_WIDTH_M * 2:g} m wide); "
                         f"expected a road at least that wide for a dashcam")
    return RoadNetwork(grid, clearance, graph)


def longest_route(net: RoadNetwork) -> np.ndarray:
    """(k, 3) float64 world points along the centre of the road's longest drive (the largest connected part
    of the graph, double sweep), smoothed where the smoothing keeps the car on the road."""
    import networkx as nx
    part = net.graph.subgraph(max(nx.connected_components(net.graph), key=len))
    # Ends on the centreline: cells whose clearance no neighbour exceeds (the ridge of the distance map).
    ridge = net.clearance_m >= ndimage.maximum_filter(net.clearance_m, size=3)
    ends = [n for n in part.nodes if ridge[n]] or list(part.nodes)
    start = min(part.nodes)
    dist = nx.single_source_dijkstra_path_length(part, start, weight="cost")
    a = max(ends, key=lambda n: dist.get(n, -1.0))
    dist, paths = nx.single_source_dijkstra(part, a, weight="cost")
    b = max(ends, key=lambda n: dist.get(n, -1.0))
    points = np.array([part.nodes[n]["pos"] for n in paths[b]], np.float64)
    return _smooth(net, points)


def _smooth(net: RoadNetwork, points: np.ndarray) -> np.ndarray:
    """Moving average over SMOOTHING_M of arc length; points that would leave room-for-a-car cells keep
    their raw position."""
    if len(points) < 3:
        return points
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points[:, :2], axis=0), axis=1))])
    out = points.copy()
    for k in range(len(points)):
        near = np.abs(s - s[k]) <= SMOOTHING_M / 2
        out[k, :2] = points[near, :2].mean(axis=0)
    keep = net.on_road(out[:, :2], VEHICLE_HALF_WIDTH_M)
    out[~keep] = points[~keep]
    return out


def route_length_m(route: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(route[:, :2], axis=0), axis=1).sum())


def drive(route: np.ndarray, start_m: float, distances_m: np.ndarray, look_m: float = 2.0
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where a car is after driving ``distances_m`` (t,) metres from ``start_m`` along ``route`` (k, 3): road
    points (t, 3), headings (t,) radians about +Z from +X, and the road's grade angle (t,) radians, from
    the route ``look_m`` behind and ahead. A car that reaches the route's end stops there."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(route[:, :2], axis=0), axis=1))])
    at = np.clip(start_m + np.asarray(distances_m, float), 0.0, s[-1])

    def point(d):
        d = np.clip(d, 0.0, s[-1])
        return np.column_stack([np.interp(d, s, route[:, i]) for i in range(3)])

    pos = point(at)
    behind, ahead = point(at - look_m), point(at + look_m)
    delta = ahead - behind
    heading = np.arctan2(delta[:, 1], delta[:, 0])
    grade = np.arctan2(delta[:, 2], np.maximum(np.linalg.norm(delta[:, :2], axis=1), 1e-9))
    return pos, heading, grade

