"""An independent label renderer for tests: Embree (through trimesh) casting rays that numpy computes
from the camera's lens values. Shares nothing with the Mitsuba path but the world-space triangles."""

from __future__ import annotations

import numpy as np
import trimesh


def reference_labels(snapshot, camera, width: int, height: int):
    """(class_ids, instance_ids) as (H, W) arrays from first hits of pixel-centre rays."""
    return labels_of_rays(snapshot, *camera.pixel_center_rays(width, height), width, height)


def labels_of_rays(snapshot, origins, dirs, width: int, height: int):
    """(class_ids, instance_ids) as (H, W) arrays from first hits of the rays (H*W, 3), row-major."""
    mesh_index = meshes_hit(snapshot, origins, dirs).reshape(height, width)
    class_of = np.array([0] + [m.class_id for m in snapshot.meshes])
    inst_of = np.array([0] + [m.instance_id for m in snapshot.meshes])
    return class_of[mesh_index + 1], inst_of[mesh_index + 1]


def meshes_hit(snapshot, origins, dirs):
    """(N,) index into ``snapshot.meshes`` of the first mesh each ray (N, 3) hits, -1 on a miss."""
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    verts, faces, owner = snapshot.world_triangles()
    mesh = trimesh.Trimesh(verts, faces, process=False, validate=False)
    tri = RayMeshIntersector(mesh).intersects_first(origins, dirs)
    return np.where(tri >= 0, owner[np.maximum(tri, 0)], -1)


def reference_z_depth(snapshot, camera, width: int, height: int):
    """(H, W) float64 z-depth of the first hit along each pixel-centre ray (0 on a miss), from Embree's hit
    locations: the hit's offset from the camera centre projected on the optical axis."""
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    verts, faces, _ = snapshot.world_triangles()
    mesh = trimesh.Trimesh(verts, faces, process=False, validate=False)
    origins, dirs = camera.pixel_center_rays(width, height)
    locations, ray_index, _ = RayMeshIntersector(mesh).intersects_location(origins, dirs, multiple_hits=False)
    _, _, forward = camera.axes()
    z = np.zeros(width * height)
    z[ray_index] = (locations - origins[ray_index]) @ forward
    return z.reshape(height, width)


def edge_distance(snapshot, instance_id: int, origin: np.ndarray, direction: np.ndarray) -> float:
    """Metres from the ray (origin, unit direction (3,)) to the nearest triangle edge of ``instance_id``'s
    meshes; inf for instance 0 (nothing)."""
    meshes = [m for m in snapshot.meshes if m.instance_id == instance_id]
    if not meshes:
        return np.inf
    verts, faces, _ = snapshot.world_triangles(meshes)
    best = np.inf
    for i, j in ((0, 1), (1, 2), (2, 0)):
        start = verts[faces[:, i]]
        edge = verts[faces[:, j]] - start
        w = start - origin
        ee, ed, wd, ew = np.einsum("ij,ij->i", edge, edge), edge @ direction, w @ direction, np.einsum("ij,ij->i", edge, w)
        s = np.clip((ed * wd - ew) / np.maximum(ee - ed * ed, 1e-18), 0.0, 1.0)   # along the edge
        t = np.maximum(wd + s * ed, 0.0)                                            # along the ray
        best = min(best, float(np.min(np.linalg.norm(origin + t[:, None] * direction - start - s[:, None] * edge, axis=1))))
    return best
