"""Scenarios as plain data: checked when made, layers in one strength order."""

import pytest

from synthua_usd.composition.scenario import LAYER_FILE, LAYERS, ScenarioSpec, StageMetadata
from synthua_usd.core.errors import InputError
from synthua_usd.model.cameras import CameraSpec
from synthua_usd.model.twin import TwinModel

EMPTY = TwinModel(objects=(), materials={}, source="test")
CAM = CameraSpec("Cam", (0.0, -5.0, 1.5), (0.0, 0.0, 1.0), 24.0, 36.0, 24.0, "a test camera")


def spec(**kw):
    args = dict(doc="test", metadata=StageMetadata(), twin=EMPTY, cameras=(CAM,), render_camera="Cam")
    args.update(kw)
    return ScenarioSpec(**args)


def test_layers_strongest_first_heavy_ones_binary():
    assert [role for role, _ in LAYERS] == ["render", "environment", "cameras", "agents", "semantics", "twin"]
    assert {name for _, name in LAYERS if name.endswith(".usdc")} == {LAYER_FILE["twin"], LAYER_FILE["agents"]}


def test_a_scenario_without_crowd_has_no_agents_layer():
    assert spec().layer_files() == ("render.usda", "environment.usda", "cameras.usda", "semantics.usda", "twin.usdc")
    assert spec().render_camera_path == "/World/Cameras/Cam"


@pytest.mark.parametrize("kw,text", [
    (dict(cameras=(CAM, CAM)), "scenario cameras should have unique names, but were ['Cam', 'Cam']"),
    (dict(render_camera="Nope"), "render camera 'Nope' is not one of the scenario's cameras ['Cam']"),
    (dict(outputs=("rgb", "normals")), "render vars ['normals'] are not outputs synthua writes"),
])
def test_bad_scenarios_are_refused_with_the_value(kw, text):
    with pytest.raises(InputError) as err:
        spec(**kw)
    assert text in str(err.value)


@pytest.mark.parametrize("kw,text", [
    (dict(up_axis="X"), "upAxis should be 'Y' or 'Z', but was 'X'"),
    (dict(meters_per_unit=0.0), "meters_per_unit should be a finite number > 0, but was 0.0"),
    (dict(start_time_code=10.0, end_time_code=1.0), "time codes should satisfy start <= end, but were [10.0, 1.0]"),
])
def test_bad_metadata_is_refused_with_the_value(kw, text):
    with pytest.raises(InputError) as err:
        StageMetadata(**kw)
    assert text in str(err.value)


def test_time_code_count_includes_both_ends():
    assert StageMetadata(start_time_code=1.0, end_time_code=48.0).time_code_count == 48
