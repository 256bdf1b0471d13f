"""Procedural settings written as scenarios for a dataset's scenario (the demo street): each passes
``synthua validate stage``, offers every camera of the scenario at its own path with its rig type and lens, its
conditions (indoors without weather) and time codes, and renders with exact labels (its label pass against an
independent Embree ray cast); a room is lit by its own lights at night."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import SCENARIO
from reference_raycast import reference_labels
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.conditions import indoors
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.pipeline.setting_scenes import write_setting_scene
from synthua_usd.randomisation.settings import INDOOR_KINDS, SETTING_KINDS
from synthua_usd.usd.cameras import camera_paths, camera_rig_type, read_camera
from synthua_usd.usd.conditions import condition_names, read_condition
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_checks import validate_stage
from synthua_usd.usd.stage_io import open_stage

W, H = 64, 48


@pytest.fixture(scope="module")
def street():
    return open_stage(SCENARIO)


@pytest.mark.parametrize("kind", SETTING_KINDS)
def test_a_setting_scenario_validates_and_renders_exact_labels(kind, street, class_map, tmp_path):
    scene = write_setting_scene(SCENARIO, kind, 1, tmp_path / kind, class_map)
    again = write_setting_scene(SCENARIO, kind, 1, tmp_path / "again", class_map)
    for path in sorted((tmp_path / kind).rglob("*")):
        if path.is_file():  # the same variant, the same bytes
            assert path.read_bytes() == (again.parent / path.relative_to(scene.parent)).read_bytes(), path.name
    stage = open_stage(scene)
    assert [f for f in validate_stage(stage, class_map) if f.severity == "error"] == []
    assert camera_paths(stage) == camera_paths(street)
    assert condition_names(stage) == condition_names(street)
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (street.GetStartTimeCode(), street.GetEndTimeCode())
    t = float(street.GetStartTimeCode())
    for path in camera_paths(street):
        assert camera_rig_type(stage, path) == camera_rig_type(street, path)
        mine, theirs = read_camera(stage, path, t), read_camera(street, path, t)
        assert (mine.focal_length_mm, mine.horizontal_aperture_mm) == (theirs.focal_length_mm, theirs.horizontal_aperture_mm)
    for name in condition_names(street):
        inside, outside = read_condition(stage, name), read_condition(street, name)
        assert inside == (indoors(outside) if kind in INDOOR_KINDS else outside)
    snapshot = StageReader(stage, class_map).snapshot(t)
    session = RenderSession(RenderConfig(width=W, height=H, spp=1))
    seen = set()
    for path in camera_paths(stage):
        camera = read_camera(stage, path, t)
        frame = session.render(snapshot, camera, rgb=False)
        ref_class, ref_inst = reference_labels(snapshot, camera, W, H)
        assert np.array_equal(ref_class, frame.class_ids) and np.array_equal(ref_inst, frame.instance_ids), path
        seen |= set(np.unique(frame.class_ids).tolist())
    assert class_map.resolve("sidewalk").id in seen  # the cameras see the floor people stand on


def test_a_room_is_lit_by_its_lights_by_day_and_at_night(class_map, tmp_path):
    """A room's ceiling lamps light it under any condition: the metered exposure of a day and of a night image is
    the same within the noise of 4 spp (measured 7.49 and 7.24: a room lit at some 20 cd/m² of mean surface
    luminance; a night street meters below 0), and no pixel is left black."""
    scene = write_setting_scene(SCENARIO, "clinic", 0, tmp_path / "clinic", class_map)
    stage = open_stage(scene)
    snapshot = StageReader(stage, class_map).snapshot(24.0)
    camera = read_camera(stage, "/World/Cameras/PedestrianEye", 24.0)
    session = RenderSession(RenderConfig(width=W, height=H, spp=4, denoise=False))
    ev = {}
    for name in ("clear_day", "clear_night"):
        frame = session.render(snapshot, camera, condition=read_condition(stage, name), seed=0)
        ev[name] = frame.exposure.ev100
        assert np.mean(frame.rgb.max(axis=2) <= 0) < 0.02, name
    assert ev["clear_day"] == pytest.approx(ev["clear_night"], abs=0.5) and 5.0 < ev["clear_night"] < 10.0, ev
