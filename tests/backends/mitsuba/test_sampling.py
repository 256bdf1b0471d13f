"""The RGB passes' sampler: every pass asks for a count the multi-jittered sampler draws exactly, and its samples
are stratified, which an edge crossing a pixel shows against its exact coverage."""

import math

import numpy as np
import pytest

from synthua_usd.backends.mitsuba import variants
from synthua_usd.backends.mitsuba.render import render_rgb
from synthua_usd.backends.mitsuba.translate import (MAX_SPP_PER_PASS, film_dict, pass_sample_counts, sampler_dict,
                                                    takes_exactly)
from synthua_usd.model.render_config import RenderConfig


def test_pass_counts_add_up_and_are_drawn_exactly(variant):
    mi = variants.activate(variant)
    for spp in list(range(1, 70)) + [128, 512, 1000]:
        counts = pass_sample_counts(spp)
        assert sum(counts) == spp and max(counts) <= MAX_SPP_PER_PASS
        for n in set(counts):
            sampler = mi.load_dict(sampler_dict(RenderConfig(spp=n)))
            assert sampler.sample_count() == n, (spp, counts)
    # what Mitsuba rounds, takes_exactly says it does not take
    for n in range(1, 40):
        drawn = mi.load_dict({"type": "multijitter", "sample_count": n}).sample_count()
        assert takes_exactly(n) == (drawn == n), n
    assert pass_sample_counts(8) == [8] and pass_sample_counts(40) == [16, 16, 8] and pass_sample_counts(5) == [4, 1]


def _edge_scene(mi, config: RenderConfig, edge_x: float) -> dict:
    """A camera 1 m above a plane looking straight down (90° horizontal field of view: x in [-1, 1] m spans the
    image) and an emitter of radiance 1 covering x < ``edge_x`` on the plane; nothing else gives light."""
    half = 5.0
    emitter = {"type": "rectangle", "emitter": {"type": "area", "radiance": {"type": "rgb", "value": 1.0}},
               "to_world": mi.ScalarTransform4f().translate([(edge_x - half) / 2, 0.0, 0.0])
               @ mi.ScalarTransform4f().scale([(edge_x + half) / 2, half, 1.0])}
    sensor = {"type": "perspective", "fov": 90.0, "fov_axis": "x", "near_clip": 0.01, "far_clip": 10.0,
              "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 1], target=[0, 0, 0], up=[0, 1, 0]),
              "film": film_dict(config), "sampler": sampler_dict(config)}
    return {"type": "scene", "integrator": {"type": "path", "max_depth": 2}, "sensor": sensor, "quad": emitter}


@pytest.mark.parametrize("spp", [8, 16])
def test_an_edge_in_a_pixel_is_covered_within_one_stratum(variant, spp):
    """Each row's edge pixel is covered by a known share (the edge at column 10.3 from whichever side is lit);
    the sampler stratifies x into ``spp`` strata (n-rooks), so every row's estimate is within 1/spp of it.
    Independent samples miss that bound in most rows (standard deviation sqrt(p(1-p)/spp) = 0.16 at 8 spp)."""
    mi = variants.activate(variant)
    width, height = 32, 48
    config = RenderConfig(width=width, height=height, spp=spp, pixel_filter="box", denoise=False, seed=3)
    column = 10.3
    edge_x = -1.0 + 2.0 * column / width  # world x of image column 10.3 when +x runs left to right
    image = render_rgb(mi, mi.load_dict(_edge_scene(mi, config, edge_x)), config).rgb[..., 0]
    # Should the image run x the other way, the edge is at column 21.7 with the lit side right; mirrored back,
    # column 10 of it is that column 21, lit over its last 0.3 as well.
    flipped = image[:, 0].mean() < 0.5
    if flipped:
        image = image[:, ::-1]
    k, lit = math.floor(column), column - math.floor(column)
    assert np.all(image[:, :k] == 1.0) and np.all(image[:, k + 1:] == 0.0)
    errors = np.abs(image[:, k] - lit)
    assert errors.max() <= 1.0 / spp + 1e-6, (errors.max(), lit)
    # the same rows with independent samples: most of them miss the bound (the test can fail)
    independent = dict(_edge_scene(mi, config, edge_x))
    independent["sensor"] = dict(independent["sensor"], sampler={"type": "independent", "sample_count": spp})
    plain = render_rgb(mi, mi.load_dict(independent), config).rgb[..., 0]
    plain = plain[:, ::-1] if flipped else plain
    assert np.mean(np.abs(plain[:, k] - lit) > 1.0 / spp + 1e-6) > 0.2
