"""A scenario as plain data: its stage metadata, twin, agents, cameras, environment and render settings,
and the order in which its layers compose.

:func:`synthua_usd.usd.scenario_writer.write_scenario` is the one function that turns a
:class:`ScenarioSpec` into layer files and a ``scenario.usda`` root; the demo street, the demo district
and every importer's automatic scenario are specs handed to it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from synthua_usd.agents.crowd import Crowd
from synthua_usd.core.errors import InputError
from synthua_usd.core.outputs import OUTPUT_NAMES, select_outputs
from synthua_usd.model.cameras import CameraSpec
from synthua_usd.model.conditions import DEFAULT_CONDITION, SHIPPED, Condition
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.twin import TwinModel

#: Every layer a scenario may have, strongest first, with its file name. Heavy generated geometry is
#: binary crate (``.usdc``); the thin layers people review stay text (``.usda``).
LAYERS: tuple[tuple[str, str], ...] = (
    ("render", "render.usda"),
    ("environment", "environment.usda"),
    ("cameras", "cameras.usda"),
    ("agents", "agents.usdc"),
    ("semantics", "semantics.usda"),
    ("twin", "twin.usdc"),
)
LAYER_FILE = dict(LAYERS)
ROOT_FILE = "scenario.usda"
CAMERAS_ROOT = "/World/Cameras"
ENVIRONMENT_PATH = "/World/Environment"
#: Where a randomised image's scene lives (synthua_usd.usd.randomisation_layer): its crowd, its materials, the
#: crowd's prototypes.
RANDOM_ROOT = "/World/Randomisation"
CROWD_ROOT = f"{RANDOM_ROOT}/Crowd"


@dataclass(frozen=True)
class StageMetadata:
    """Metadata every synthua layer states explicitly (Z or Y up, metres per unit, time codes)."""

    up_axis: str = "Z"
    meters_per_unit: float = 1.0
    time_codes_per_second: float = 24.0
    start_time_code: float = 1.0
    end_time_code: float = 48.0
    default_prim: str = "World"

    def __post_init__(self) -> None:
        if self.up_axis not in ("Y", "Z"):
            raise InputError(f"upAxis should be 'Y' or 'Z', but was {self.up_axis!r}")
        for name in ("meters_per_unit", "time_codes_per_second"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise InputError(f"{name} should be a finite number > 0, but was {value!r}")
        if not (math.isfinite(self.start_time_code) and math.isfinite(self.end_time_code)
                and self.start_time_code <= self.end_time_code):
            raise InputError(f"time codes should satisfy start <= end, but were "
                             f"[{self.start_time_code}, {self.end_time_code}]")

    @property
    def time_code_count(self) -> int:
        """Integral time codes from start to end, both included."""
        return int(self.end_time_code - self.start_time_code) + 1


@dataclass(frozen=True)
class Environment:
    """The environment layer: the conditions a scenario offers (a ``condition`` variant set on
    ``/World/Environment``, see :mod:`synthua_usd.model.conditions`) and the one selected by default."""

    conditions: tuple[Condition, ...] = SHIPPED
    default: str = DEFAULT_CONDITION

    def __post_init__(self) -> None:
        names = [c.name for c in self.conditions]
        if not names or len(set(names)) != len(names):
            raise InputError(f"environment conditions should have unique names, but were {names}")
        if self.default not in names:
            raise InputError(f"default condition '{self.default}' is not one of {names}")


SHIPPED_ENVIRONMENT = Environment()


@dataclass(frozen=True, eq=False)
class ScenarioSpec:
    """Everything a scenario's layers hold.

    ``crowd`` is None for a scenario without an agents layer. ``render_camera``
    names the camera of ``cameras`` the render settings point at; ``render`` gives the resolution and
    samples per pixel they state; ``outputs`` the render vars (see :mod:`synthua_usd.core.outputs`).
    """

    doc: str
    metadata: StageMetadata
    twin: TwinModel
    cameras: tuple[CameraSpec, ...]
    render_camera: str
    crowd: Crowd | None = None
    environment: Environment = SHIPPED_ENVIRONMENT
    render: RenderConfig = field(default_factory=RenderConfig)
    outputs: tuple[str, ...] = OUTPUT_NAMES

    def __post_init__(self) -> None:
        names = [c.name for c in self.cameras]
        if len(set(names)) != len(names):
            raise InputError(f"scenario cameras should have unique names, but were {names}")
        if self.render_camera not in names:
            raise InputError(f"render camera '{self.render_camera}' is not one of the scenario's cameras {names}")
        select_outputs(self.outputs)

    @property
    def render_camera_path(self) -> str:
        return f"{CAMERAS_ROOT}/{self.render_camera}"

    def layer_files(self) -> tuple[str, ...]:
        """The file names of this scenario's layers, strongest first."""
        return tuple(name for role, name in LAYERS if role != "agents" or self.crowd is not None)
