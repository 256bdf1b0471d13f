"""The stated limits of the importers: ranges of their parameters and of the numbers and sizes they read.

Kept apart from the importer modules so that the command line can build its options from them without
loading trimesh, laspy or pymeshlab. Each limit says why it is where it is.
"""

from __future__ import annotations

from synthua_usd.core.input_files import MiB
from synthua_usd.model.ranges import Range

# --- parameters --------------------------------------------------------------------------------------------

#: mesh: file units to metres (micrometres to kilometres, with room on both sides).
SCALE = Range(1e-6, 1e6)
#: pointcloud: largest Hausdorff distance simplification may introduce; 10 µm is below any scanner's noise.
MAX_DEVIATION = Range(1e-5, 10, "m")
#: pointcloud: RANSAC inlier distance; below 0.1 mm no plane of a real scan has inliers, above 10 m
#: everything is one plane.
PLANE_THRESHOLD = Range(1e-4, 10, "m")
#: pointcloud: bound on the 95th percentile of a segment's point-to-surface distances before it is a finding;
#: 1 mm is below any scanner's noise, 100 m explains nothing.
MAX_RESIDUAL = Range(1e-3, 100, "m")
#: pointcloud: the same bound for a tree's convex hull, whose points lie inside it (trunk, branches, the far
#: side of the crown), so that the depth of a crown is no finding but a hull around empty space is.
MAX_HULL_RESIDUAL = Range(1e-3, 100, "m")
#: footprints, osm: metres per level when a building gives levels; by default 3 m, a common storey of homes and
#: offices (floor to floor), which the levels x storey estimates of OSM 3-D renderers also use.
STOREY_HEIGHT = Range(1, 20, "m")
DEFAULT_STOREY_HEIGHT_M = 3.0
#: footprints, osm: the height of a building that states none; by default two storeys.
DEFAULT_HEIGHT = Range(1, 1000, "m")
DEFAULT_HEIGHT_M = 2 * DEFAULT_STOREY_HEIGHT_M

# --- numbers read from files ---------------------------------------------------------------------------------

#: Largest horizontal or vertical extent of one import; the twin is stored in 32-bit floats around a local
#: origin, which at 1,000 km still resolves 6 cm.
MAX_EXTENT_M = 1_000_000.0
#: Building heights above ground (the tallest building is 828 m), and the least a block may rise above its
#: min_height: 10 cm (an extrusion thinner than that is a digitising slip, and trimesh cannot extrude ~0).
HEIGHT = Range(0.1, 1000, "m")
MIN_BLOCK_HEIGHT_M = 0.1
MIN_HEIGHT = Range(0, 1000, "m")
LEVELS = Range(0, 300, low_open=True)
#: Levels of a roof, or skipped below a raised building part (OpenStreetMap's roof:levels, building:min_level).
ROOF_LEVELS = Range(0, 300)
#: Smallest footprint area: 10 cm x 10 cm; below it a polygon is a digitising slip, not a building.
MIN_FOOTPRINT_AREA_M2 = 0.01
#: CityJSON transform: scale of the integer vertices (metres per unit) and translation.
TRANSFORM_SCALE = Range(0, 1000, low_open=True)

# --- sizes ---------------------------------------------------------------------------------------------------

#: Mesh files: parsing takes several times the file's size in memory.
MAX_MESH_BYTES = 512 * MiB
#: OpenStreetMap extracts: a city's .osm.pbf is tens of MiB (its XML about ten times that); libosmium keeps
#: the node locations of the whole file in memory to assemble areas.
MAX_OSM_BYTES = 2048 * MiB
#: Point cloud files (LAS/LAZ/PLY).
MAX_POINTCLOUD_BYTES = 2048 * MiB
#: Points of one cloud: RANSAC, Delaunay and MeshLab's simplification work on all of them in memory.
MAX_POINTS = 20_000_000
#: Triangles of one mesh import.
MAX_TRIANGLES = 20_000_000
