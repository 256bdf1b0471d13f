"""``synthua generate --executor ray``: the same bytes as the local pool, and an unreachable head refused before
anything is written."""

from __future__ import annotations

import pytest

from conftest import SCENARIO, TINY_CONFIG, generate_dataset
from dataset_runs import tree_bytes
from hostile import assert_refused, run_synthua


@pytest.mark.slow
def test_ray_executor_gives_the_same_bytes(generated, tmp_path):
    pytest.importorskip("ray")
    out = tmp_path / "ray"
    generate_dataset(out, executor="ray", workers=1)
    assert tree_bytes(out) == tree_bytes(generated)


def test_unreachable_ray_head_is_refused_before_anything_is_written(tmp_path):
    pytest.importorskip("ray")
    out = tmp_path / "out"
    result = run_synthua("generate", SCENARIO, "--config", TINY_CONFIG, "--out", out, "--executor", "ray",
                         "--address", "127.0.0.1:9")
    assert_refused(result, "--address", "127.0.0.1:9")
    assert result.seconds < 30 and not out.exists()


@pytest.mark.slow
def test_a_randomised_job_on_two_ray_workers_gives_the_local_pools_bytes(generated_random, tmp_path):
    """Issue 39: the randomised street job (its view scores and its images) on a Ray instance of two worker actors
    writes what the local pool wrote, file for file."""
    pytest.importorskip("ray")
    from conftest import RANDOM_CONFIG

    out = tmp_path / "ray"
    generate_dataset(out, config=RANDOM_CONFIG, executor="ray", workers=2)
    assert tree_bytes(out) == tree_bytes(generated_random)
