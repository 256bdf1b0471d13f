"""Polygon meshes as triangles, and their texture coordinates (``primvars:st`` and the like) per point.

USD meshes hold polygons (``faceVertexCounts``, ``faceVertexIndices``); a renderer wants triangles whose
corners index points. Texture coordinates come per point (``vertex``/``varying`` interpolation) or per face
corner (``faceVarying``, the usual export of DCC tools: a seam is two corners of one point with different
coordinates). Per-corner coordinates become per-point ones by splitting a point wherever its corners
disagree, and only there, so triangles stay valid and geometry stays the same: every triangle keeps its
three positions, and the label pass, which sees only geometry, is unaffected.
"""

from __future__ import annotations

import logging

import numpy as np
from pxr import Usd, UsdGeom

from synthua_usd.geometry.uv import split_corners

log = logging.getLogger(__name__)

#: Interpolations of a texture-coordinate primvar that become per-point coordinates.
INTERPOLATIONS = (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying, UsdGeom.Tokens.faceVarying)


def fan_corners(counts: np.ndarray, holes: set[int] | frozenset[int] = frozenset()) -> tuple[np.ndarray, np.ndarray]:
    """Fan triangulation of polygons with ``counts`` corners each, skipping faces in ``holes`` and faces with
    fewer than 3 corners.

    Returns ``corners`` (m, 3) int64, positions in ``faceVertexIndices`` (so ``indices[corners]`` are the
    triangles' points and per-corner data is looked up the same way), and ``faces`` (m,) int64, the
    polygon each triangle came from.
    """
    counts = np.asarray(counts, np.int64)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]) if len(counts) else np.zeros(0, np.int64)
    per_face = np.maximum(counts - 2, 0)
    if holes:
        per_face[np.fromiter((h for h in holes if 0 <= h < len(counts)), np.int64)] = 0
    faces = np.repeat(np.arange(len(counts), dtype=np.int64), per_face)
    # k = 1 .. n-2 inside each face: the triangle (start, start + k, start + k + 1).
    first = np.repeat(np.cumsum(per_face) - per_face, per_face)
    k = np.arange(len(faces), dtype=np.int64) - first + 1
    s = starts[faces]
    return np.stack([s, s + k, s + k + 1], axis=1).reshape(-1, 3), faces


def read_uvs(prim: Usd.Prim, t: Usd.TimeCode, name: str, indices: np.ndarray, corners: np.ndarray,
             points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The mesh ``prim``'s texture coordinates from primvar ``name`` as (points, triangles, uvs): points
    (k, 3) (``points`` with some repeated where face-varying corners disagree), triangles (m, 3) int64 into
    them and uvs (k, 2) float32. ``indices`` is the mesh's faceVertexIndices and ``corners`` its triangles'
    corners (:func:`fan_corners`). Returns None, after one warning naming the prim, when the primvar is
    absent, not two numbers per element, of another interpolation, or of the wrong length."""
    primvar = UsdGeom.PrimvarsAPI(prim).GetPrimvar(name)
    where = f"{prim.GetPath()}: primvars:{name}"
    if not primvar or not primvar.HasValue():
        log.warning("%s is missing; its material's textures need it, rendering the material's constants", where)
        return None
    values = primvar.ComputeFlattened(t)
    data = np.asarray(values, np.float64) if values is not None else np.zeros((0,))
    interpolation = primvar.GetInterpolation()
    if data.ndim != 2 or data.shape[1] != 2 or not np.all(np.isfinite(data)):
        log.warning("%s holds %s; expected finite pairs (float2/texCoord2f); rendering the material's constants",
                    where, f"an array of shape {data.shape}")
        return None
    if interpolation not in INTERPOLATIONS:
        log.warning("%s has interpolation '%s'; supported: %s; rendering the material's constants", where,
                    interpolation, ", ".join(INTERPOLATIONS))
        return None
    triangles = indices[corners]
    if interpolation == UsdGeom.Tokens.faceVarying:
        if len(data) != len(indices):
            log.warning("%s has %d face-varying values for %d face corners; rendering the material's constants",
                        where, len(data), len(indices))
            return None
        return split_corners(points, triangles, data[corners].astype(np.float32))
    if len(data) != len(points):
        log.warning("%s has %d %s values for %d points; rendering the material's constants", where, len(data),
                    interpolation, len(points))
        return None
    return points, triangles, data.astype(np.float32)
