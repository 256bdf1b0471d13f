"""A randomised scene's devices and hair: a seeded draw reaches every model of every aid class and every hair
style and colour, and the model and the hair are drawn without shifting any other draw of the scene (adding
a model, or switching hair off, changes nothing else)."""

from __future__ import annotations

import dataclasses

import numpy as np

from synthua_usd.assets.devices import DEVICE_MODELS
from synthua_usd.assets.hair import HAIR_STYLES
from synthua_usd.model.materials import HAIR_COLOURS, STREET_SHIRTS
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


def test_companions_push_chairs_and_walk_beside_aid_users():
    """Shares of 1: every manual wheelchair user with room left in the cast is pushed by an adult pedestrian (at
    least 1.5 m tall, holding that user's chair fit), every other aid user walks with 1-2 pedestrians; shares of
    0: nobody does. Companions count among the Poisson number of people and share their aid user's group."""
    from synthua_usd.assets.bodies import load_bank
    from synthua_usd.assets.postures import fit_device
    from synthua_usd.randomisation.scene import PUSHER_MIN_HEIGHT_M

    bank = load_bank()
    every = dataclasses.replace(CONFIG, crowd=dataclasses.replace(CONFIG.crowd, pushed_share=(1.0, 1.0),
                                                                  accompanied_share=(1.0, 1.0)))
    cast = draw_cast(np.random.default_rng(5), every, 4000.0, [])[2]
    pushed = [k for k, m in enumerate(cast) if m.pushed_by is not None]
    assert len(pushed) >= 3
    for k, m in enumerate(cast):
        if m.aid is not None and k < len(cast) - 1:  # the last one may have had no room left
            if m.aid == "manual_wheelchair":
                pusher = cast[m.pushed_by]
                assert m.pushed_by == k + 1 and pusher.pushes == k and pusher.profile == "pedestrian"
                assert bank.height_m[pusher.body] >= PUSHER_MIN_HEIGHT_M
                assert pusher.pushing == fit_device(bank, m.body, "manual_wheelchair")
                assert pusher.group == m.group is not None
            else:
                companions = [c for c in cast if c.accompanies == k]
                assert 1 <= len(companions) <= 2
                assert all(c.profile == "pedestrian" and c.group == m.group for c in companions)
    none = dataclasses.replace(CONFIG, crowd=dataclasses.replace(CONFIG.crowd, pushed_share=(0.0, 0.0),
                                                                 accompanied_share=(0.0, 0.0)))
    alone = draw_cast(np.random.default_rng(5), none, 4000.0, [])[2]
    assert not any(m.pushes is not None or m.accompanies is not None or m.pushed_by is not None for m in alone)
    assert abs(len(alone) - len(cast)) < 0.1 * len(cast)  # the same Poisson draw of people, companions among them


def test_devices_models_narrow_the_model_draw_and_shift_no_other_draw():
    """devices.models ["detailed"]: every device detailed, everything else as drawn with both models; the document
    leaves the field out while it is its default (datasets written before keep their generate.json and job key)."""
    cast = _cast(3)
    detailed_config = dataclasses.replace(CONFIG, devices=dataclasses.replace(CONFIG.devices, models=("detailed",)))
    detailed = draw_cast(np.random.default_rng(3), detailed_config, 4000.0, [])[2]
    assert len(detailed) == len(cast) > 100
    assert {m.device.model for m in detailed if m.device} == {"detailed"}
    same = [dataclasses.replace(m, device=dataclasses.replace(m.device, model="detailed")) if m.device else m for m in cast]
    assert same == list(detailed)
    assert "models" not in CONFIG.to_document()["devices"]
    assert detailed_config.to_document()["devices"]["models"] == ["detailed"]
    assert RandomisationConfig.from_document(detailed_config.to_document()) == detailed_config
    both = RandomisationConfig.from_document({"devices": {"models": ["standard", "detailed"]}})
    assert both.devices.models == ("detailed", "standard") and "models" not in both.to_document()["devices"]


def _near_palette(colour, palette, jitter: float) -> bool:
    """Whether ``colour`` is a colour of ``palette`` with each channel scaled by at most 1 +- ``jitter``."""
    return any(np.all(np.abs(np.asarray(colour) - c.base_color) <= jitter * np.asarray(c.base_color) + 1e-9)
               for c in palette)


def test_the_street_palette_and_long_clothes_change_the_clothes_only():
    """looks.palette street: every upper garment a street colour; long_sleeves and long_legs 1: every forearm and
    shin clothed; nothing else drawn differently; the document leaves the three fields out at their defaults."""
    cast = _cast(3)
    looks = dataclasses.replace(CONFIG.looks, palette="street", long_sleeves=1.0, long_legs=1.0)
    street = draw_cast(np.random.default_rng(3), dataclasses.replace(CONFIG, looks=looks), 4000.0, [])[2]
    jitter = CONFIG.crowd.clothing_jitter
    assert len(street) == len(cast) > 100
    assert all(_near_palette(m.upper, STREET_SHIRTS, jitter) for m in street)
    assert not all(_near_palette(m.upper, STREET_SHIRTS, jitter) for m in cast)
    assert all(m.long_sleeves and m.long_legs for m in street)
    assert 0.4 < np.mean([m.long_sleeves for m in cast]) < 0.8 and not all(m.long_legs for m in cast)
    blank = (0.0, 0.0, 0.0)
    assert [dataclasses.replace(m, upper=blank, long_sleeves=True, long_legs=True) for m in cast] == \
        [dataclasses.replace(m, upper=blank) for m in street]
    assert not {"palette", "long_sleeves", "long_legs"} & set(CONFIG.to_document()["looks"])
    document = dataclasses.replace(CONFIG, looks=looks).to_document()
    assert {k: document["looks"][k] for k in ("palette", "long_sleeves", "long_legs")} == \
        {"palette": "street", "long_sleeves": 1.0, "long_legs": 1.0}
    assert RandomisationConfig.from_document(document).looks == looks


def test_with_looks_off_the_clothes_fields_change_nothing():
    off = dataclasses.replace(CONFIG.looks, enabled=False)
    plain = draw_cast(np.random.default_rng(5), dataclasses.replace(CONFIG, looks=off), 4000.0, [])[2]
    asked = dataclasses.replace(off, palette="street", long_sleeves=1.0, long_legs=0.0)
    same = draw_cast(np.random.default_rng(5), dataclasses.replace(CONFIG, looks=asked), 4000.0, [])[2]
    assert list(same) == list(plain) and len(plain) > 100
