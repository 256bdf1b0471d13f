"""Polygon meshes as triangles, and their texture coordinates (``primvars:st`` and the like) and authored normals
per point.

USD meshes hold polygons (``faceVertexCounts``, ``faceVertexIndices``); a renderer wants triangles whose
corners index points. Texture coordinates come per point (``vertex``/``varying`` interpolation) or per face
corner (``faceVarying``, the usual export of DCC tools: a seam is two corners of one point with different
coordinates). Per-corner coordinates become per-point ones by splitting a point wherever its corners
disagree, and only there, so triangles stay valid and geometry stays the same: every triangle keeps its
three positions, and the label pass, which sees only geometry, is unaffected. Authored normals (``normals`` or
``primvars:normals``) are read and split alike; a mesh without them is shaded flat.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from pxr import Usd, UsdGeom

from synthua_usd.model.meshes import split_corners

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


def corner_uvs(prim: Usd.Prim, t: Usd.TimeCode, name: str, indices: np.ndarray, corners: np.ndarray,
               point_count: int) -> "MeshData | None":
    """The mesh ``prim``'s texture coordinates from primvar ``name`` (:class:`MeshData`: per corner of its triangles
    ``corners``, :func:`fan_corners`, for face-varying ones; per point, ``point_count`` of them, for the others;
    ``indices`` is its faceVertexIndices). None, after one warning naming the prim, when the primvar is absent, not
    two numbers per element, of another interpolation, or of the wrong length."""
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
    return _per_corner(data, interpolation, indices, corners, point_count, where,
                       "rendering the material's constants")


def corner_normals(prim: Usd.Prim, t: Usd.TimeCode, indices: np.ndarray, corners: np.ndarray,
                   point_count: int) -> "MeshData | None":
    """The mesh ``prim``'s authored normals (``primvars:normals``, else ``normals``) as unit vectors in the prim's
    space, per corner or per point as :func:`corner_uvs` gives texture coordinates; None when none are authored,
    or, after one warning naming the prim, when they are not finite non-zero triples of a supported interpolation and length
    (the mesh is then shaded flat, as without them)."""
    primvar = UsdGeom.PrimvarsAPI(prim).GetPrimvar("normals")
    if primvar and primvar.HasValue():
        values, interpolation, where = primvar.ComputeFlattened(t), primvar.GetInterpolation(), "primvars:normals"
    else:
        mesh = UsdGeom.Mesh(prim)
        attr = mesh.GetNormalsAttr()
        if not attr or not attr.HasAuthoredValue():
            return None
        values, interpolation, where = attr.Get(t), mesh.GetNormalsInterpolation(), "normals"
    where = f"{prim.GetPath()}: {where}"
    data = np.asarray(values, np.float64) if values is not None else np.zeros((0,))
    lengths = np.linalg.norm(data, axis=-1) if data.ndim == 2 else np.zeros(0)
    if data.ndim != 2 or data.shape[1] != 3 or not np.all(np.isfinite(data)) or not np.all(lengths > 1e-12):
        found = (f"an array of shape {data.shape}" if data.ndim != 2 or data.shape[1] != 3
                 else "zero or non-finite vectors")
        log.warning("%s holds %s; expected finite non-zero triples (normal3f); shading it flat", where, found)
        return None
    return _per_corner(data / lengths[:, None], interpolation, indices, corners, point_count, where, "shading it flat")


def _per_corner(data: np.ndarray, interpolation: str, indices: np.ndarray, corners: np.ndarray, point_count: int,
                where: str, otherwise: str) -> "MeshData | None":
    """``data`` (k, c) of a primvar-like attribute of ``interpolation`` as :class:`MeshData`."""
    if interpolation not in INTERPOLATIONS:
        log.warning("%s has interpolation '%s'; supported: %s; %s", where, interpolation, ", ".join(INTERPOLATIONS),
                    otherwise)
        return None
    if interpolation == UsdGeom.Tokens.faceVarying:
        if len(data) != len(indices):
            log.warning("%s has %d face-varying values for %d face corners; %s", where, len(data), len(indices),
                        otherwise)
            return None
        return MeshData(data[corners].astype(np.float32))
    if len(data) != point_count:
        log.warning("%s has %d %s values for %d points; %s", where, len(data), interpolation, point_count, otherwise)
        return None
    return MeshData(data.astype(np.float32), per_point=True)


@dataclass(frozen=True, eq=False)
class MeshData:
    """Values of a primvar-like attribute of a mesh: ``values`` (n, c) float32 per point when ``per_point``
    (``vertex``/``varying`` interpolation), else (m, 3, c) per triangle corner (``faceVarying``)."""

    values: np.ndarray
    per_point: bool = False


def split_attributes(points: np.ndarray, triangles: np.ndarray, *data: MeshData | None
                     ) -> tuple[np.ndarray, np.ndarray, list[np.ndarray | None]]:
    """(points, triangles, per-point arrays) from ``data`` (each :class:`MeshData` or None) of the mesh ``points``
    (n, 3), ``triangles`` (m, 3): when any is per corner, points are split where the corners of one point
    disagree in any of them (:func:`synthua_usd.model.meshes.split_corners`), and only there; else the mesh stays
    as it is (every point, in its order)."""
    present = [d for d in data if d is not None]
    if all(d.per_point for d in present):
        return points, triangles, [None if d is None else d.values for d in data]
    corners = [d.values[triangles] if d.per_point else d.values for d in present]
    points, triangles, joined = split_corners(points, triangles, np.concatenate(corners, axis=2))
    out, at = [], 0
    for d in data:
        if d is None:
            out.append(None)
            continue
        width = d.values.shape[-1]
        out.append(joined[:, at:at + width])
        at += width
    return points, triangles, out
