"""Render settings: a frozen dataclass that refuses bad values and unknown keys, and the order its sources settle in."""

import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.model.render_config import RenderConfig, resolve_render


def test_render_config_refuses_bad_values():
    with pytest.raises(InputError, match="spp should be an integer in 1..65536, but was 0"):
        RenderConfig(spp=0)
    with pytest.raises(InputError, match=r"unknown keys \['colour'\]"):
        RenderConfig.from_dict({"colour": 1})


def test_round_trips_through_a_dict():
    config = RenderConfig(width=64, height=48, spp=4, seed=3, variant="scalar_rgb")
    assert RenderConfig.from_dict(config.to_dict()) == config


def test_resolve_render_takes_each_field_from_the_strongest_source_that_sets_it():
    """RenderConfig's defaults < the stage's UsdRender settings < the config's render block < the command line;
    None leaves a field to the weaker sources."""
    assert resolve_render() == RenderConfig()
    stage = {"width": 640, "height": 480, "spp": 3}
    assert resolve_render(stage=stage) == RenderConfig(width=640, height=480, spp=3)
    config = {"width": 320, "height": None, "spp": None, "max_depth": 4}
    assert resolve_render(stage=stage, config=config) == RenderConfig(width=320, height=480, spp=3, max_depth=4)
    options = {"spp": 7, "height": None, "seed": 2, "variant": "scalar_rgb"}
    assert resolve_render(stage=stage, config=config, options=options) == RenderConfig(
        width=320, height=480, spp=7, max_depth=4, seed=2, variant="scalar_rgb")
    assert resolve_render(stage={"width": None, "height": None, "spp": None}) == RenderConfig()


def test_resolve_render_refuses_unknown_fields_and_bad_values():
    with pytest.raises(InputError, match=r"unknown keys \['colour'\]"):
        resolve_render(options={"colour": 1})
    with pytest.raises(InputError, match="spp should be an integer in 1..65536, but was 0"):
        resolve_render(config={"spp": 0})
