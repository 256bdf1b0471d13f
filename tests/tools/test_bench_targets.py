"""tools/bench_targets.py: ratios and the markdown table it prints (the benchmark itself is not a test)."""

import sys

import pytest

from conftest import REPO, load_tool


@pytest.fixture(scope="module")
def bench():
    return load_tool("bench_targets.py", "bench_targets")


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


@pytest.mark.slow
def test_a_tiny_run_measures_every_mitsuba_row(tmp_path):
    """The benchmark end to end at 64x48 without Cycles and the pipeline: every Mitsuba row is measured (a
    change of the render API it calls shows here, not only in the next full run)."""
    import json
    import subprocess

    out = tmp_path / "bench.json"
    proc = subprocess.run([sys.executable, str(REPO / "tools" / "bench_targets.py"), "--width", "64", "--height", "48",
                           "--reference-spp", "8", "--repeat", "1", "--denoise-spps", "2", "--skip-cycles",
                           "--skip-pipeline", "--json", str(out)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    rows = {row["measure"].split(" (")[0]: row for row in json.loads(out.read_text())["rows"]}
    for measure in ("label pass", "RGB 16 spp", "first load", "per-frame update, next time code",
                    "per-frame update, another camera"):
        assert measure in rows and rows[measure]["value"] not in ("", "-"), (measure, sorted(rows))
    assert any(name.startswith("RGB denoised") and "dB" in row["value"] for name, row in rows.items())
    assert "dB" in rows["RGB at the default quality"]["value"]
    assert rows["per-frame update, next time code, against a default-quality frame"]["ratio"].endswith("%")
