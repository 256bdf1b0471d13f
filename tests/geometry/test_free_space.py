"""Free space round a camera's eye, against boxes whose inside and outside are known."""

import numpy as np
import pytest
import trimesh

from synthua_usd.geometry.free_space import MIN_FREE_VIEW_M, check_eyes
from synthua_usd.model.meshes import box, merge


def _mesh(*meshes):
    return trimesh.Trimesh(*merge(*meshes), process=False)


HOUSE = box((0, 0, 0), (10, 10, 8))
GROUND = (np.array([[-100, -100, 0], [100, -100, 0], [100, 100, 0], [-100, 100, 0]], float),
          np.array([[0, 1, 2], [0, 2, 3]]))


def test_inside_a_closed_house_is_not_free_outside_it_is():
    mesh = _mesh(HOUSE, GROUND)
    inside, street, facing = check_eyes(mesh, np.array([[5, 5, 1.6], [-10, 5, 1.6], [-3, 5, 1.6]]),
                                        np.array([[1, 0, 0], [0, 1, 0], [1, 0, -0.05]]))
    assert inside.inside_share == 1.0 and not inside.ok and "inside a closed surface" in inside.reason
    assert street.ok and street.inside_share == 0.0 and street.open_sky and street.clearance_m == pytest.approx(1.6)
    assert not facing.ok and facing.free_view_m == pytest.approx(3.0, abs=0.01) and 3.0 < MIN_FREE_VIEW_M
    assert "blocked 3.0 m ahead" in facing.reason


def test_a_house_without_its_floor_still_encloses_and_a_canopy_covers():
    walls_and_roof = (HOUSE[0], HOUSE[1][np.abs(trimesh.Trimesh(*HOUSE, process=False).face_normals[:, 2] + 1) > 1e-6])
    canopy = box((20, 0, 3), (30, 10, 3.2))
    inside, under = check_eyes(_mesh(walls_and_roof, canopy, GROUND), np.array([[5, 5, 1.6], [25, 5, 1.6]]),
                               np.array([[1, 0, 0], [1, 0, 0]]))
    assert not inside.ok and inside.inside_share == 1.0
    assert under.inside_share == 0.0 and not under.open_sky and "under a roof" in under.reason
    assert check_eyes(_mesh(canopy), np.array([[25, 5, 1.6]]), np.array([[1, 0, 0]]), need_sky=False)[0].ok


def test_a_wall_too_close():
    (near,) = check_eyes(_mesh(HOUSE, GROUND), np.array([[-0.1, 5, 1.6]]), np.array([[-1, 0, 0]]))
    assert near.clearance_m == pytest.approx(0.1, abs=0.01) and "0.10 m from it" in near.reason
