"""The demo district as layers: ``synthua twin demo`` writes its twin and semantics; ``write_district_scenario``
adds camera rigs, environment and render settings for the shipped scenario in ``stages/district``."""

from __future__ import annotations

from pathlib import Path

from synthua_usd.cameras import CameraRig
from synthua_usd.largo_district import PLAZA_Z, build_district, street_z
from synthua_usd.pipeline.populate import PopulateRequest, populate
from synthua_usd.taxonomy import ClassMap
from synthua_usd.usd.authoring import StageMetadata, save_layer_atomic
from synthua_usd.usd.compose import compose_layers
from synthua_usd.usd.scenario_layers import build_camera_layer, build_environment, build_render_settings
from synthua_usd.usd.twin_writer import write_twin

#: Persons per m² of walkable area in the shipped scenario: about 130 people on ~4,500 m², free walking.
AGENT_DENSITY = 0.03

META = StageMetadata(up_axis="Z", meters_per_unit=1.0, time_codes_per_second=24.0, start_time_code=1.0,
                     end_time_code=48.0, default_prim="World")

DISTRICT_CAMERAS = (
    CameraRig("CCTV_Largo", (-30.0, 6.0, PLAZA_Z + 6.0), (0.0, 20.0, PLAZA_Z), 2.8, 4.8, 3.6,
              "CCTV on a largo lamp post, 6 m up, over the market."),
    CameraRig("CCTV_Street", (6.5, -34.0, 6.0), (0.0, -10.0, 1.0), 2.8, 4.8, 3.6,
              "CCTV at the foot of the cobbled street, looking up the slope."),
    CameraRig("PedestrianEye_Street", (-6.5, -30.0, float(street_z(-30.0)) + 0.15 + 1.6), (-2.0, 0.0, PLAZA_Z + 1.0),
              24.0, 36.0, 24.0, "Pedestrian eye level (1.6 m) on the cobbled street's west sidewalk, looking uphill."),
    CameraRig("WheelchairEye_Largo", (-12.0, 7.0, PLAZA_Z + 1.24), (10.0, 25.0, PLAZA_Z + 1.0), 24.0, 36.0, 24.0,
              "Seated wheelchair user's eye level (1.2 m) in the largo."),
    CameraRig("UAV_Oblique", (-60.0, -70.0, 55.0), (0.0, 0.0, 0.0), 24.0, 36.0, 24.0,
              "UAV, oblique 45 degrees over the district."),
)


def write_district(out_dir: str | Path, seed: int = 0, class_map: ClassMap | None = None) -> dict:
    """Write ``twin.usda`` and ``semantics.usda`` of the district for ``seed``; returns counts and paths."""
    model = build_district(seed)
    files = write_twin(model, out_dir, class_map or ClassMap.default(), META)
    return {"files": files, "objects": len(model.objects), "triangles": model.triangle_count(),
            "classes": model.label_counts()}


def write_district_scenario(out_dir: str | Path, seed: int = 0, agents: bool = True) -> list[Path]:
    """The district's twin and semantics plus cameras, environment, render settings, a populated agents layer
    (``AGENT_DENSITY``, default aid share) and ``scenario.usda`` composing them."""
    out_dir = Path(out_dir)
    files = list(write_district(out_dir, seed)["files"])
    cams = build_camera_layer(META, DISTRICT_CAMERAS, "Largo da Ordem demo district: camera rigs with physical lens values.")
    layers = {"cameras.usda": cams, "environment.usda": build_environment(META),
              "render.usda": build_render_settings(META, camera="/World/Cameras/CCTV_Largo")}
    for name, stage in layers.items():
        files.append(save_layer_atomic(stage.GetRootLayer(), out_dir / name))
    order = ["render.usda", "environment.usda", "cameras.usda", "semantics.usda", "twin.usda"]
    scenario = out_dir / "scenario.usda"
    compose_layers(scenario, [out_dir / n for n in order], doc=f"Largo da Ordem demo district (seed {seed}) scenario.")
    if agents:
        report = populate(PopulateRequest(scenario, out_dir / "agents.usda", density_per_m2=AGENT_DENSITY,
                                          frames=int(META.end_time_code - META.start_time_code + 1), seed=seed))
        files += report.files
        order.insert(3, "agents.usda")
    files.append(compose_layers(scenario, [out_dir / n for n in order],
                                doc=f"Largo da Ordem demo district (seed {seed}) scenario."))
    return files
