"""`synthua create`: the shipped scenarios written from the library code."""

from pxr import Sdf

from conftest import STAGES
from layer_match import mismatch
from synthua_usd.composition.rigs import RigSpec
from synthua_usd.composition.scenario import ROOT_FILE
from synthua_usd.demo import district
from synthua_usd.demo.street import street_scenario


def test_create_street_writes_the_committed_stages(run_cli, tmp_path):
    code, out, _ = run_cli("create", "street", tmp_path)
    assert code == 0
    names = street_scenario().layer_files() + (ROOT_FILE,)
    assert out.splitlines() == [f"wrote {tmp_path / n}" for n in names]
    assert [m for m in (mismatch(tmp_path / n, STAGES / n) for n in names) if m] == []


def test_create_district_passes_the_seed_and_aims_its_rigs(run_cli, tmp_path, monkeypatch):
    # The command's wiring only (the district itself is tested in tests/demo): a cheap scenario and one cheap
    # rig stand in.
    seeds = []
    monkeypatch.setattr(district, "district_scenario", lambda seed: seeds.append(seed) or street_scenario())
    monkeypatch.setattr(district, "DISTRICT_RIGS", (RigSpec("uav_nadir", name="Above", aim="crossing"),))
    monkeypatch.setattr(district, "DISTRICT_RIG_TIME_CODES", (1.0,))
    monkeypatch.setattr(district, "DISTRICT_RENDER_RIG", "Above")
    code, out, _ = run_cli("create", "district", tmp_path / "d", "--seed", "3")
    assert code == 0 and seeds == [3]
    assert (tmp_path / "d" / ROOT_FILE).exists() and f"wrote {tmp_path / 'd' / ROOT_FILE}" in out
    assert "Above" in out and (tmp_path / "d" / "rigs.report.json").exists()
    root = Sdf.Layer.FindOrOpen(str(tmp_path / "d" / ROOT_FILE))
    assert "rigs.usda" in root.subLayerPaths
    assert "</World/Cameras/Above>" in (tmp_path / "d" / "render.usda").read_text()
