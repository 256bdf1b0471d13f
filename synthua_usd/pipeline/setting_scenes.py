"""A procedural setting (:mod:`synthua_usd.demo.settings`) written as a complete scenario for a dataset's scenario:
what a randomised scene in that setting renders.

The setting scenario has the dataset scenario's stage metadata (axes, units, time codes), its conditions (indoors
without their weather: :func:`synthua_usd.model.conditions.indoors`), its render settings (camera, resolution,
samples) and every one of its cameras at the same prim path, with the same rig type and filmback (the focal length
its rig type's lens starts at), placed in the setting (:func:`synthua_usd.demo.settings.layout.setting_cameras`); the twin and semantics are the setting's own, with
their textures. It has no crowd of its own: the randomised crowd is placed on its walkable floors. Everything is
authored by the one scenario writer (:func:`synthua_usd.usd.scenario_writer.write_scenario`).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from synthua_usd.composition.scenario import CAMERAS_ROOT, ROOT_FILE, Environment, ScenarioSpec
from synthua_usd.core.errors import InputError
from synthua_usd.model.cameras import CameraSpec
from synthua_usd.model.conditions import indoors
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.taxonomy import ClassMap


def setting_spec(scenario: Path, kind: str, variant: int) -> ScenarioSpec:
    """The scenario of the setting ``kind`` / ``variant`` for the dataset scenario ``scenario`` (see the module's
    docstring); an :class:`InputError` when a camera of ``scenario`` is not under ``/World/Cameras``."""
    from synthua_usd.composition.scenario import SHIPPED_ENVIRONMENT
    from synthua_usd.demo.settings import build_setting
    from synthua_usd.demo.settings.layout import setting_cameras
    from synthua_usd.usd.cameras import camera_paths, camera_rig_type, read_camera
    from synthua_usd.usd.conditions import condition_names, read_condition, selected_condition
    from synthua_usd.usd.render_settings import render_defaults
    from synthua_usd.usd.stage_io import open_stage, stage_metadata

    stage = open_stage(scenario, allow_external_assets=True)
    meta = replace(stage_metadata(stage), default_prim="World")  # a setting's scenario is rooted at /World
    t = meta.start_time_code
    if meta.up_axis != "Z" or meta.meters_per_unit != 1.0:
        raise InputError(f"{scenario}: randomise.settings builds Z-up scenes in metres; this scenario is "
                         f"{meta.up_axis}-up at {meta.meters_per_unit:g} m per unit; expected upAxis Z, metersPerUnit 1")
    wanted = []
    for path in camera_paths(stage):
        parent, _, name = path.rpartition("/")
        if parent != CAMERAS_ROOT:
            raise InputError(f"{scenario}: camera {path} is not under {CAMERAS_ROOT}; expected the scenario's cameras "
                             f"there (randomise.settings places each of them in the setting at its own path)")
        cam = read_camera(stage, path, t)
        wanted.append(CameraSpec(name, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), cam.focal_length_mm,
                                 cam.horizontal_aperture_mm, cam.vertical_aperture_mm,
                                 stage.GetPrimAtPath(path).GetDocumentation(), cam.clip_near_m, cam.clip_far_m,
                                 camera_rig_type(stage, path)))
    if not wanted:
        raise InputError(f"{scenario}: has no cameras; expected a scenario with at least one UsdGeom.Camera")
    names = condition_names(stage)
    if names:
        conditions = tuple(read_condition(stage, n) for n in names)
        environment = Environment(conditions, selected_condition(stage) or names[0])
    else:
        environment = SHIPPED_ENVIRONMENT
    setting = build_setting(kind, variant)
    if setting.indoor:
        environment = Environment(tuple(indoors(c) for c in environment.conditions), environment.default)
    defaults = render_defaults(stage)
    render = RenderConfig(**{k: v for k, v in defaults.render_values().items() if v is not None})
    render_camera = (defaults.camera_path or "").rpartition("/")[2]
    cameras = setting_cameras(setting.layout, wanted)
    return ScenarioSpec(doc=f"{setting.twin.source} for {Path(scenario).name}", metadata=meta, twin=setting.twin,
                        cameras=cameras, render_camera=render_camera if render_camera in {c.name for c in cameras}
                        else cameras[0].name, environment=environment, render=render)


def write_setting_scene(scenario: Path, kind: str, variant: int, out_dir: Path, class_map: ClassMap,
                        dataset_part: bool = False) -> Path:
    """Write the setting ``kind`` / ``variant`` for ``scenario`` into ``out_dir`` as one output set (kept when
    ``out_dir`` holds it already) and return its ``scenario.usda``; ``dataset_part``: ``out_dir`` is in the scenes
    folder of the dataset being generated."""
    from synthua_usd.usd.scenario_writer import write_scenario

    out_dir = Path(out_dir)
    if (out_dir / ROOT_FILE).is_file():
        return out_dir / ROOT_FILE
    write_scenario(setting_spec(scenario, kind, variant), out_dir, class_map, dataset_part=dataset_part)
    return out_dir / ROOT_FILE
