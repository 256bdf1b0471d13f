"""A randomised scene's devices and hair: a seeded draw reaches every model of every aid class and every hair
style and colour, and the model and the hair are drawn without shifting any other draw of the scene (adding
a model, or switching hair off, changes nothing else)."""

from __future__ import annotations

import dataclasses

import numpy as np

from synthua_usd.assets.devices import DEVICE_MODELS
from synthua_usd.assets.hair import HAIR_STYLES
from synthua_usd.model.materials import HAIR_COLOURS
from synthua_usd.randomisation import scene
from synthua_usd.randomisation.config import CrowdRandomisation, HairRandomisation, RandomisationConfig
from synthua_usd.randomisation.scene import draw_cast

CONFIG = RandomisationConfig(crowd=CrowdRandomisation(density_per_m2=(0.05, 0.05), aid_share=(0.9, 0.9)))


def _cast(seed: int):
    return draw_cast(np.random.default_rng(seed), CONFIG, 4000.0, [])[2]


def test_a_seeded_draw_reaches_every_model_of_every_class():
    cast = _cast(7)
    drawn = {(m.aid, m.device.model) for m in cast if m.device is not None}
    assert drawn == {(aid, model) for aid, models in DEVICE_MODELS.items() for model in models}
    assert [m.device for m in _cast(7)] == [m.device for m in cast]  # a function of the seed


def test_the_model_draw_shifts_no_other_draw(monkeypatch):
    cast = _cast(3)
    monkeypatch.setattr(scene, "DEVICE_MODELS", {aid: {"standard": models["standard"]} for aid, models in DEVICE_MODELS.items()})
    standard = _cast(3)
    assert len(cast) == len(standard) > 100
    assert {m.device.model for m in standard if m.device} == {"standard"}
    assert {m.device.model for m in cast if m.device} == {"standard", "detailed"}
    same = [dataclasses.replace(m, device=dataclasses.replace(m.device, model="standard")) if m.device else m for m in cast]
    assert same == list(standard)


def test_a_seeded_draw_reaches_every_hair_style_and_colour():
    cast = _cast(7)
    assert {m.hair.style for m in cast} == set(HAIR_STYLES)
    assert {m.hair.colour for m in cast if m.hair.style != "none"} == set(HAIR_COLOURS)
    for m in cast:
        assert (m.hair.base_color is None) == (m.hair.style == "none")
    narrow = dataclasses.replace(CONFIG, hair=HairRandomisation(styles=("long",), colours=("auburn",)))
    assert {(m.hair.style, m.hair.colour) for m in draw_cast(np.random.default_rng(7), narrow, 4000.0, [])[2]} == \
        {("long", "auburn")}


def test_the_hair_draw_shifts_no_other_draw():
    """Hair off (or narrowed) draws the same cast, less the hair, as hair on: its stream is a child's."""
    on = _cast(3)
    off = draw_cast(np.random.default_rng(3), dataclasses.replace(CONFIG, hair=HairRandomisation(enabled=False)),
                    4000.0, [])[2]
    assert all(m.hair is None for m in off)
    assert [dataclasses.replace(m, hair=None) for m in on] == list(off)
    bald = dataclasses.replace(CONFIG, hair=HairRandomisation(styles=("none",)))
    assert [dataclasses.replace(m, hair=None) for m in draw_cast(np.random.default_rng(3), bald, 4000.0, [])[2]] == list(off)
