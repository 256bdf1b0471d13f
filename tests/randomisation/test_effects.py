"""The draw of an image's camera effects (synthua_usd/randomisation/effects.py): probabilities and ranges kept
(frequencies against the binomial, the focus distance's log-uniform median), one effect's settings moving no other
effect's draw, the record's round trip, the ``effects`` stream of its own, and the config's refusals."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from synthua_usd.core.errors import InputError
from synthua_usd.core.schemas import schema_errors
from synthua_usd.dataset.config import GenerationConfig
from synthua_usd.randomisation.config import EFFECTS, EffectsRandomisation, RandomisationConfig
from synthua_usd.randomisation.effects import EffectsDraw, draw_effects, draw_image_effects

ALL = EffectsRandomisation(enabled=True, **{f"{e}_probability": 1.0 for e in EFFECTS})


def _draws(config: EffectsRandomisation, n: int, seed: int = 0) -> list[EffectsDraw]:
    return [draw_effects(np.random.default_rng([seed, k]), config) for k in range(n)]


def test_each_effect_applies_with_its_probability_and_stays_in_its_ranges():
    """2,000 draws at the default probabilities: each effect's share within 4 binomial standard deviations; every
    value within its range (quality a whole number); the focus distance log-uniform (median the geometric mean of
    its ends)."""
    config = EffectsRandomisation(enabled=True)
    n = 2000
    draws = _draws(config, n)
    for effect in EFFECTS:
        p = getattr(config, f"{effect}_probability")
        share = sum(getattr(d, effect) is not None for d in draws) / n
        assert abs(share - p) <= 4 * math.sqrt(p * (1 - p) / n) + 1e-12, (effect, share, p)

    def within(values, bounds):
        return all(bounds[0] <= v <= bounds[1] for v in values)

    taken = lambda name: [getattr(d, name) for d in draws if getattr(d, name) is not None]  # noqa: E731
    defocus, blur, noise = taken("defocus"), taken("motion_blur"), taken("noise")
    assert within([d.focus_m for d in defocus], config.focus_m)
    assert within([d.radius_width_share for d in defocus], config.defocus_radius_width_share)
    median = float(np.median([d.focus_m for d in defocus]))
    assert median == pytest.approx(math.sqrt(config.focus_m[0] * config.focus_m[1]), rel=0.15)
    assert within([b.length_width_share for b in blur], config.motion_blur_length_width_share)
    assert within([b.angle_deg for b in blur], (0.0, 180.0))
    assert within([v.corner_loss for v in taken("vignetting")], config.vignetting_corner_loss)
    assert within([x.ev for x in taken("exposure")], config.exposure_ev)
    assert within([x.shot_gain for x in noise], config.noise_shot_gain)
    assert within([x.read_sigma for x in noise], config.noise_read_sigma)
    assert len({x.seed for x in noise}) == len(noise)
    gains = [g for w in taken("white_balance") for g in (w.red_gain, w.blue_gain)]
    assert within(gains, config.white_balance_gain)
    qualities = [j.quality for j in taken("jpeg")]
    assert within(qualities, config.jpeg_quality) and all(isinstance(q, int) for q in qualities)
    assert set(qualities) == set(range(config.jpeg_quality[0], config.jpeg_quality[1] + 1))


def test_one_effects_settings_move_no_other_effects_draw():
    base = _draws(ALL, 50)
    for change in ({"defocus_probability": 0.0}, {"motion_blur_length_width_share": (0.05, 0.06)},
                   {"jpeg_probability": 0.0, "noise_read_sigma": (0.0, 0.0)}):
        other = _draws(replace(ALL, **change), 50)
        changed = {name.rsplit("_probability", 1)[0] for name in change} | {
            e for e in EFFECTS for name in change if name.startswith(e)}
        for a, b in zip(base, other):
            for effect in set(EFFECTS) - changed:
                assert getattr(a, effect) == getattr(b, effect), (change, effect)


def test_one_order_of_effects():
    from dataclasses import fields

    from synthua_usd.randomisation.effects import KINDS

    assert tuple(KINDS) == EFFECTS == tuple(f.name for f in fields(EffectsDraw))
    assert [f.name for f in fields(EffectsRandomisation) if f.name.endswith("_probability")] == \
        [f"{e}_probability" for e in EFFECTS]


def test_the_record_round_trips_and_refuses_what_it_cannot_read():
    draw = _draws(ALL, 1)[0]
    doc = draw.to_dict()
    assert list(doc) == list(EFFECTS) and all(v is not None for v in doc.values())
    assert EffectsDraw.from_dict(doc) == draw and EffectsDraw().to_dict() == dict.fromkeys(EFFECTS)
    assert EffectsDraw.from_dict(dict.fromkeys(EFFECTS)) == EffectsDraw()
    for bad, mentions in (({**doc, "bloom": None}, "unknown keys ['bloom']"),
                          ({**doc, "jpeg": {"quality": 80, "x": 1}}, "effects.jpeg"),
                          ({**doc, "exposure": {"ev": "bright"}}, "expected finite numbers"),
                          ({**doc, "exposure": {"ev": float("nan")}}, "expected finite numbers"),
                          ([1, 2], "expected an object")):
        with pytest.raises(InputError) as err:
            EffectsDraw.from_dict(bad, source="rec.json: randomisation.effects")
        assert mentions in str(err.value) and "\n" not in str(err.value)


def test_an_images_effects_come_from_a_stream_of_their_own():
    """Off or without a randomise block: none. On: the same image keys give the same draw; another camera, time code,
    condition or seed another; the scene's draws come from other streams (the effects stream's first numbers are not
    the scene's or the light's)."""
    on = RandomisationConfig(seed=4, effects=ALL)
    assert draw_image_effects(None, 1, "/World/Cam", 24, "clear_day") is None
    assert draw_image_effects(RandomisationConfig(seed=4), 1, "/World/Cam", 24, "clear_day") is None
    first = draw_image_effects(on, 1, "/World/Cam", 24, "clear_day")
    assert first == draw_image_effects(on, 1, "/World/Cam", 24.0, "clear_day")
    for args in ((2, "/World/Cam", 24, "clear_day"), (1, "/World/Other", 24, "clear_day"),
                 (1, "/World/Cam", 25, "clear_day"), (1, "/World/Cam", 24, "sunset"), (1, "/World/Cam", 24, None)):
        assert draw_image_effects(on, *args) != first, args
    from synthua_usd.randomisation.streams import stream

    effects = stream(4, 1, "effects", "/World/Cam", 24, "clear_day").random(4)
    for scope in ("scene", "view", "light"):
        assert not np.array_equal(stream(4, 1, scope, "/World/Cam", 24, "clear_day").random(4), effects)


def test_off_by_default_and_left_out_of_the_config_document_when_default():
    """A randomise block without effects keeps its document (and so its generate.json and job key) as before;
    with effects on they round-trip and the schema takes them."""
    plain = GenerationConfig.from_document({"name": "x", "images": 2, "randomise": {"seed": 3}})
    assert not plain.randomise.effects.enabled and "effects" not in plain.to_document()["randomise"]
    assert "effects" not in plain.randomise.enabled_parts
    doc = {"name": "x", "images": 2, "randomise": {"effects": {"enabled": True, "jpeg_quality": [70, 80],
                                                                "focus_m": [2, 2]}}}
    config = GenerationConfig.from_document(doc)
    assert config.randomise.effects.jpeg_quality == (70, 80) and config.randomise.effects.focus_m == (2.0, 2.0)
    assert config.to_document()["randomise"]["effects"]["enabled"] is True
    assert GenerationConfig.from_document(config.to_document()) == config
    assert "effects" in config.randomise.enabled_parts


@pytest.mark.parametrize("block, mentions", [
    ({"jpeg_quality": [60.5, 90]}, "randomise.effects.jpeg_quality: ['60.5', '90']; expected two whole numbers"),
    ({"jpeg_quality": [0, 90]}, "expected a range within [1, 100]"),
    ({"focus_m": [5, 2]}, "randomise.effects.focus_m: [5, 2]"),
    ({"focus_m": [0.01, 2]}, "expected a range within [0.1, 10000]"),
    ({"vignetting_corner_loss": [0.2, 1.0]}, "randomise.effects.vignetting_corner_loss"),
    ({"defocus_radius_width_share": [0, 0.2]}, "within [0, 0.05]"),
])
def test_impossible_effects_are_refused_in_one_line(block, mentions):
    with pytest.raises(InputError) as err:
        GenerationConfig.from_document({"name": "x", "images": 2, "randomise": {"effects": block}}, source="gen.json")
    message = str(err.value)
    assert mentions in message and message.startswith("gen.json") and "\n" not in message


def test_the_dataclass_refuses_what_the_schema_would():
    """Built in code (issue 45's compositing draws with its own config), not through a document."""
    with pytest.raises(InputError, match=r"effects.jpeg_probability: 1.5; expected a probability in \[0, 1\]"):
        EffectsRandomisation(jpeg_probability=1.5)
    with pytest.raises(InputError, match=r"effects.noise_read_sigma: \[0.2, 0.3\]"):
        EffectsRandomisation(noise_read_sigma=(0.2, 0.3))


def test_the_record_schema_takes_a_draw_and_refuses_a_stranger():
    draw = _draws(ALL, 1)[0].to_dict()
    assert schema_errors(draw, "record", "effects") == []
    assert schema_errors(EffectsDraw().to_dict(), "record", "effects") == []
    assert schema_errors({**draw, "bloom": None}, "record", "effects")
    assert schema_errors({**draw, "jpeg": {"quality": 101}}, "record", "effects")
    assert schema_errors({k: v for k, v in draw.items() if k != "noise"}, "record", "effects")
