"""The one writer of scenarios: a :class:`ScenarioSpec` becomes its layer files and a ``scenario.usda``
root that sublayers them, strongest first, written as one set (nothing is replaced unless all is written)."""

from __future__ import annotations

from pathlib import Path

from pxr import Usd

from synthua_usd.composition.scenario import LAYER_FILE, ROOT_FILE, ScenarioSpec, StageMetadata
from synthua_usd.core.atomic import output_set
from synthua_usd.core.texture_images import write_texture_images
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.model.twin import TwinModel
from synthua_usd.usd.agents_writer import build_agents_layer
from synthua_usd.usd.authoring import save_layer_atomic
from synthua_usd.usd.compose import compose_layers
from synthua_usd.usd.scenario_layers import build_camera_layer, build_environment, build_render_settings
from synthua_usd.usd.twin_writer import author_twin


def scenario_stages(spec: ScenarioSpec, class_map: ClassMap) -> dict[str, Usd.Stage]:
    """Every layer of ``spec`` as an in-memory stage, by file name, strongest first."""
    meta = spec.metadata
    twin, semantics = author_twin(spec.twin, class_map, meta)
    stages = {
        "render": build_render_settings(meta, spec.render_camera_path, spec.render, spec.outputs),
        "environment": build_environment(meta, spec.environment),
        "cameras": build_camera_layer(meta, spec.cameras, f"{spec.doc}: cameras with physical lens values."),
        "agents": build_agents_layer(spec.crowd, meta, class_map.taxonomy) if spec.crowd is not None else None,
        "semantics": semantics,
        "twin": twin,
    }
    return {LAYER_FILE[role]: stage for role, stage in stages.items() if stage is not None}


def write_scenario(spec: ScenarioSpec, out_dir: str | Path, class_map: ClassMap | None = None,
                   dataset_part: bool = False) -> list[Path]:
    """Write every layer of ``spec`` and ``scenario.usda`` into ``out_dir``; returns the final paths.

    Files of ``out_dir`` that are not part of the scenario are left alone. ``dataset_part``: ``out_dir`` is a part
    of the dataset being generated (a randomised scene's scenario, :func:`synthua_usd.core.atomic.output_set`)."""
    class_map = class_map or ClassMap.default()
    out_dir = Path(out_dir)
    stages = scenario_stages(spec, class_map)
    names = list(stages) + [ROOT_FILE]
    with output_set(out_dir, dataset_part=dataset_part) as staging:
        for name, stage in stages.items():
            save_layer_atomic(stage.GetRootLayer(), staging / name)
        names += [str(p.relative_to(staging)) for p in write_texture_images(spec.twin.images, staging)]
        compose_layers(staging / ROOT_FILE, [staging / name for name in stages], doc=f"{spec.doc} scenario.")
    return [out_dir / name for name in names]


def write_twin_layers(model: TwinModel, out_dir: str | Path, class_map: ClassMap, meta: StageMetadata) -> list[Path]:
    """Only the twin and semantics layers of ``model`` (no scenario root), written as one set."""
    twin, semantics = author_twin(model, class_map, meta)
    out_dir = Path(out_dir)
    names = (LAYER_FILE["twin"], LAYER_FILE["semantics"])
    with output_set(out_dir) as staging:
        for name, stage in zip(names, (twin, semantics)):
            save_layer_atomic(stage.GetRootLayer(), staging / name)
        images = [str(p.relative_to(staging)) for p in write_texture_images(model.images, staging)]
    return [out_dir / name for name in (*names, *images)]
