"""Scenario roots: sublayers written relative to the root, metadata stated once, disagreements refused."""

import pytest
from pxr import Sdf

from conftest import STAGES
from synthua_usd.core.errors import StageError
from synthua_usd.usd.compose import compose_layers


def test_compose_subset_writes_relative_sublayers(run_cli, tmp_path):
    out = tmp_path / "sub" / "mine.usda"
    code, stdout, _ = run_cli("compose", out, STAGES / "cameras.usda", STAGES / "twin.usdc", "--allow-external-assets")
    assert code == 0 and "2 sublayers" in stdout
    layer = Sdf.Layer.FindOrOpen(str(out))
    assert list(layer.subLayerPaths) == ["../../stages/cameras.usda", "../../stages/twin.usdc"] or \
        all(p.endswith(n) and not p.startswith("/") for p, n in zip(layer.subLayerPaths, ["cameras.usda", "twin.usdc"]))
    assert layer.pseudoRoot.GetInfo("metersPerUnit") == 1.0
    assert (layer.startTimeCode, layer.endTimeCode) == (1, 48)


def test_compose_refuses_layers_outside_the_scenarios_folder(run_cli, tmp_path):
    """A scenario reaching outside its folder is refused by validate, render and generate: compose says so
    when it would write one, and names the flag that accepts it."""
    out = tmp_path / "mine.usda"
    code, _, err = run_cli("compose", out, STAGES / "cameras.usda", STAGES / "twin.usdc")
    assert code == 2 and err.count("synthua: error:") == 1 and not out.exists()
    assert "cameras.usda: outside the scenario's folder" in err and "--allow-external-assets" in err
    inside = tmp_path / "layers"
    inside.mkdir()
    (inside / "tiny.usda").write_text(Sdf.Layer.FindOrOpen(str(STAGES / "cameras.usda")).ExportToString())
    assert run_cli("compose", out, inside / "tiny.usda")[0] == 0  # a sub-folder is inside
    code, _, err = run_cli("validate", "stage", out)  # findings of a cameras-only stage, but no refusal
    assert code in (0, 1) and "outside" not in err, err


def test_compose_missing_layer_exit_2_and_nothing_written(run_cli, tmp_path):
    out = tmp_path / "x.usda"
    code, _, err = run_cli("compose", out, STAGES / "twin.usdc", tmp_path / "nope.usda")
    assert code == 2 and "nope.usda: file not found" in err
    assert not out.exists()


def test_compose_refuses_disagreeing_units(tmp_path):
    cm = tmp_path / "cm.usda"
    layer = Sdf.Layer.CreateNew(str(cm))
    layer.pseudoRoot.SetInfo("metersPerUnit", 0.01)
    layer.Save()
    with pytest.raises(StageError, match="layers disagree on metersPerUnit"):
        compose_layers(tmp_path / "out.usda", [STAGES / "twin.usdc", cm])
