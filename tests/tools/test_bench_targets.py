"""tools/bench_targets.py: ratios and the markdown table it prints (the benchmark itself is not a test)."""

import importlib.util
import sys

import pytest

from conftest import REPO


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_targets", REPO / "tools" / "bench_targets.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_ratios(bench):
    assert bench.ratio(0.09, 0.06) == "1.50x"
    assert bench.ratio(3.0, 1.0, nd=0) == "3x"
    assert bench.ratio(0.1, 2.0, "%", 1) == "5.0 %"
    assert bench.ratio(1.0, 0.0) == bench.ratio(None, 1.0) == "-"


def test_markdown_table_has_one_line_per_row_and_escapes_pipes(bench):
    rows = [bench.Row("label pass", "0.060 s", "raw bound 0.050 s", bench.ratio(0.06, 0.05), "<= 1.5x",
                      bench.verdict(True)),
            bench.Row("a|b", "x")]
    lines = bench.markdown_table(rows).splitlines()
    assert lines[0] == "| measure | value | against | ratio | target | status |"
    assert lines[1] == "|---|---|---|---|---|---|"
    assert lines[2] == "| label pass | 0.060 s | raw bound 0.050 s | 1.20x | <= 1.5x | met |"
    assert lines[3] == "| a\\|b | x |  |  |  |  |"
    assert bench.verdict(False, "0.6x") == "NOT met (0.6x)" and bench.verdict(None) == "n/a"
