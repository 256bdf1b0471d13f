"""A randomised scene's devices: a seeded draw reaches every model of every aid class, and the model is
drawn without shifting any other draw of the scene (adding a model changes nothing else)."""

from __future__ import annotations

import dataclasses

import numpy as np

from synthua_usd.assets.devices import DEVICE_MODELS
from synthua_usd.randomisation import scene
from synthua_usd.randomisation.config import CrowdRandomisation, RandomisationConfig
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
