"""The walking-skeleton demo: a 40 m street segment authored as separate USD layers.

Layout (Z up, metres): the road runs along X between y = -3.5 and 3.5 at z = 0; sidewalks (top at
z = 0.15, kerb 15 cm) run beside it; the north sidewalk has one curb ramp where a zebra crosswalk meets it.
Building A stands north, building B south. One pedestrian walks along the south sidewalk; one manual
wheelchair user rolls along the north sidewalk towards the ramp.

The agents layer is written by the same code as populated crowds (:mod:`synthua_usd.usd.agents_writer`).
``write_street_demo`` writes twin, semantics, agents, cameras, environment and render layers and a
``scenario.usda`` that composes them by sublayers. Output is deterministic: no randomness, fixed order.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pxr import Kind, Usd

from synthua_usd import geometry as geo
from synthua_usd.cameras import CameraRig
from synthua_usd.agents.motion import simulate
from synthua_usd.agents.population import Plan
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.assets.people import PersonLook
from synthua_usd.scene import Material
from synthua_usd.usd.agents_writer import build_agents_layer
from synthua_usd.usd.authoring import (StageMetadata, apply_label, define_mesh, define_preview_material,
                                       define_xform, new_layer, save_layer_atomic, set_kind)
from synthua_usd.usd.compose import compose_layers
from synthua_usd.usd.scenario_layers import build_camera_layer, build_environment, build_render_settings

TAXONOMY = "synthua"
META = StageMetadata(up_axis="Z", meters_per_unit=1.0, time_codes_per_second=24.0,
                     start_time_code=1.0, end_time_code=48.0, default_prim="World")

ROAD_HALF_WIDTH = 3.5
SIDEWALK_WIDTH = 3.0
KERB_HEIGHT = 0.15
STREET_HALF_LENGTH = 20.0
CROSSWALK_X = 2.0
RAMP_HALF_WIDTH = 0.75
RAMP_LENGTH = 1.8  # 15 cm over 1.8 m: 1:12, the usual maximum running slope for curb ramps.

LAYER_FILES = ("render.usda", "environment.usda", "cameras.usda", "agents.usda", "semantics.usda", "twin.usda")

MATERIALS = {
    "Asphalt": Material("Asphalt", (0.045, 0.045, 0.05), 0.9),
    "Concrete": Material("Concrete", (0.36, 0.35, 0.33), 0.85),
    "Granite": Material("Granite", (0.48, 0.47, 0.46), 0.7),
    "RampConcrete": Material("RampConcrete", (0.55, 0.42, 0.22), 0.8),
    "RoadPaint": Material("RoadPaint", (0.8, 0.8, 0.78), 0.6),
    "PlasterOchre": Material("PlasterOchre", (0.62, 0.42, 0.2), 0.9),
    "PlasterBlue": Material("PlasterBlue", (0.22, 0.35, 0.55), 0.9),
    "RoofTile": Material("RoofTile", (0.35, 0.12, 0.07), 0.8),
    "Glass": Material("Glass", (0.04, 0.06, 0.08), 0.15),
    "Wood": Material("Wood", (0.28, 0.13, 0.05), 0.7),
    "Metal": Material("Metal", (0.3, 0.3, 0.32), 0.35, metallic=0.9),
    "LampGlass": Material("LampGlass", (0.9, 0.88, 0.8), 0.3),
    "Bark": Material("Bark", (0.18, 0.11, 0.06), 0.9),
    "Leaves": Material("Leaves", (0.07, 0.2, 0.04), 0.8),
}

CAMERAS = (
    # 1/3" CCTV sensor (4.8 x 3.6 mm) behind a 2.8 mm lens: ~81 degree horizontal view from 6 m up.
    CameraRig("CCTV", (-10.0, -6.2, 5.5), (2.0, 2.5, 0.0), 2.8, 4.8, 3.6,
              "Wall-mounted CCTV camera on building B, 6 m above the sidewalk.", clip_far_m=500.0),
    # Full-frame 36 x 24 mm with a 24 mm lens, held at 1.6 m eye height.
    CameraRig("PedestrianEye", (-11.0, -4.6, 1.6), (4.0, 1.5, 1.0), 24.0, 36.0, 24.0,
              "Pedestrian eye level (1.6 m) on the south sidewalk, looking down the street.", clip_far_m=500.0),
    # Same lens at the eye height of a seated wheelchair user (1.2 m).
    CameraRig("WheelchairEye", (8.0, 5.6, 1.2), (-2.0, 4.5, 0.7), 24.0, 36.0, 24.0,
              "Eye level of a seated wheelchair user (1.2 m) on the north sidewalk, looking west.", clip_far_m=500.0),
)


# --- twin --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Part:
    """One mesh of the twin. ``labelled`` is the prim (relative to /World/Twin) that carries the class:
    the part itself or the model it belongs to. Labels are never nested, so every mesh inherits exactly one."""

    path: str
    labelled: str
    label: str
    mesh: geo.Mesh
    material: str


def _twin_parts() -> list[Part]:
    """Every mesh of the twin, in a fixed order."""
    L, W, H = STREET_HALF_LENGTH, ROAD_HALF_WIDTH, KERB_HEIGHT
    parts = [Part("Road", "Road", "road", geo.box((-L, -W - 0.2, -0.3), (L, W + 0.2, 0.0)), "Asphalt")]
    # Sidewalks: slabs whose street-side face is the kerb. The north one leaves a gap for the ramp.
    parts += [
        Part("SidewalkSouth/Slab", "SidewalkSouth", "sidewalk",
             geo.box((-L, -W - SIDEWALK_WIDTH, -0.3), (L, -W - 0.2, H)), "Concrete"),
        Part("SidewalkSouth/Kerb", "SidewalkSouth", "sidewalk", geo.box((-L, -W - 0.2, 0.0), (L, -W, H)), "Granite"),
    ]
    x0, x1 = CROSSWALK_X - RAMP_HALF_WIDTH, CROSSWALK_X + RAMP_HALF_WIDTH
    y_back = W + RAMP_LENGTH
    parts += [
        Part("SidewalkNorth/Slab", "SidewalkNorth", "sidewalk", geo.merge(
            geo.box((-L, W + 0.2, -0.3), (x0, W + SIDEWALK_WIDTH, H)),
            geo.box((x1, W + 0.2, -0.3), (L, W + SIDEWALK_WIDTH, H)),
            geo.box((x0, y_back, -0.3), (x1, W + SIDEWALK_WIDTH, H))), "Concrete"),
        Part("SidewalkNorth/Kerb", "SidewalkNorth", "sidewalk", geo.merge(
            geo.box((-L, W, 0.0), (x0, W + 0.2, H)), geo.box((x1, W, 0.0), (L, W + 0.2, H))), "Granite"),
        Part("CurbRamp", "CurbRamp", "curb_ramp", geo.ramp(x0, x1, W, y_back, 0.005, H, -0.3), "RampConcrete"),
    ]
    # Zebra bars: 0.5 m wide, 0.5 m apart, 1 cm proud of the asphalt so no surface is coplanar.
    bars = [geo.box((CROSSWALK_X - 1.5, y, 0.0), (CROSSWALK_X + 1.5, y + 0.5, 0.01))
            for y in np.arange(-W + 0.25, W - 0.25, 1.0)]
    parts.append(Part("Crosswalk", "Crosswalk", "crosswalk", geo.merge(*bars), "RoadPaint"))
    parts += _building("BuildingA", x=(-16.0, -1.0), y=(W + SIDEWALK_WIDTH, 13.0), height=10.0,
                       facade_y=W + SIDEWALK_WIDTH, facing=-1, material="PlasterOchre")
    parts += _building("BuildingB", x=(2.0, 18.0), y=(-13.0, -W - SIDEWALK_WIDTH), height=8.0,
                       facade_y=-W - SIDEWALK_WIDTH, facing=1, material="PlasterBlue")
    px, py = 6.0, W + 0.6
    parts += [
        Part("LightPole/Pole", "LightPole/Pole", "light_pole", geo.merge(
            geo.cylinder((px, py, H + 3.0), 0.08, 6.0),
            geo.box((px - 0.04, py - 1.2, H + 5.9), (px + 0.04, py, H + 5.98))), "Metal"),
        Part("LightPole/Luminaire", "LightPole/Luminaire", "luminaire",
             geo.box((px - 0.2, py - 1.5, H + 5.75), (px + 0.2, py - 0.9, H + 5.9)), "LampGlass"),
    ]
    tx, ty = 12.0, -W - 1.6
    parts += [
        Part("Tree/Trunk", "Tree", "vegetation", geo.cylinder((tx, ty, H + 1.5), 0.15, 3.0, sections=12), "Bark"),
        Part("Tree/Crown", "Tree", "vegetation", geo.ellipsoid((tx, ty, H + 4.2), (1.8, 1.8, 2.0)), "Leaves"),
    ]
    bx, by = -4.0, W + SIDEWALK_WIDTH - 0.5
    parts += [
        Part("Bench/Seat", "Bench", "furniture", geo.merge(
            geo.box((bx - 0.9, by - 0.2, H + 0.42), (bx + 0.9, by + 0.2, H + 0.47)),
            geo.box((bx - 0.9, by + 0.2, H + 0.5), (bx + 0.9, by + 0.25, H + 0.9))), "Wood"),
        Part("Bench/Legs", "Bench", "furniture", geo.merge(*[
            geo.box((bx + sx - 0.03, by - 0.18, H), (bx + sx + 0.03, by + 0.22, H + 0.42)) for sx in (-0.8, 0.8)]),
             "Metal"),
    ]
    return parts


def _building(name: str, x, y, height: float, facade_y: float, facing: int, material: str) -> list[Part]:
    """A block with a door and two rows of windows on its street façade (``facing`` = ±1 along y).

    The block and roof are one ``building`` instance (``<name>/Structure``); each door and window is its own.
    """
    parts = [Part(f"{name}/Structure/Body", f"{name}/Structure", "building",
                  geo.box((x[0], y[0], 0.0), (x[1], y[1], height)), material),
             Part(f"{name}/Structure/Roof", f"{name}/Structure", "building",
                  geo.box((x[0] - 0.3, y[0] - 0.3, height), (x[1] + 0.3, y[1] + 0.3, height + 0.25)), "RoofTile")]
    proud = facing * 0.05  # doors and windows stand 5 cm out of the wall, towards the street.

    def on_facade(x0, x1, z0, z1):
        ya, yb = sorted((facade_y, facade_y + proud))
        return geo.box((x0, ya, z0), (x1, yb, z1))

    mid = 0.5 * (x[0] + x[1])
    parts.append(Part(f"{name}/Door", f"{name}/Door", "door", on_facade(mid - 0.6, mid + 0.6, KERB_HEIGHT, 2.4), "Wood"))
    for floor, z in enumerate((3.2, 6.2)):
        for k, cx in enumerate(np.linspace(x[0] + 2.0, x[1] - 2.0, 4)):
            if floor == 0 and abs(cx - mid) < 1.5:
                continue
            path = f"{name}/Window_{floor}{k}"
            parts.append(Part(path, path, "window", on_facade(cx - 0.6, cx + 0.6, z, z + 1.5), "Glass"))
    return parts


def build_twin(meta: StageMetadata = META) -> tuple[Usd.Stage, Usd.Stage]:
    """The twin layer (geometry, materials) and the semantics layer (label overrides) as two stages."""
    twin = new_layer(meta, "synthua demo street: twin geometry and UsdPreviewSurface materials (no labels).")
    twin.SetDefaultPrim(define_xform(twin, "/World", kind=Kind.Tokens.assembly).GetPrim())
    define_xform(twin, "/World/Twin", kind=Kind.Tokens.group)
    looks = {name: define_preview_material(twin, f"/World/Looks/{name}", spec) for name, spec in MATERIALS.items()}
    semantics = new_layer(meta, "synthua demo street: UsdSemantics class labels over the twin (taxonomy 'synthua').")
    semantics.SetDefaultPrim(semantics.OverridePrim("/World"))
    labelled: set[str] = set()
    for part in _twin_parts():
        path = f"/World/Twin/{part.path}"
        model = "/World/Twin/" + part.path.split("/")[0]
        if not twin.GetPrimAtPath(model):
            set_kind(define_xform(twin, model).GetPrim(), Kind.Tokens.component)
        parent = path.rsplit("/", 1)[0]
        if not twin.GetPrimAtPath(parent):
            define_xform(twin, parent)
        define_mesh(twin, path, *part.mesh, looks[part.material])
        if part.labelled not in labelled:
            apply_label(semantics.OverridePrim(f"/World/Twin/{part.labelled}"), TAXONOMY, part.label)
            labelled.add(part.labelled)
    return twin, semantics


# --- agents --------------------------------------------------------------------------------------------

def build_agents(meta: StageMetadata = META) -> Usd.Stage:
    """The agents layer: a pedestrian walking east on the south sidewalk at 1.3 m/s and a manual wheelchair
    user rolling east on the north sidewalk at 0.9 m/s, written like any populated agents layer."""
    y_south, y_north = -ROAD_HALF_WIDTH - 1.3, ROAD_HALF_WIDTH + 1.2
    plans = [
        Plan(PROFILES["pedestrian"], 1.3, np.array([(-4.0, y_south, KERB_HEIGHT), (4.0, y_south, KERB_HEIGHT)]),
             ("sidewalk", "sidewalk"), 0.0, 0.0),
        Plan(PROFILES["manual_wheelchair"], 0.9, np.array([(-2.0, y_north, KERB_HEIGHT), (4.0, y_north, KERB_HEIGHT)]),
             ("sidewalk", "sidewalk"), 0.0, 0.0),
    ]
    trajectories, dropped = simulate(plans, int(meta.end_time_code - meta.start_time_code + 1), meta.time_codes_per_second)
    if dropped:  # fixed, far-apart routes: this would be a bug here, not bad input
        raise RuntimeError(f"demo street: {dropped} scripted agents collided")
    looks = [PersonLook(1.75, 1.0, "Skin2", "Shirt0", "Trousers0"), PersonLook(1.7, 1.05, "Skin1", "Shirt2", "Trousers1")]
    return build_agents_layer(trajectories, looks, meta, TAXONOMY,
                              "synthua demo street: agents with time-sampled transforms and their own class labels.")


# --- cameras, environment, render settings ---------------------------------------------------------------

def build_cameras(meta: StageMetadata = META) -> Usd.Stage:
    return build_camera_layer(meta, CAMERAS, "synthua demo street: camera rigs with physical lens values.")


def write_street_demo(out_dir: str | Path) -> list[Path]:
    """Write every layer of the demo and ``scenario.usda`` into ``out_dir``; returns the paths written."""
    out_dir = Path(out_dir)
    twin, semantics = build_twin()
    layers = {"twin.usda": twin, "semantics.usda": semantics, "agents.usda": build_agents(),
              "cameras.usda": build_cameras(), "environment.usda": build_environment(META),
              "render.usda": build_render_settings(META)}
    written = [save_layer_atomic(layers[name].GetRootLayer(), out_dir / name) for name in LAYER_FILES]
    written.append(compose_layers(out_dir / "scenario.usda", [out_dir / name for name in LAYER_FILES],
                                  doc="synthua demo street scenario: composes the demo layers, strongest first."))
    return written
