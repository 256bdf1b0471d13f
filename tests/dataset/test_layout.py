"""The dataset layout: names from scene text are safe path components; nothing leaves the dataset folder."""

from __future__ import annotations

from pathlib import Path

import pytest

from synthua_usd.core.errors import OutputError
from synthua_usd.dataset.layout import Layout, cityscapes_city, image_name, inside, safe_component

HOSTILE = ["../../etc/passwd", "/abs/path", "a b\nc", "dot.dot..", "\x00nul", "C:\\win", "Câmera_Ω", "", "-", "…"]


@pytest.mark.parametrize("text", HOSTILE)
def test_safe_component_is_one_plain_component(text):
    out = safe_component(text)
    assert out and all(c.isascii() and (c.isalnum() or c == "-") for c in out)
    assert not out.startswith(("-", ".")) or out == "x"


@pytest.mark.parametrize("text", HOSTILE)
def test_image_names_are_plain_and_unique_by_id(text):
    a, b = image_name(1, text, 24.0, text, 0), image_name(2, text, 24.0, text, 0)
    assert a != b and "/" not in a and not a.startswith(".")
    assert inside(Path("/data"), Layout.rgb_png("train", a)).parent == Path("/data/images/train")


def test_time_codes_in_names_sort_and_keep_fractions():
    assert image_name(3, "Cam", 24.5, None, 2) == "000003_Cam_t0024p500_stage_s2"
    assert image_name(3, "Cam", 24, "clear_day", 0) == "000003_Cam_t0024_clear-day_s0"


@pytest.mark.parametrize("relative", ["../x", "a/../../x", "/etc/passwd", "a/.hidden", ".", "", "a\\b",
                                      "a/b\nc"])
def test_inside_refuses_paths_that_leave_or_hide(relative):
    with pytest.raises(OutputError):
        inside(Path("/data"), relative)


def test_cityscapes_city_has_no_underscores():
    assert cityscapes_city("demo_street-2") == "demostreet2"
    assert cityscapes_city("__") == "synthua"
