"""Hair made from the body mesh: a closed, outward-wound shell over the scalp, outside the head and within a few
centimetres of it, only above the neck, cheap in triangles; bald is no mesh."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from synthua_usd.assets.bodies import BONES, skin
from synthua_usd.assets.hair import HAIR_STYLES, STYLE_SHAPES
from synthua_usd.assets.postures import BodyParts

BODIES = (15, 0, 47, 55, 71)  # a child of 5, adults and two of the aid stratum


@pytest.fixture(scope="module")
def parts():
    return BodyParts()


@pytest.mark.parametrize("posture", [None, "manual_wheelchair", "walker"])
@pytest.mark.parametrize("style", [s for s in HAIR_STYLES if s != "none"])
def test_hair_is_a_closed_outward_shell_just_outside_the_head(parts, posture, style):
    bank = parts.bank
    for body in BODIES:
        _, base, _ = parts.get(body, posture)
        posed = skin(bank.points[body], bank, base.skinning(bank.joints[body]))
        points, triangles = parts.hair(body, posture, None, style)
        hair = trimesh.Trimesh(points, triangles, process=False)
        assert hair.is_watertight and hair.is_winding_consistent and hair.volume > 0, (body, style)
        assert len(triangles) < 3000
        person = trimesh.Trimesh(posed, bank.triangles, process=False)
        assert person.is_watertight
        surface = np.concatenate([points, hair.sample(2000, seed=body)])
        assert not person.contains(surface).any(), (body, style)
        gap = np.abs(trimesh.proximity.signed_distance(person, points))
        assert gap.min() >= 0.0009 and gap.max() <= STYLE_SHAPES[style][0] * 1.4 + 0.002, (body, style, gap.max())
        neck = base.joints[BONES.index("head"), 2]
        assert points[:, 2].min() > neck + 0.03, (body, style)


def test_bald_is_no_mesh_and_styles_differ(parts):
    assert parts.hair(3, None, None, "none") is None
    volumes = [trimesh.Trimesh(*parts.hair(3, None, None, s), process=False).volume for s in ("short", "medium", "long")]
    assert volumes == sorted(volumes) and volumes[0] > 0
    with pytest.raises(ValueError):
        parts.hair(3, None, None, "mohawk")
