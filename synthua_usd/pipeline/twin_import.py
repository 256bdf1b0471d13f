"""Writing an imported twin: its layers with a generated ground, automatic cameras framed on what is there, and
``import_report.json``, as one set (a failed import leaves an earlier import in the folder untouched).

Each automatic camera's label pass is rendered (exact pixel-centre labels, :data:`CHECK_SIZE`) on the written
scenario; a camera whose pixels show less than :data:`MIN_LABELLED_SHARE` of the twin's labelled geometry (the
generated ground is unlabelled and does not count) is a finding in the report; so is a camera that could not be
placed in free space outdoors (:mod:`synthua_usd.geometry.free_space`), with the reason.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from synthua_usd.agents.crowd import Crowd, CrowdParams, populate_crowd
from synthua_usd.composition.scenario import CAMERAS_ROOT, ROOT_FILE, ScenarioSpec, StageMetadata
from synthua_usd.core.atomic import output_set, write_json_atomic
from synthua_usd.core.findings import Finding, Severity
from synthua_usd.core.input_guard import Inputs
from synthua_usd.geometry.framing import Framing, automatic_cameras
from synthua_usd.geometry.ground import ground_object
from synthua_usd.model.materials import subset
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.model.twin import TwinModel
from synthua_usd.usd.scenario_writer import write_scenario

REPORT_FILE = "import_report.json"
#: Imports are static: one time code.
IMPORT_METADATA = StageMetadata(start_time_code=1, end_time_code=1)
#: The least share of an automatic camera's pixels that must show labelled geometry of the twin.
MIN_LABELLED_SHARE = 0.10
#: Size of the label pass that checks it (pixels).
CHECK_SIZE = (160, 120)


def with_ground(model: TwinModel) -> TwinModel:
    """``model`` with its generated ground (:func:`synthua_usd.geometry.ground.ground_object`) as its last object."""
    ground = ground_object(model)
    objects = (*model.objects, ground)
    materials = {**model.materials, **subset(p.material for p in ground.parts)}
    return dataclasses.replace(model, objects=objects, materials=materials)


#: Where imported twins' people walk by default: CityJSON and photogrammetry roads often include their
#: sidewalks, so roads count.
IMPORT_WALKABLE = ("sidewalk", "crosswalk", "curb_ramp", "street_road", "road")


def populated(model: TwinModel, params: CrowdParams) -> Crowd:
    """A crowd on ``model``'s walkable surfaces (its objects' triangles and classes; the generated ground is
    unlabelled, so nobody walks there)."""
    verts, faces, names, n = [], [], [], 0
    for obj in model.objects:
        for part in obj.parts:
            verts.append(part.points)
            faces.append(part.triangles + n)
            names += [obj.label] * len(part.triangles)
            n += len(part.points)
    return populate_crowd(np.concatenate(verts), np.concatenate(faces), np.array(names, object), params)


def import_scenario(model: TwinModel, crowd: CrowdParams | None = None) -> tuple[ScenarioSpec, Framing]:
    """The twin on its generated ground with automatic ``Overview`` and ``Street`` cameras, a clear day and
    default render settings, and with ``crowd`` people walking on it (time codes 1 to ``crowd.time_codes``);
    and how the cameras were framed."""
    grounded = with_ground(model)
    framing = automatic_cameras(model, grounded.objects[-1])
    people = populated(grounded, crowd) if crowd is not None else None
    metadata = IMPORT_METADATA if crowd is None else StageMetadata(
        start_time_code=1, end_time_code=crowd.time_codes, time_codes_per_second=crowd.time_codes_per_second)
    spec = ScenarioSpec(doc=f"synthua twin imported from {model.source}", metadata=metadata, twin=grounded,
                        cameras=framing.cameras, render_camera="Overview", crowd=people)
    return spec, framing


def labelled_shares(scenario: Path, class_map: ClassMap, cameras: list[str]) -> dict[str, float]:
    """Camera name → share of its pixel-centre label pass (:data:`CHECK_SIZE`) that hits labelled geometry."""
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    stage = open_stage(scenario)
    time_code = stage.GetStartTimeCode()
    snapshot = StageReader(stage, class_map).snapshot(time_code)
    session = RenderSession(RenderConfig(width=CHECK_SIZE[0], height=CHECK_SIZE[1], spp=1, denoise=False))
    class_of = np.zeros(max((i.id for i in snapshot.instances), default=0) + 1, np.int64)
    for inst in snapshot.instances:
        class_of[inst.id] = inst.class_id
    shares = {}
    for name in cameras:
        ids = session.quick_labels(snapshot, read_camera(stage, f"{CAMERAS_ROOT}/{name}", time_code))
        shares[name] = float(np.mean(class_of[ids] != 0))
    return shares


def write_import(model: TwinModel, out_dir: str | Path, class_map: ClassMap, report: dict,
                 crowd: CrowdParams | None = None, inputs: Inputs | None = None) -> tuple[list[Path], dict]:
    """Write the scenario of ``model`` (with ``crowd`` people when given) and ``report`` (completed with the
    ground, the cameras' framing and label-pass shares, the population, and their findings) into
    ``out_dir``, none of the files one of the command's ``inputs``; returns the final paths and the report."""
    out_dir = Path(out_dir)
    spec, framing = import_scenario(model, crowd)
    with output_set(out_dir, inputs=inputs) as staging:
        written = write_scenario(spec, staging, class_map)
        shares = labelled_shares(staging / ROOT_FILE, class_map, [c.name for c in spec.cameras])
        findings = list(report.get("findings", []))
        for name in shares:
            placement = framing.report[name.lower()]["placement"]
            if not placement["free_space"]:
                findings.append(Finding(
                    "camera-placement", f"{CAMERAS_ROOT}/{name}",
                    f"no spot in free space outdoors was found for it: {placement['reason']} (move it with "
                    f"'synthua cameras' or author your own)", Severity.WARNING).to_dict())
        for name, share in shares.items():
            if share < MIN_LABELLED_SHARE:
                findings.append(Finding(
                    "camera-coverage", f"{CAMERAS_ROOT}/{name}",
                    f"its label pass shows the twin in {share:.1%} of its pixels; expected at least "
                    f"{MIN_LABELLED_SHARE:.0%} (move it with 'synthua cameras' or author your own)",
                    Severity.WARNING).to_dict())
        ground = spec.twin.objects[-1]
        report = {**report, "ground": {"path": ground.path, **ground.attributes},
                  "cameras": {name: {**framing.report[name.lower()], "labelled_share": share,
                                     "min_labelled_share": MIN_LABELLED_SHARE} for name, share in shares.items()},
                  "findings": findings}
        if spec.crowd is not None:
            report["population"] = {k: v if isinstance(v, (dict, int)) else float(v)
                                    for k, v in spec.crowd.report.items()}
        write_json_atomic(staging / REPORT_FILE, report)
    return [out_dir / p.relative_to(staging) for p in written] + [out_dir / REPORT_FILE], report
