"""A scenario written together with camera rigs aimed inside it: the job behind ``synthua create district``.

The scenario's layers are written into a staging folder, the rigs are placed in that staged scenario (they
aim at its own crowd, so they can only be placed once it exists), then ``rigs.usda`` and its report join
the layers, the render settings point at the chosen rig camera, and ``scenario.usda`` is composed again.
Everything moves into place together (:func:`synthua_usd.core.atomic.output_set`).
"""

from __future__ import annotations

import logging
from pathlib import Path

from synthua_usd.composition.rigs import AimedRigs
from synthua_usd.composition.scenario import CAMERAS_ROOT, LAYER_FILE, ROOT_FILE, ScenarioSpec
from synthua_usd.core.atomic import output_set
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline.camera_rigs import RigRequest, RigsResult, author_rigs
from synthua_usd.usd.authoring import save_layer_atomic
from synthua_usd.usd.compose import compose_layers
from synthua_usd.usd.scenario_layers import build_render_settings
from synthua_usd.usd.scenario_writer import write_scenario

log = logging.getLogger(__name__)

RIGS_FILE = "rigs.usda"


def write_scenario_with_rigs(spec: ScenarioSpec, aimed: AimedRigs, out_dir: str | Path,
                             class_map_path: Path | None = None) -> tuple[list[Path], RigsResult]:
    """Write ``spec`` and its aimed rigs into ``out_dir`` as one set; returns the final paths and the rigs'
    result (its report). A render camera that was rejected leaves the spec's own render camera in place."""
    out_dir = Path(out_dir)
    with output_set(out_dir) as staging:
        written = write_scenario(spec, staging, ClassMap.load_or_bundled(class_map_path))
        images = [str(p.relative_to(staging)) for p in written if p.parent != staging]
        result = author_rigs(RigRequest(stage_path=staging / ROOT_FILE, out_path=staging / RIGS_FILE, rigs=aimed.rigs,
                                        width=spec.render.width, height=spec.render.height,
                                        time_codes=aimed.time_codes, min_target_px=aimed.min_target_px,
                                        class_map_path=class_map_path))
        names = join_rigs(spec, staging, aimed, result.report)
    files = names + [result.report_path.name, ROOT_FILE] + images
    return [out_dir / n for n in files], result


def join_rigs(spec: ScenarioSpec, folder: Path, aimed: AimedRigs, report: dict) -> list[str]:
    """In a written scenario ``folder`` that holds ``rigs.usda``: point the render settings at the aimed render
    camera when ``report`` says it was written, and compose ``scenario.usda`` again with ``rigs.usda`` beside
    the cameras layer. Returns the layer file names, strongest first."""
    names = list(spec.layer_files())
    names.insert(names.index(LAYER_FILE["cameras"]), RIGS_FILE)
    written = {c["name"] for c in report["cameras"] if c["status"] == "written"}
    if aimed.render_camera in written:
        render = build_render_settings(spec.metadata, f"{CAMERAS_ROOT}/{aimed.render_camera}", spec.render,
                                       spec.outputs)
        save_layer_atomic(render.GetRootLayer(), folder / LAYER_FILE["render"])
    elif aimed.render_camera:
        log.warning("rig camera %s was not placed; the render settings keep %s", aimed.render_camera,
                    spec.render_camera_path)
    compose_layers(folder / ROOT_FILE, [folder / n for n in names], doc=f"{spec.doc} scenario.")
    return names
