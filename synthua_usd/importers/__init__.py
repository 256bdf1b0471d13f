"""Importers: real city data → :class:`synthua_usd.model.twin.TwinModel` (plain data; no USD, no renderer).

Each importer module parses and validates one kind of input and returns a TwinModel; it never writes
files. :func:`importers` maps the kind names of ``synthua twin import KIND`` to them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable

if TYPE_CHECKING:  # the twin module pulls in trimesh; the CLI imports this package at start-up
    from synthua_usd.model.twin import TwinModel

Importer = Callable[..., "TwinModel"]


def importers() -> dict[str, Importer]:
    """Kind name → importer function. The modules are imported on first use: each pulls in heavy
    libraries of its own (laspy, pymeshlab, pyproj, shapely, osmium) that other commands need not load."""
    from synthua_usd.importers import cityjson, footprints, mesh, osm, pointcloud

    return {"mesh": mesh.import_mesh, "cityjson": cityjson.import_cityjson,
            "pointcloud": pointcloud.import_pointcloud, "footprints": footprints.import_footprints,
            "osm": osm.import_osm}
