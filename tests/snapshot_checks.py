"""Comparing scene snapshots in tests: what a carried reader (or a randomised stage) gives against a fresh read."""

from __future__ import annotations

import numpy as np


def assert_same_snapshot(carried, fresh) -> None:
    """Two snapshots hold the same meshes (paths, points bit for bit, triangles, uvs, materials, labels), the
    same materials for them, instances, lights and keypoints."""
    assert [m.prim_path for m in carried.meshes] == [m.prim_path for m in fresh.meshes]
    for a, b in zip(carried.meshes, fresh.meshes):
        assert np.array_equal(a.points, b.points) and np.array_equal(a.triangles, b.triangles), a.prim_path
        assert (a.material_key, a.instance_id, a.class_id, a.lamp, a.double_sided) == \
            (b.material_key, b.instance_id, b.class_id, b.lamp, b.double_sided), a.prim_path
        assert (a.uvs is None) == (b.uvs is None) and (a.uvs is None or np.array_equal(a.uvs, b.uvs))
    used = {m.material_key for m in fresh.meshes}
    assert {k: carried.materials[k] for k in used} == {k: fresh.materials[k] for k in used}
    assert carried.instances == fresh.instances
    assert carried.lights == fresh.lights
    assert sorted(carried.keypoints) == sorted(fresh.keypoints)
    for k in carried.keypoints:
        assert np.array_equal(carried.keypoints[k].points, fresh.keypoints[k].points)
