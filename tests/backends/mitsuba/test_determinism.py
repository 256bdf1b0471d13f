"""Same seed, same bytes: RGB with the box pixel filter is bit-identical between sessions, whatever a
session rendered before; with the Gaussian filter, the LLVM variant's splats race (see docs/rendering.md)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import DISTRICT, activate_variant
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.conditions import read_condition
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_io import open_stage

CAMERA = "/World/Cameras/CCTV_Largo"


@pytest.fixture(scope="module")
def district():
    stage = open_stage(DISTRICT / "scenario.usda")
    return stage, StageReader(stage, ClassMap.default())


def _render(district, warm_up: bool, seed: int | None, config_seed: int = 0, condition: str = "day_rain_fog"):
    stage, reader = district
    session = RenderSession(RenderConfig(width=96, height=72, spp=8, pixel_filter="box", seed=config_seed,
                                         variant="llvm_ad_rgb"))
    cond = read_condition(stage, condition)
    if warm_up:  # another time code, camera and condition first: the session updates instead of loading
        session.render(reader.snapshot(40.0), read_camera(stage, "/World/Cameras/CCTV_Street", 40.0),
                       condition=read_condition(stage, "clear_day"))
    return session.render(reader.snapshot(12.0), read_camera(stage, CAMERA, 12.0), condition=cond, seed=seed).rgb


def test_box_filter_rgb_is_bit_identical_after_updates(district):
    activate_variant("llvm_ad_rgb")
    fresh = _render(district, warm_up=False, seed=3)
    updated = _render(district, warm_up=True, seed=3)
    assert np.array_equal(fresh, updated)


def test_render_seed_replaces_the_config_seed(district):
    activate_variant("llvm_ad_rgb")
    by_argument = _render(district, warm_up=False, seed=5)
    by_config = _render(district, warm_up=False, seed=None, config_seed=5)
    other = _render(district, warm_up=False, seed=6)
    assert np.array_equal(by_argument, by_config)
    assert not np.array_equal(by_argument, other)
