"""Views framed as photographers frame aid users (issue 40: the ``framing`` part of the randomise block): the
camera a few metres from an aid user at an eye height, the user filling the drawn share of the frame height, as
the label pass measures it; CCTV views keep their rigs; off by default, and then nothing is drawn or recorded."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import SCENARIO
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.randomisation.config import RandomisationConfig
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.randomisation_layer import agent_path
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_io import open_stage

W, H = 160, 120


@pytest.fixture(scope="module")
def framed(class_map):
    from synthua_usd.pipeline.randomiser import Randomiser

    stage = open_stage(SCENARIO)
    config = RandomisationConfig.from_document({"seed": 4, "crowd": {"aid_share": [0.5, 0.7]},
                                                "framing": {"enabled": True, "share": 1.0}})
    randomiser = Randomiser(stage, config, class_map, (W, H))
    reader = StageReader(stage, class_map)
    session = RenderSession(RenderConfig(width=W, height=H, spp=1, denoise=False))
    views = []
    for seed in range(5):
        for camera_path in ("/World/Cameras/PedestrianEye", "/World/Cameras/CCTV"):
            drawn = randomiser.apply(seed, camera_path, 24.0, None)
            snapshot = reader.snapshot(24.0)
            camera = read_camera(stage, camera_path, 24.0)
            labels = session.render(snapshot, camera, rgb=False)
            views.append((camera_path, drawn, snapshot, camera, labels.instance_ids, randomiser))
    randomiser.close()
    return views


def test_an_eye_level_view_frames_an_aid_user_at_the_drawn_share_of_the_height(framed):
    checked = 0
    for camera_path, drawn, snapshot, camera, ids, randomiser in framed:
        framing = drawn.view.framing
        if camera_path.endswith("CCTV"):
            assert framing is None and "framing" not in drawn.to_dict()["view"]
            continue
        assert framing is not None, "an eye-level view with aid users placed is framed when share is 1"
        config = randomiser.config.framing
        assert config.distance_m[0] <= framing.distance_m <= config.distance_m[1]
        heights = config.seated_height_m if framing.seated else config.eye_height_m
        ground = randomiser.area.height_below(camera.origin + [0.0, 0.0, 0.01])
        assert heights[0] - 1e-6 <= camera.origin[2] - ground <= heights[1] + 1e-6
        assert np.allclose(camera.camera_to_world, np.array(framing.camera_to_world), atol=1e-5)
        # the user (its person and device) measured in the label pass fills the share asked, give or take what a
        # bank's standing height says of a person walking (bent knees) or of a device's push handles
        prefix = agent_path(framing.user) + "/"
        mask = np.isin(ids, [i.id for i in snapshot.instances if i.prim_path.startswith(prefix)])
        rows = np.flatnonzero(mask.any(axis=1))
        share = (rows[-1] - rows[0] + 1) / H
        assert abs(share - framing.height_share) <= 0.15 * framing.height_share + 2 / H, (share, framing)
        checked += 1
    assert checked == 5


def test_framing_is_off_by_default_and_leaves_the_document_as_before():
    config = RandomisationConfig()
    assert not config.framing.enabled and "framing" not in config.to_document()
    on = RandomisationConfig.from_document({"framing": {"enabled": True}})
    assert on.to_document()["framing"]["enabled"] and RandomisationConfig.from_document(on.to_document()) == on
