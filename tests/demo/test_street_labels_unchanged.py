"""The shipped demo street, now binary crate layers with instanced agents, renders the very label maps the
text layers of commit bb615bc rendered (class and instance ids at 320x240, every camera, time codes 1 and
24; recorded from those layers before the change)."""

import numpy as np
import pytest

from conftest import DATA, SCENARIO
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.errors import InputError
from synthua_usd.render_config import RenderConfig
from synthua_usd.usd.cameras import camera_paths, read_camera
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_io import open_stage

REFERENCE = DATA / "refs" / "street_labels_bb615bc.npz"


@pytest.mark.slow
def test_crate_street_labels_are_byte_identical_to_the_text_layers(class_map):
    assert SCENARIO.with_name("twin.usdc").exists() and not SCENARIO.with_name("twin.usda").exists()
    reference = np.load(REFERENCE)
    stage = open_stage(SCENARIO)
    reader = StageReader(stage, class_map)
    try:  # the reference was traced by llvm_ad_rgb; scalar's kd-tree may break float ties at edges otherwise
        session = RenderSession(RenderConfig(width=320, height=240, spp=1, variant="llvm_ad_rgb"))
    except InputError as exc:
        pytest.skip(f"llvm_ad_rgb cannot run here: {exc}")
    checked = 0
    for t in (1.0, 24.0):
        snapshot = reader.snapshot(t)
        for path in camera_paths(stage):
            frame = session.render(snapshot, read_camera(stage, path, t), rgb=False)
            old = reference[f"street|{t:g}|{path}".replace("/", "_")]
            assert np.array_equal(frame.class_ids, old[0]) and np.array_equal(frame.instance_ids, old[1]), (t, path)
            checked += 1
    assert checked == len(reference.files) == 6
