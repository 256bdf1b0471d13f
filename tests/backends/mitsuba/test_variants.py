"""Choosing the Mitsuba variant: named variants are checked, never guessed."""

import pytest

from synthua_usd.backends.mitsuba import variants
from synthua_usd.core.errors import InputError


def test_unknown_variant_is_an_input_error():
    with pytest.raises(InputError, match="variant 'teapot_rgb' is not in this Mitsuba build"):
        variants.activate("teapot_rgb")
    with pytest.raises(InputError, match="not an RGB variant"):
        variants.activate("scalar_spectral")


def test_a_named_variant_is_the_one_set(variant):
    assert variants.activate(variant).variant() == variant


def test_llvm_older_than_the_minimum_is_refused_with_a_way_out(monkeypatch):
    monkeypatch.setattr(variants, "MIN_LLVM", (999, 0, 0))
    with pytest.raises(InputError, match=r"variant 'llvm_ad_rgb' cannot run here .* try scalar_rgb"):
        variants.activate("llvm_ad_rgb")
