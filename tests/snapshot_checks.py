"""Comparing scene snapshots in tests: what a carried reader (or a randomised stage) gives against a fresh read."""

from __future__ import annotations

import dataclasses
import hashlib
from pathlib import Path

import numpy as np


def _by_content(material):
    """``material`` with each texture's path replaced by its image's SHA-256: two copies of one image are the
    same texture (exported layers read copies of the package's look images)."""
    textures = {name: dataclasses.replace(t, path=hashlib.sha256(Path(t.path).read_bytes()).hexdigest())
                for name, t in material.textures.items()}
    return dataclasses.replace(material, **textures)


def assert_same_snapshot(carried, fresh) -> None:
    """Two snapshots hold the same meshes (paths, points bit for bit, triangles, uvs, normals, materials, labels),
    the same materials for them (textures by their images' content), instances, lights and keypoints."""
    assert [m.prim_path for m in carried.meshes] == [m.prim_path for m in fresh.meshes]
    for a, b in zip(carried.meshes, fresh.meshes):
        assert np.array_equal(a.points, b.points) and np.array_equal(a.triangles, b.triangles), a.prim_path
        assert (a.material_key, a.instance_id, a.class_id, a.lamp, a.double_sided) == \
            (b.material_key, b.instance_id, b.class_id, b.lamp, b.double_sided), a.prim_path
        assert (a.uvs is None) == (b.uvs is None) and (a.uvs is None or np.array_equal(a.uvs, b.uvs))
        assert (a.normals is None) == (b.normals is None)
        assert a.normals is None or np.array_equal(a.normals, b.normals)
    used = {m.material_key for m in fresh.meshes}
    assert {k: _by_content(carried.materials[k]) for k in used} == {k: _by_content(fresh.materials[k]) for k in used}
    assert carried.instances == fresh.instances
    assert carried.lights == fresh.lights
    assert sorted(carried.keypoints) == sorted(fresh.keypoints)
    for k in carried.keypoints:
        assert np.array_equal(carried.keypoints[k].points, fresh.keypoints[k].points)
