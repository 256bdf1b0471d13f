"""A tiny street crossing for the agents' tests: a road between sidewalks with two crosswalks, one of them
with a curb ramp on one side only. Test modules of this folder import it (pytest puts the folder on
sys.path)."""

import numpy as np

from synthua_usd.agents.population import plan_agents
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.agents.walkable import build_grid, shortest_path, walkable_graph
from synthua_usd.model import meshes as geo


def crossing_scene():
    """A 7 m road between two 3 m sidewalks (15 cm kerbs). Crosswalk A at x = -6 has a curb ramp only on
    the north side; crosswalk B at x = 8 has ramps on both sides."""
    parts, classes = [], []

    def add(mesh, cls):
        parts.append(mesh)
        classes.extend([cls] * len(mesh[1]))

    add(geo.box((-20, -3.5, -0.3), (20, 3.5, 0.0)), "road")
    for x in (-6.0, 8.0):
        add(geo.merge(*[geo.box((x - 1.5, y, 0.0), (x + 1.5, y + 0.5, 0.01)) for y in np.arange(-3.25, 3.25, 1.0)]),
            "crosswalk")
    ramps = {"north": [-6.0, 8.0], "south": [8.0]}
    for side, y_kerb, y_back in (("north", 3.5, 6.5), ("south", -3.5, -6.5)):
        sgn = 1 if y_back > y_kerb else -1
        cuts = sorted(ramps[side])
        start = -20.0
        for g in cuts + [None]:
            end = 20.0 if g is None else g - 1.0
            add(geo.box((start, *sorted((y_kerb, y_back))[:1], -0.3), (end, sorted((y_kerb, y_back))[1], 0.15)),
                "sidewalk")
            if g is not None:
                lo, hi = sorted((y_kerb + sgn * 1.8, y_back))
                add(geo.box((g - 1.0, lo, -0.3), (g + 1.0, hi, 0.15)), "sidewalk")
                low, high = (y_kerb, y_kerb + sgn * 1.8)
                add(geo.ramp(g - 1.0, g + 1.0, low, high, 0.005, 0.15, -0.3), "curb_ramp")
                start = g + 1.0
    verts, faces = geo.merge(*parts)
    return verts, faces, np.array(classes, object)



def crossing_network():
    """(grid, graph) of :func:`crossing_scene` with 0.5 m cells."""
    grid = build_grid(*crossing_scene(), cell_m=0.5)
    return grid, walkable_graph(grid)


def route(graph, grid, profile, a, b):
    return shortest_path(graph, grid.cell_of(*a), grid.cell_of(*b), PROFILES[profile])


def corridor_plans(rng, graph, grid, n):
    return plan_agents(rng, graph, grid, n, aid_share=0.4, min_route_m=5.0)

