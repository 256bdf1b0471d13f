"""Render settings: a frozen dataclass that refuses bad values and unknown keys."""

import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.model.render_config import RenderConfig


def test_render_config_refuses_bad_values():
    with pytest.raises(InputError, match="spp should be an integer in 1..65536, but was 0"):
        RenderConfig(spp=0)
    with pytest.raises(InputError, match=r"unknown keys \['colour'\]"):
        RenderConfig.from_dict({"colour": 1})


def test_round_trips_through_a_dict():
    config = RenderConfig(width=64, height=48, spp=4, seed=3, variant="scalar_rgb")
    assert RenderConfig.from_dict(config.to_dict()) == config
