"""The walking-skeleton demo: a 40 m street segment as a scenario.

Layout (Z up, metres): the road runs along X between y = -3.5 and 3.5 at z = 0; sidewalks (top at
z = 0.15, kerb 15 cm) run beside it; the north sidewalk has one curb ramp where a zebra crosswalk meets it.
Building A stands north, building B south. One pedestrian walks along the south sidewalk; one manual
wheelchair user rolls along the north sidewalk towards the ramp.

:func:`street_scenario` returns the plain-data :class:`ScenarioSpec`; ``synthua create street`` hands it to
the scenario writer like every other scenario. Deterministic: no randomness, fixed order.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.agents.crowd import Crowd, CrowdParams, scripted_crowd
from synthua_usd.agents.motion import simulate
from synthua_usd.agents.population import Plan
from synthua_usd.agents.profiles import PROFILES
from synthua_usd.assets.people import PersonLook
from synthua_usd.composition.scenario import ScenarioSpec, StageMetadata
from synthua_usd.model import meshes as geo
from synthua_usd.model.cameras import CameraSpec
from synthua_usd.model.materials import subset
from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart

META = StageMetadata(up_axis="Z", meters_per_unit=1.0, time_codes_per_second=24.0,
                     start_time_code=1.0, end_time_code=48.0, default_prim="World")

ROAD_HALF_WIDTH = 3.5
SIDEWALK_WIDTH = 3.0
KERB_HEIGHT = 0.15
STREET_HALF_LENGTH = 20.0
CROSSWALK_X = 2.0
RAMP_HALF_WIDTH = 0.75
RAMP_LENGTH = 1.8  # 15 cm over 1.8 m: 1:12, the usual maximum running slope for curb ramps.

CAMERAS = (
    # 1/3" CCTV sensor (4.8 x 3.6 mm) behind a 2.8 mm lens: ~81 degree horizontal view from 6 m up.
    CameraSpec("CCTV", (-10.0, -6.2, 5.5), (2.0, 2.5, 0.0), 2.8, 4.8, 3.6,
              "Wall-mounted CCTV camera on building B, 6 m above the sidewalk.", clip_far_m=500.0,
              rig_type="cctv"),
    # Full-frame 36 x 24 mm with a 24 mm lens, held at 1.6 m eye height.
    CameraSpec("PedestrianEye", (-11.0, -4.6, 1.6), (4.0, 1.5, 1.0), 24.0, 36.0, 24.0,
              "Pedestrian eye level (1.6 m) on the south sidewalk, looking down the street.", clip_far_m=500.0,
              rig_type="pedestrian_eye"),
    # Same lens at the eye height of a seated wheelchair user (1.2 m).
    CameraSpec("WheelchairEye", (8.0, 5.6, 1.2), (-2.0, 4.5, 0.7), 24.0, 36.0, 24.0,
              "Eye level of a seated wheelchair user (1.2 m) on the north sidewalk, looking west.",
              clip_far_m=500.0, rig_type="wheelchair_eye"),
)


# --- twin --------------------------------------------------------------------------------------------

def _obj(path: str, label: str, *parts: TwinPart) -> TwinObject:
    return TwinObject(path, label, tuple(parts))


def street_twin() -> TwinModel:
    """Every labelled object of the street, in a fixed order. Labels are never nested: each object's
    parts inherit exactly one class."""
    L, W, H = STREET_HALF_LENGTH, ROAD_HALF_WIDTH, KERB_HEIGHT
    part = TwinPart.of
    objects = [_obj("Road", "road", part("Mesh", geo.box((-L, -W - 0.2, -0.3), (L, W + 0.2, 0.0)), "Asphalt"))]
    # Sidewalks: slabs whose street-side face is the kerb. The north one leaves a gap for the ramp.
    objects.append(_obj("SidewalkSouth", "sidewalk",
                        part("Slab", geo.box((-L, -W - SIDEWALK_WIDTH, -0.3), (L, -W - 0.2, H)), "Concrete"),
                        part("Kerb", geo.box((-L, -W - 0.2, 0.0), (L, -W, H)), "Granite")))
    x0, x1 = CROSSWALK_X - RAMP_HALF_WIDTH, CROSSWALK_X + RAMP_HALF_WIDTH
    y_back = W + RAMP_LENGTH
    objects.append(_obj("SidewalkNorth", "sidewalk",
                        part("Slab", geo.merge(
                            geo.box((-L, W + 0.2, -0.3), (x0, W + SIDEWALK_WIDTH, H)),
                            geo.box((x1, W + 0.2, -0.3), (L, W + SIDEWALK_WIDTH, H)),
                            geo.box((x0, y_back, -0.3), (x1, W + SIDEWALK_WIDTH, H))), "Concrete"),
                        part("Kerb", geo.merge(geo.box((-L, W, 0.0), (x0, W + 0.2, H)),
                                               geo.box((x1, W, 0.0), (L, W + 0.2, H))), "Granite")))
    objects.append(_obj("CurbRamp", "curb_ramp",
                        part("Mesh", geo.ramp(x0, x1, W, y_back, 0.005, H, -0.3), "RampConcrete")))
    # Zebra bars: 0.5 m wide, 0.5 m apart, 1 cm proud of the asphalt so no surface is coplanar.
    bars = [geo.box((CROSSWALK_X - 1.5, y, 0.0), (CROSSWALK_X + 1.5, y + 0.5, 0.01))
            for y in np.arange(-W + 0.25, W - 0.25, 1.0)]
    objects.append(_obj("Crosswalk", "crosswalk", part("Mesh", geo.merge(*bars), "RoadPaint")))
    objects += _building("BuildingA", x=(-16.0, -1.0), y=(W + SIDEWALK_WIDTH, 13.0), height=10.0,
                         facade_y=W + SIDEWALK_WIDTH, facing=-1, material="Wall0")
    objects += _building("BuildingB", x=(2.0, 18.0), y=(-13.0, -W - SIDEWALK_WIDTH), height=8.0,
                         facade_y=-W - SIDEWALK_WIDTH, facing=1, material="Wall1")
    px, py = 6.0, W + 0.6
    objects.append(_obj("LightPole/Pole", "light_pole", part("Mesh", geo.merge(
        geo.cylinder((px, py, H + 3.0), 0.08, 6.0),
        geo.box((px - 0.04, py - 1.2, H + 5.9), (px + 0.04, py, H + 5.98))), "Metal")))
    objects.append(_obj("LightPole/Luminaire", "luminaire",
                        part("Mesh", geo.box((px - 0.2, py - 1.5, H + 5.75), (px + 0.2, py - 0.9, H + 5.9)), "LampGlass")))
    tx, ty = 12.0, -W - 1.6
    objects.append(_obj("Tree", "vegetation",
                        part("Trunk", geo.cylinder((tx, ty, H + 1.5), 0.15, 3.0, sections=12), "Bark"),
                        part("Crown", geo.ellipsoid((tx, ty, H + 4.2), (1.8, 1.8, 2.0)), "Leaves")))
    bx, by = -4.0, W + SIDEWALK_WIDTH - 0.5
    objects.append(_obj("Bench", "furniture",
                        part("Seat", geo.merge(
                            geo.box((bx - 0.9, by - 0.2, H + 0.42), (bx + 0.9, by + 0.2, H + 0.47)),
                            geo.box((bx - 0.9, by + 0.2, H + 0.5), (bx + 0.9, by + 0.25, H + 0.9))), "Wood"),
                        part("Legs", geo.merge(*[
                            geo.box((bx + sx - 0.03, by - 0.18, H), (bx + sx + 0.03, by + 0.22, H + 0.42))
                            for sx in (-0.8, 0.8)]), "Metal")))
    used = {p.material for o in objects for p in o.parts}
    return TwinModel(objects=tuple(objects), materials=subset(used), source="synthua demo street")


def _building(name: str, x, y, height: float, facade_y: float, facing: int, material: str) -> list[TwinObject]:
    """A block with a door and two rows of windows on its street façade (``facing`` = ±1 along y).

    The block and roof are one ``building`` instance (``<name>/Structure``); each door and window is its own.
    """
    objects = [_obj(f"{name}/Structure", "building",
                    TwinPart.of("Body", geo.box((x[0], y[0], 0.0), (x[1], y[1], height)), material),
                    TwinPart.of("Roof", geo.box((x[0] - 0.3, y[0] - 0.3, height),
                                                (x[1] + 0.3, y[1] + 0.3, height + 0.25)), "RoofTile"))]
    proud = facing * 0.05  # doors and windows stand 5 cm out of the wall, towards the street.

    def on_facade(x0, x1, z0, z1):
        ya, yb = sorted((facade_y, facade_y + proud))
        return geo.box((x0, ya, z0), (x1, yb, z1))

    mid = 0.5 * (x[0] + x[1])
    objects.append(_obj(f"{name}/Door", "door", TwinPart.of("Mesh", on_facade(mid - 0.6, mid + 0.6, KERB_HEIGHT, 2.4), "Wood")))
    for floor, z in enumerate((3.2, 6.2)):
        for k, cx in enumerate(np.linspace(x[0] + 2.0, x[1] - 2.0, 4)):
            if floor == 0 and abs(cx - mid) < 1.5:
                continue
            objects.append(_obj(f"{name}/Window_{floor}{k}", "window",
                                TwinPart.of("Mesh", on_facade(cx - 0.6, cx + 0.6, z, z + 1.5), "Glass")))
    return objects


# --- agents --------------------------------------------------------------------------------------------

def street_crowd() -> Crowd:
    """A pedestrian walking east on the south sidewalk at 1.3 m/s and a manual wheelchair user rolling east
    on the north sidewalk at 0.9 m/s, animated like any populated crowd."""
    y_south, y_north = -ROAD_HALF_WIDTH - 1.3, ROAD_HALF_WIDTH + 1.2
    plans = [
        Plan(PROFILES["pedestrian"], 1.3, np.array([(-4.0, y_south, KERB_HEIGHT), (4.0, y_south, KERB_HEIGHT)]),
             ("sidewalk", "sidewalk"), 0.0, 0.0),
        Plan(PROFILES["manual_wheelchair"], 0.9, np.array([(-2.0, y_north, KERB_HEIGHT), (4.0, y_north, KERB_HEIGHT)]),
             ("sidewalk", "sidewalk"), 0.0, 0.0),
    ]
    params = CrowdParams(density_per_m2=0.01, aid_share=0.5, time_codes=META.time_code_count,
                         time_codes_per_second=META.time_codes_per_second)
    trajectories, dropped = simulate(plans, params.time_codes, params.time_codes_per_second)
    if dropped:  # fixed, far-apart routes: this would be a bug here, not bad input
        raise RuntimeError(f"demo street: {dropped} scripted agents collided")
    looks = [PersonLook(4, "Skin6", "Shirt0", "Trousers0", "Shoes1"), PersonLook(51, "Skin2", "Shirt2", "Trousers1", "Shoes0")]
    return scripted_crowd(trajectories, looks, params)


def street_scenario() -> ScenarioSpec:
    """The demo street as a scenario: twin, agents, three cameras, a clear day, default render settings."""
    return ScenarioSpec(doc="synthua demo street", metadata=META, twin=street_twin(), cameras=CAMERAS,
                        render_camera="CCTV", crowd=street_crowd())
