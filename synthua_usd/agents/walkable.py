"""The walkable graph: a 2-D grid over the twin whose cells lie on walkable surfaces, joined to their
eight neighbours by edges that know their length, slope and whether they step over a kerb.

Walkable classes: sidewalk, crosswalk, curb_ramp and the cobbled street_road; the asphalt road only
inside a crosswalk's footprint. A cell's surface is found by casting a vertical ray (Embree through
trimesh) and taking the highest walkable hit with 2 m of headroom free of other geometry, so that
benches, poles and stands block their cells while tent canopies do not.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from synthua_usd.agents.profiles import AgentProfile
from synthua_usd.core.errors import InputError

if TYPE_CHECKING:  # imported where used (~0.2 s that most processes never need)
    import networkx as nx

WALKABLE = ("sidewalk", "crosswalk", "curb_ramp", "street_road")
CROSSING_ONLY = "road"
#: Between neighbouring cells, a rise of more than STEP_M that is also steeper than KERB_SLOPE is a kerb
#: or a stair riser (stepped, not rolled); a curb ramp (1:12) stays below it even across a diagonal.
#: Above MAX_STEP_M it is a wall.
STEP_M = 0.03
KERB_SLOPE = 0.125
MAX_STEP_M = 0.22
HEADROOM_M = 2.0
#: Most cells a walkable grid may have (each is one downward ray; 4e6 cells is a 1 km square at 0.5 m).
MAX_CELLS = 4_000_000


@dataclass(frozen=True, eq=False)
class WalkableGrid:
    """Cells of ``cell_m`` metres. ``z`` (ny, nx) float64 surface height (NaN where not walkable); ``surface``
    (ny, nx) object array of class names ('' where not walkable). Cell (i, j) centre is at
    (x0 + (j + 0.5) cell, y0 + (i + 0.5) cell)."""

    x0: float
    y0: float
    cell_m: float
    z: np.ndarray = field(repr=False)
    surface: np.ndarray = field(repr=False)
    blocker: np.ndarray | None = field(default=None, repr=False)  # (ny, nx) class of what blocks a cell, or ''

    def cells_beside(self, class_name: str) -> list[tuple[int, int]]:
        """Walkable cells next to a cell blocked by ``class_name`` (e.g. the seats of benches)."""
        if self.blocker is None:
            return []
        hit = self.blocker == class_name
        near = np.zeros_like(hit)
        near[1:] |= hit[:-1]
        near[:-1] |= hit[1:]
        near[:, 1:] |= hit[:, :-1]
        near[:, :-1] |= hit[:, 1:]
        return [(int(i), int(j)) for i, j in zip(*np.nonzero(near & self.walkable))]

    @property
    def walkable(self) -> np.ndarray:
        return ~np.isnan(self.z)

    def centre(self, i: int, j: int) -> np.ndarray:
        return np.array([self.x0 + (j + 0.5) * self.cell_m, self.y0 + (i + 0.5) * self.cell_m, self.z[i, j]])

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        return int((y - self.y0) // self.cell_m), int((x - self.x0) // self.cell_m)

    def area_m2(self) -> float:
        return float(self.walkable.sum()) * self.cell_m ** 2


def build_grid(vertices: np.ndarray, faces: np.ndarray, face_class: np.ndarray, cell_m: float = 0.5,
               walkable: tuple[str, ...] = WALKABLE) -> WalkableGrid:
    """Rasterise walkable surfaces. ``vertices`` (n, 3) world metres, Z up; ``faces`` (m, 3); ``face_class``
    (m,) class name per face; ``walkable`` the classes people walk on (the road counts inside crosswalks
    whatever this says; add ``road`` for twins whose roads include their sidewalks, as CityJSON's often do)."""
    import trimesh
    if len(faces) == 0:
        raise InputError("the twin has no geometry to walk on")
    mesh = trimesh.Trimesh(vertices, faces, process=False, validate=False)
    # The grid spans the labelled geometry: an imported twin's generated ground (unlabelled) reaches kilometres
    # past it, and nobody walks there.
    labelled = np.asarray(face_class, object) != "unlabelled"
    spanned = vertices[np.unique(faces[labelled])] if labelled.any() else vertices
    lo, hi = spanned.min(axis=0), spanned.max(axis=0)
    hi[2] = vertices[:, 2].max()  # rays start above everything
    if not (math.isfinite(cell_m) and cell_m > 0):
        raise InputError(f"cell size: {cell_m!r}; expected a finite number of metres > 0")
    nx_, ny_ = int(math.ceil((hi[0] - lo[0]) / cell_m)), int(math.ceil((hi[1] - lo[1]) / cell_m))
    if nx_ * ny_ > MAX_CELLS:
        raise InputError(f"walkable grid: {hi[0] - lo[0]:.0f} x {hi[1] - lo[1]:.0f} m at {cell_m:g} m cells is "
                         f"{nx_ * ny_:.3g} cells; expected at most {MAX_CELLS:.0e} (use a larger --cell-m)")
    xs = lo[0] + (np.arange(nx_) + 0.5) * cell_m
    ys = lo[1] + (np.arange(ny_) + 0.5) * cell_m
    gx, gy = np.meshgrid(xs, ys)
    origins = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, hi[2] + 10.0)])
    dirs = np.tile([0.0, 0.0, -1.0], (len(origins), 1))
    locations, ray_idx, tri_idx = mesh.ray.intersects_location(origins, dirs, multiple_hits=True)
    classes = np.asarray(face_class, object)
    normals_up = mesh.face_normals[:, 2] > 0.5
    z = np.full(gx.size, np.nan)
    surface = np.full(gx.size, "", object)
    blocker = np.full(gx.size, "", object)
    crosswalk_boxes = _footprints(vertices, faces, classes, "crosswalk")
    order = np.lexsort((-locations[:, 2], ray_idx))
    ray_sorted, loc_sorted, tri_sorted = ray_idx[order], locations[order], tri_idx[order]
    starts = np.searchsorted(ray_sorted, np.arange(len(origins)))
    ends = np.searchsorted(ray_sorted, np.arange(len(origins)), side="right")
    for r in range(len(origins)):
        hits = range(starts[r], ends[r])
        for k in hits:
            cls = classes[tri_sorted[k]]
            if not normals_up[tri_sorted[k]]:
                continue
            walk = cls in walkable or (cls == CROSSING_ONLY and _inside(origins[r, :2], crosswalk_boxes))
            if not walk:
                continue
            zk = loc_sorted[k, 2]
            above = [m for m in hits if m != k and zk + 0.05 < loc_sorted[m, 2] < zk + HEADROOM_M]
            if above:
                blocker[r] = classes[tri_sorted[above[-1]]]  # the lowest thing in the way
            else:
                z[r] = zk
                surface[r] = "crosswalk" if cls == CROSSING_ONLY and cls not in walkable else cls
            break  # the highest walkable surface decides the cell, free or blocked
    return WalkableGrid(float(lo[0]), float(lo[1]), cell_m, z.reshape(ny_, nx_), surface.reshape(ny_, nx_),
                        blocker.reshape(ny_, nx_))


def _footprints(vertices, faces, classes, name) -> list[tuple[float, float, float, float]]:
    """x/y bounding boxes of connected groups of ``name`` faces (one per crosswalk, roughly)."""
    import trimesh
    idx = np.flatnonzero(classes == name)
    if len(idx) == 0:
        return []
    sub = trimesh.Trimesh(vertices, faces[idx], process=False, validate=False)
    # Bars of one crosswalk are 0.5 m apart: merge components whose boxes are within 1 m.
    boxes = []
    for comp in trimesh.graph.connected_components(sub.face_adjacency, nodes=np.arange(len(idx))):
        pts = vertices[faces[idx[comp]].ravel()]
        boxes.append([pts[:, 0].min(), pts[:, 1].min(), pts[:, 0].max(), pts[:, 1].max()])
    merged = True
    while merged:
        merged = False
        for a in range(len(boxes)):
            for b in range(a + 1, len(boxes)):
                A, B = boxes[a], boxes[b]
                if A[0] - 1 <= B[2] and B[0] - 1 <= A[2] and A[1] - 1 <= B[3] and B[1] - 1 <= A[3]:
                    boxes[a] = [min(A[0], B[0]), min(A[1], B[1]), max(A[2], B[2]), max(A[3], B[3])]
                    del boxes[b]
                    merged = True
                    break
            if merged:
                break
    return [tuple(b) for b in boxes]


def _inside(xy, boxes) -> bool:
    return any(b[0] - 0.3 <= xy[0] <= b[2] + 0.3 and b[1] - 0.3 <= xy[1] <= b[3] + 0.3 for b in boxes)


def walkable_graph(grid: WalkableGrid) -> nx.Graph:
    """Nodes (i, j) with ``pos`` (3,) and ``surface``; edges with ``length_m`` (3-D), ``dz_m``, ``slope``,
    ``kerb`` (a step: see STEP_M, KERB_SLOPE) and ``cobbles``. Rises above MAX_STEP_M are not edges."""
    import networkx as nx
    g = nx.Graph()
    ok = grid.walkable
    ny_, nx_ = ok.shape
    for i, j in zip(*np.nonzero(ok)):
        g.add_node((int(i), int(j)), pos=grid.centre(i, j), surface=grid.surface[i, j])
    for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1)):
        for i, j in zip(*np.nonzero(ok)):
            a, b = i + di, j + dj
            if not (0 <= a < ny_ and 0 <= b < nx_ and ok[a, b]):
                continue
            dz = grid.z[a, b] - grid.z[i, j]
            if abs(dz) > MAX_STEP_M:
                continue
            run = grid.cell_m * math.hypot(di, dj)
            kerb = abs(dz) > STEP_M and abs(dz) / run > KERB_SLOPE
            g.add_edge((int(i), int(j)), (int(a), int(b)), length_m=math.hypot(run, dz), dz_m=float(dz),
                       slope=abs(dz) / run, kerb=kerb,
                       cobbles="street_road" in (grid.surface[i, j], grid.surface[a, b]))
    return g


def travel_times_s(profile: AgentProfile, length_m, slope, kerb, cobbles) -> np.ndarray:
    """Travel time in seconds along edges of ``length_m`` (e,) float64 metres, ``slope`` (e,) float64 rise/run,
    ``kerb`` and ``cobbles`` (e,) bool (the edge attributes of :func:`walkable_graph`), for ``profile``:
    (e,) float64, inf where it cannot pass. Every operation is one IEEE operation per element, in the order
    scalar Python would do it, so an element equals what the same formula gives for one edge."""
    length_m, slope = np.asarray(length_m, np.float64), np.asarray(slope, np.float64)
    t = length_m / profile.speed_mps
    t = t * (1.0 + profile.slope_penalty * np.maximum(0.0, slope - 0.02))
    t = np.where(cobbles, t * profile.cobble_factor, t)
    t = np.where(slope > profile.max_slope, np.inf, t)
    stepped = length_m / profile.speed_mps + 0.5 if profile.can_step_kerb else np.inf  # a step costs a moment
    return np.where(kerb, stepped, t)


def edge_cost(profile: AgentProfile):
    """networkx weight function: travel time in seconds (:func:`travel_times_s`), or None where ``profile``
    cannot pass."""
    def cost(u, v, data) -> float | None:
        t = float(travel_times_s(profile, data["length_m"], data["slope"], data["kerb"], data["cobbles"]))
        return None if t == math.inf else t
    return cost


class Router:
    """Shortest paths over travel time on one walkable graph, for any profile.

    The search is networkx's ``astar_path`` with :func:`edge_cost` as its weight, step for step: the same
    queue entries (priority, push counter, node, cost so far, parent) pushed in the same order, neighbours
    taken in the graph's adjacency order, the same heuristic value, so the same path comes out, ties
    included (a route is part of the committed stages). What differs is the bookkeeping: edges are held as
    arrays over the graph's adjacency, each profile's costs are computed for every edge at once on first use
    (not once per edge a search relaxes), and nodes are list indices.
    """

    def __init__(self, graph: nx.Graph) -> None:
        self.graph = graph
        self.nodes = list(graph)
        self._index = {n: k for k, n in enumerate(self.nodes)}
        # Each node's position as its own contiguous (2,) array: the heuristic takes the same dot product
        # as np.linalg.norm of a subtraction of two ``pos[:2]`` does.
        self._xy = [np.array(graph.nodes[n]["pos"][:2], np.float64) for n in self.nodes]
        first, neighbour, attributes = [0], [], []
        for n in self.nodes:
            for m, data in graph.adj[n].items():
                neighbour.append(self._index[m])
                attributes.append((data["length_m"], data["slope"], data["kerb"], data["cobbles"]))
            first.append(len(neighbour))
        self._first = first  # node k's neighbours are entries first[k]:first[k + 1], in adjacency order
        self._neighbour = neighbour
        columns = list(zip(*attributes)) or [(), (), (), ()]
        self._length_m, self._slope = np.array(columns[0], np.float64), np.array(columns[1], np.float64)
        self._kerb, self._cobbles = np.array(columns[2], bool), np.array(columns[3], bool)
        self._costs: dict[AgentProfile, list[float]] = {}

    def costs(self, profile: AgentProfile) -> list[float]:
        """Travel time (s) per adjacency entry for ``profile``, inf where it cannot pass; computed once."""
        if profile not in self._costs:
            self._costs[profile] = travel_times_s(profile, self._length_m, self._slope, self._kerb,
                                                  self._cobbles).tolist()
        return self._costs[profile]

    def path(self, start, goal, profile: AgentProfile) -> list:
        """The nodes from ``start`` to ``goal`` (both included) that :func:`shortest_path` returns; raises
        ``networkx.NodeNotFound`` and ``networkx.NetworkXNoPath`` as it does."""
        import networkx as nx
        for role, node in (("Source", start), ("Target", goal)):
            if node not in self._index:
                raise nx.NodeNotFound(f"{role} {node} is not in G")
        source, target = self._index[start], self._index[goal]
        cost, first, neighbour, xy = self.costs(profile), self._first, self._neighbour, self._xy
        goal_xy, speed, inf = xy[target], profile.speed_mps, math.inf
        # networkx keeps the source out of its ``enqueued`` map: a neighbour re-queues it, and the pops
        # count. Unqueued nodes have an infinite queued cost here; -2 marks unexplored, -1 the source's None.
        queued_cost, queued_h, parent_of = [inf] * len(self.nodes), [0.0] * len(self.nodes), [-2] * len(self.nodes)
        counter = itertools.count()
        queue = [(0, next(counter), source, 0, -1)]
        while queue:
            _, __, node, dist, parent = heapq.heappop(queue)
            if node == target:
                path = [node]
                while parent != -1:
                    path.append(parent)
                    parent = parent_of[parent]
                return [self.nodes[k] for k in reversed(path)]
            if parent_of[node] != -2:
                if parent_of[node] == -1 or queued_cost[node] < dist:
                    continue
            parent_of[node] = parent
            for e in range(first[node], first[node + 1]):
                c = cost[e]
                if c == inf:
                    continue
                m = neighbour[e]
                total = dist + c
                if queued_cost[m] != inf:
                    if queued_cost[m] <= total:
                        continue
                    h = queued_h[m]
                else:
                    d = xy[m] - goal_xy
                    h = math.sqrt(d.dot(d)) / speed
                queued_cost[m], queued_h[m] = total, h
                heapq.heappush(queue, (total + h, next(counter), m, total, node))
        raise nx.NetworkXNoPath(f"Node {goal} not reachable from {start}")


def shortest_path(graph: nx.Graph, start, goal, profile: AgentProfile) -> list[tuple[int, int]]:
    """A* over travel time; the heuristic (straight-line distance at the profile's speed) never
    overestimates, since every cost multiplier is at least 1. One search: for many on one graph, keep a
    :class:`Router`, which computes each profile's edge costs once."""
    return Router(graph).path(start, goal, profile)
