"""The procedural demo district, modelled on Largo da Ordem (Curitiba): about 150 m x 100 m, Z up.

Layout (metres; x east, y north): an asphalt road along the south (y -45..-37) with sidewalks; a sloped
cobbled street (x -5..5) climbing 3 m from the road (y -33) to the largo (y 5); the paved largo
(y 5..34) with the Sunday market, benches, trees, a bicycle rack, dogs and pigeons; the church at its
north end; rows of two- and three-storey houses with doors, windows and murals along every street;
steps with railings down a grass slope west of the street; crosswalks with a curb ramp at each end;
light poles and lanterns, signage, manhole covers, a bus stop with a bus, parked cars and motorcycles,
and a few mobility aids standing unattended (a walker by a bench, a wheelchair by the church door).

Everything random comes from one ``numpy.random.Generator`` seeded by the caller, drawn in a fixed
order, so the same seed gives the same :class:`TwinModel` (and byte-identical layers).
:func:`district_scenario` adds cameras, a populated crowd, environment and render settings.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.agents.crowd import Crowd, CrowdParams, populate_crowd
from synthua_usd.assets import buildings, devices, market, nature, place, street, vehicles
from synthua_usd.composition.rigs import AimedRigs, RigSpec
from synthua_usd.composition.scenario import ScenarioSpec, StageMetadata
from synthua_usd.demo.district_textures import add_textures
from synthua_usd.demo.twin_builder import TwinBuilder
from synthua_usd.model import meshes as geo
from synthua_usd.model.cameras import CameraSpec
from synthua_usd.model.materials import WALL_COLOURS, subset
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.model.twin import TwinModel, TwinPart

ROAD_Y = (-45.0, -37.0)
ROAD_SIDEWALK_S = (-49.5, -45.0)
ROAD_SIDEWALK_N = (-37.0, -33.0)
STREET_X = (-5.0, 5.0)
STREET_SIDEWALK_W = 3.0
STREET_Y = (-33.0, 5.0)      # the slope; the street itself reaches down to the road (ROAD_Y[1])
PLAZA_X = (-45.0, 45.0)
PLAZA_Y = (5.0, 34.0)
PLAZA_Z = 3.0
PAVER_H = 0.04   # the largo's paving over its slab
COBBLE_H = 0.07  # the cobbled street's setts over its bed (0 at the road)
KERB_H = 0.15
HALF_X = 75.0
CROSSWALK_XS = (-30.0, 30.0)
STREET_CROSSWALK_Y = -29.0
RAMP_LEN = 1.8   # 15 cm over 1.8 m: 1:12
RAMP_HALF_W = 1.2
SLOPE_X = (-45.0, -19.0)     # the grass slope west of the street, rising along y to the largo
SLOPE_Y0 = -21.0
STEPS_X = -30.0              # centre line of the flight of steps up the slope, 3 m wide

PAINTS = ["PaintRed", "PaintBlue", "PaintBlack", "PaintWhite", "PaintSilver"]


def street_z(y: float | np.ndarray) -> float | np.ndarray:
    """Height of the cobbled street's bed at ``y``: 0 at the road, PLAZA_Z at the largo."""
    t = np.clip((np.asarray(y, float) - STREET_Y[0]) / (STREET_Y[1] - STREET_Y[0]), 0.0, 1.0)
    return t * PLAZA_Z


def slope_z(y: float) -> float:
    """Height of the grass slope's surface at ``y``: the kerb's height at its foot, the largo's at its top."""
    t = (y - SLOPE_Y0) / (PLAZA_Y[0] - SLOPE_Y0)
    return KERB_H + t * (PLAZA_Z - KERB_H)


def _shear(mesh: geo.Mesh) -> geo.Mesh:
    """Lift a mesh by the street's slope at each vertex's y. Planar faces stay planar where the mesh lies
    within one straight stretch of the slope; :func:`_street_box` cuts boxes at the bends."""
    pts, tris = mesh
    return pts + np.column_stack([np.zeros(len(pts)), np.zeros(len(pts)), street_z(pts[:, 1])]), tris


def _street_box(min_corner, max_corner) -> geo.Mesh:
    """A box lifted by the street's slope, cut where the slope starts and ends so that its faces follow the
    street's bends (a box sheared only at its corners would cut across them, into or above the stones)."""
    (x0, y0, z0), (x1, y1, z1) = min_corner, max_corner
    edges = [y0, *(y for y in STREET_Y if y0 < y < y1), y1]
    return _shear(geo.merge(*[geo.box((x0, a, z0), (x1, b, z1)) for a, b in zip(edges, edges[1:])]))


def _ramp_along_x(x_low, x_high, y0, y1, z_low, z_high, z_base) -> geo.Mesh:
    """A wedge rising along x (``x_low`` may exceed ``x_high``)."""
    pts, tris = geo.ramp(y0, y1, x_low, x_high, z_low, z_high, z_base)
    return pts[:, [1, 0, 2]], tris[:, ::-1]


def sidewalk_x_strip(x0, x1, y_kerb, y_back, gaps: list[float], z_of=None) -> list[TwinPart]:
    """A sidewalk along x whose kerb faces the road at ``y_kerb``; curb-ramp gaps centred at ``gaps``.
    Returns slab and kerb pieces (the kerb is 20 cm of granite along the road edge)."""
    sgn = 1.0 if y_back > y_kerb else -1.0
    cuts = sorted(gaps)
    spans, start = [], x0
    for g in cuts:
        spans.append((start, g - RAMP_HALF_W))
        start = g + RAMP_HALF_W
    spans.append((start, x1))
    slab, kerb = [], []
    yk0, yk1 = sorted((y_kerb, y_kerb + sgn * 0.2))
    ys0, ys1 = sorted((y_kerb + sgn * 0.2, y_back))
    for a, b in spans:
        if b - a > 0.01:
            slab.append(geo.box((a, ys0, -0.3), (b, ys1, KERB_H)))
            kerb.append(geo.box((a, yk0, -0.3), (b, yk1, KERB_H)))
    for g in cuts:  # behind each ramp the sidewalk continues at full height
        yb0, yb1 = sorted((y_kerb + sgn * RAMP_LEN, y_back))
        slab.append(geo.box((g - RAMP_HALF_W, yb0, -0.3), (g + RAMP_HALF_W, yb1, KERB_H)))
    return [TwinPart.of("Slab", geo.merge(*slab), "Concrete"), TwinPart.of("Kerb", geo.merge(*kerb), "Granite")]


def build_district(seed: int = 0, textures: bool = True) -> TwinModel:
    """The district for ``seed`` as a :class:`TwinModel` (local metres, origin at the layout's centre), with
    its procedural textures (:mod:`synthua_usd.demo.district_textures`) unless ``textures`` is False."""
    rng = np.random.default_rng(seed)
    b = TwinBuilder()
    _streets(b)
    _buildings(b, rng)
    _furniture(b, rng)
    _market(b, rng)
    _vehicles(b, rng)
    _nature(b, rng)
    _mobility_aids(b)
    model = TwinModel(objects=tuple(b.objects), materials=subset(p.material for o in b.objects for p in o.parts),
                      source=f"largo-da-ordem demo district (seed {seed})", report={"seed": seed})
    return add_textures(model, seed) if textures else model


def _streets(b: TwinBuilder) -> None:
    L = HALF_X
    # Open ground under everything, 2 cm below the road so that no two surfaces are coplanar: for the same
    # reason it reaches 1 m past the road's ends and further down than any bed or slab (their end and
    # bottom faces would otherwise lie in its own).
    b.add("Nature", "Ground", "grass", [TwinPart.of("Surface", geo.box((-L - 1.0, -50.0, -1.0), (L + 1.0, 50.0, -0.02)), "Grass")])
    b.add("Streets", "AsphaltRoad", "road", [TwinPart.of("Surface", geo.box((-L, ROAD_Y[0], -0.3), (L, ROAD_Y[1], 0.0)), "Asphalt")])
    # Road sidewalks, with curb ramps at the crosswalks; the north one stops at the cobbled street.
    b.add("Sidewalks", "RoadSouth", "sidewalk", sidewalk_x_strip(-L, L, ROAD_Y[0], ROAD_SIDEWALK_S[0], list(CROSSWALK_XS)))
    for side, (x0, x1) in (("RoadNorthWest", (-L, STREET_X[0] - STREET_SIDEWALK_W)),
                           ("RoadNorthEast", (STREET_X[1] + STREET_SIDEWALK_W, L))):
        gaps = [g for g in CROSSWALK_XS if x0 < g < x1]
        b.add("Sidewalks", side, "sidewalk", sidewalk_x_strip(x0, x1, ROAD_Y[1], ROAD_SIDEWALK_N[1], gaps))
    for x in CROSSWALK_XS:
        for y_kerb, sgn in ((ROAD_Y[0], -1.0), (ROAD_Y[1], 1.0)):
            ya, yb = sorted((y_kerb, y_kerb + sgn * RAMP_LEN))
            low, high = (yb, ya) if sgn < 0 else (ya, yb)
            pts, tris = geo.ramp(x - RAMP_HALF_W, x + RAMP_HALF_W, low, high, 0.005, KERB_H, -0.3)
            b.add("CurbRamps", "Ramp", "curb_ramp", [TwinPart.of("Surface", (pts, tris), "RampConcrete")])
        bars = [geo.box((x - 1.5, y, 0.0), (x + 1.5, y + 0.5, 0.01)) for y in np.arange(ROAD_Y[0] + 0.25, ROAD_Y[1] - 0.4, 1.0)]
        b.add("Crosswalks", "Zebra", "crosswalk", [TwinPart.of("Bars", geo.merge(*bars), "RoadPaint")])
    # The cobbled street, sloping up to the largo: its setts are an image with a normal map
    # (district_textures.PAVED), laid on a bed whose top is the stones' top.
    x0, x1 = STREET_X
    y_start = ROAD_Y[1]
    bed = _street_box((x0, y_start, -0.5), (x1, STREET_Y[1], COBBLE_H))
    b.add("Streets", "CobbledStreet", "street_road", [TwinPart.of("Setts", bed, "Cobble0")], surface="cobblestone")
    # Its sidewalks (sheared with the slope) and a crosswalk near the bottom with ramps on both sides.
    cy = STREET_CROSSWALK_Y
    for side, (kx, sgn) in (("StreetWest", (x0, -1.0)), ("StreetEast", (x1, 1.0))):
        xa, xb = sorted((kx + sgn * 0.2, kx + sgn * STREET_SIDEWALK_W))
        ka, kb = sorted((kx, kx + sgn * 0.2))
        ra, rb = sorted((kx, kx + sgn * RAMP_LEN))
        slab = [_street_box((xa, y_start, -0.5), (xb, cy - RAMP_HALF_W, KERB_H)),
                _street_box((xa, cy + RAMP_HALF_W, -0.5), (xb, STREET_Y[1], KERB_H))]
        back_a, back_b = sorted((kx + sgn * RAMP_LEN, kx + sgn * STREET_SIDEWALK_W))
        slab.append(_street_box((back_a, cy - RAMP_HALF_W, -0.5), (back_b, cy + RAMP_HALF_W, KERB_H)))
        kerb = [_street_box((ka, y_start, -0.5), (kb, cy - RAMP_HALF_W, KERB_H)),
                _street_box((ka, cy + RAMP_HALF_W, -0.5), (kb, STREET_Y[1], KERB_H))]
        b.add("Sidewalks", side, "sidewalk", [TwinPart.of("Slab", geo.merge(*slab), "Concrete"),
                                              TwinPart.of("Kerb", geo.merge(*kerb), "Granite")])
        low, high = (ra, rb) if sgn > 0 else (rb, ra)
        b.add("CurbRamps", "Ramp", "curb_ramp",
              [TwinPart.of("Surface", _shear(_ramp_along_x(low, high, cy - RAMP_HALF_W, cy + RAMP_HALF_W, 0.075, KERB_H, -0.5)),
                     "RampConcrete")])
    bars = [geo.box((x, cy - 1.5, 0.072), (x + 0.5, cy + 1.5, 0.085)) for x in np.arange(x0 + 0.25, x1 - 0.4, 1.0)]
    b.add("Crosswalks", "Zebra", "crosswalk", [TwinPart.of("Bars", _shear(geo.merge(*bars)), "RoadPaint")])
    # The largo: a slab paved with stones of three close shades (light, warm, grey), an image with a normal map
    # as the setts; with two shades far apart (light and near-black) it read as a checkerboard from every camera.
    b.add("Sidewalks", "Largo", "sidewalk",
          [TwinPart.of("Pavers", geo.box((PLAZA_X[0], PLAZA_Y[0], PLAZA_Z - 3.5), (PLAZA_X[1], PLAZA_Y[1], PLAZA_Z + PAVER_H)),
                       "PaverWarm")])
    # Grass slope west of the street, steps down it, railings along the steps and the slope's top edge.
    gx0, gx1, gy0 = SLOPE_X[0], SLOPE_X[1], SLOPE_Y0
    slope = geo.ramp(gx0, gx1, gy0, PLAZA_Y[0], KERB_H, PLAZA_Z, -0.5)
    b.add("Nature", "GrassSlope", "grass", [TwinPart.of("Surface", slope, "Grass")])
    # The flight starts 5 cm in front of the slope's foot: flush, the two front faces would lie in one
    # plane. Every tread then stands a few millimetres proud of the slope, the top one level with the largo.
    n_steps, rise = 19, (PLAZA_Z - KERB_H) / 19
    foot = gy0 - 0.05
    tread = (PLAZA_Y[0] - foot) / n_steps
    flight = place(street.steps(3.0, n_steps, rise, tread), (STEPS_X, foot, KERB_H), 90.0)
    b.add("Steps", "Flight", "sidewalk", flight, surface="steps")
    # Railings stand on the grass (posts planted in the slope), 10 cm short of its edges, the largo and the
    # houses' back walls, so that no post sticks out over an edge or into a wall.
    top = PLAZA_Y[0] - 0.1
    for x in (STEPS_X - 1.6, STEPS_X + 1.6):
        b.add("Railings", "Railing", "railing",
              street.railing((x, gy0 + 0.1, slope_z(gy0 + 0.1)), (x, top, slope_z(top)), height=1.0))
    b.add("Railings", "Railing", "railing", street.railing((gx0 + 0.1, top, slope_z(top)), (STEPS_X - 1.8, top, slope_z(top))))
    b.add("Railings", "Railing", "railing", street.railing((STEPS_X + 1.8, top, slope_z(top)), (gx1 - 0.1, top, slope_z(top))))
    # Manhole covers on the road, the cobbles and the largo; the one on the cobbles (z None) tilts with the
    # street, on its stones.
    for x, y, z in [(-55.0, -41.0, 0.0), (12.0, -39.5, 0.0), (48.0, -43.0, 0.0), (0.0, -12.0, None), (-20.0, 28.0, PLAZA_Z + PAVER_H)]:
        cover = place(street.manhole_cover(), (x, y, COBBLE_H if z is None else z))
        if z is None:
            cover = [TwinPart.of(p.name, _shear(p.mesh), p.material) for p in cover]
        b.add("Covers", "Manhole", "cover", cover)


def _buildings(b: TwinBuilder, rng: np.random.Generator) -> None:
    def house(folder, at, heading, width, depth, storeys, mural, foundation, ground_z=None):
        """``ground_z(y)``: height of a sloping sidewalk in front of the house; its doors stand on it."""
        wall = f"Wall{int(rng.integers(len(WALL_COLOURS)))}"
        parts = buildings.row_house(rng, width, depth, storeys, wall, foundation_m=foundation, mural=mural)
        stem = b.add(folder, "House", "building", place(parts.structure, at, heading), storeys=storeys)
        for k, door in enumerate(parts.doors):
            door = place(door, at, heading)
            if ground_z is not None:  # lift the door's sill to the sidewalk's highest point under it
                pts = np.concatenate([p.points for p in door])
                lift = max(ground_z(y) for y in pts[:, 1]) - pts[:, 2].min()
                door = [p.moved(p.points + (0.0, 0.0, lift)) for p in door]
            b.sub(stem, "Door", k, "door", door)
        for k, window in enumerate(parts.windows):
            b.sub(stem, "Window", k, "window", place(window, at, heading))
        for k, mural_p in enumerate(parts.murals):
            b.sub(stem, "Mural", k, "mural", place(mural_p, at, heading))

    depth = 11.0
    # Along the cobbled street, stepping up with the slope; fronts on the sidewalks' back edge.
    for side, front_x, heading in (("StreetWest", STREET_X[0] - STREET_SIDEWALK_W, 0.0),
                                   ("StreetEast", STREET_X[1] + STREET_SIDEWALK_W, 180.0)):
        y = STREET_Y[0] + 4.5
        while y < STREET_Y[1] - 3.0:
            width = float(rng.uniform(5.5, 8.5))
            width = min(width, STREET_Y[1] - y)
            cy = y + width / 2
            cx = front_x - depth / 2 if heading == 0.0 else front_x + depth / 2
            z = float(street_z(cy)) + KERB_H
            house(f"Buildings/{side}", (cx, cy, z), heading, width, depth, int(rng.integers(2, 4)),
                  bool(rng.random() < 0.35), foundation=3.5, ground_z=lambda y: float(street_z(y)) + KERB_H)
            y += width
    # Along the asphalt road's north side, facing south.
    for x_from, x_to in ((-HALF_X + 1.0, -46.0), (STREET_X[1] + STREET_SIDEWALK_W + 12.0, HALF_X - 1.0)):
        x = x_from
        while x < x_to - 4.0:
            width = min(float(rng.uniform(6.0, 9.0)), x_to - x)
            house("Buildings/RoadNorth", (x + width / 2, ROAD_SIDEWALK_N[1] + depth / 2, KERB_H), -90.0, width, depth,
                  int(rng.integers(2, 4)), bool(rng.random() < 0.3), foundation=0.5)
            x += width
    # Framing the largo, west and east.
    for x_front, heading in ((PLAZA_X[0], 0.0), (PLAZA_X[1], 180.0)):
        y = PLAZA_Y[0] + 1.0
        while y < PLAZA_Y[1] + 10.0:
            width = float(rng.uniform(6.0, 9.0))
            cx = x_front - depth / 2 if heading == 0.0 else x_front + depth / 2
            house("Buildings/Largo", (cx, y + width / 2, PLAZA_Z + PAVER_H), heading, width, depth,
                  int(rng.integers(2, 4)), bool(rng.random() < 0.3), foundation=3.5)
            y += width
    # The church at the north end of the largo, facing south.
    # The nave's front (its side doors) on the largo's north edge, the tower 0.5 m out onto the largo; the
    # foundation reaches the open ground below the largo's level, as the houses' do.
    parts = buildings.church(width=14.0, depth=14.0, foundation_m=3.5)
    at, heading = (0.0, PLAZA_Y[1] + 7.0, PLAZA_Z + PAVER_H), -90.0
    stem = b.add("Buildings", "Church", "building", place(parts.structure, at, heading), name="Igreja da Ordem")
    for k, door in enumerate(parts.doors):
        b.sub(stem, "Door", k, "door", place(door, at, heading))
    for k, window in enumerate(parts.windows):
        b.sub(stem, "Window", k, "window", place(window, at, heading))


def _furniture(b: TwinBuilder, rng: np.random.Generator) -> None:
    pz = PLAZA_Z + PAVER_H
    # Lanterns along the cobbled street's sidewalks and round the largo; arm lights along the road.
    for x, heading in ((STREET_X[0] - 0.6, 0.0), (STREET_X[1] + 0.6, 180.0)):
        for y in np.arange(STREET_Y[0] + 6.0, STREET_Y[1], 12.0):
            pole, lamp = street.light_pole(4.0)
            at = (x, y, float(street_z(y)) + KERB_H)
            b.add("Lighting", "Pole", "light_pole", place(pole, at, heading))
            b.add("Lighting", "Lantern", "luminaire", place(lamp, at, heading))
    for x in np.arange(PLAZA_X[0] + 5.0, PLAZA_X[1], 15.0):
        for y in (PLAZA_Y[0] + 1.0, PLAZA_Y[1] - 1.0):
            pole, lamp = street.light_pole(4.0)
            b.add("Lighting", "Pole", "light_pole", place(pole, (x, y, pz)))
            b.add("Lighting", "Lantern", "luminaire", place(lamp, (x, y, pz)))
    for x in np.arange(-HALF_X + 8.0, HALF_X, 20.0):
        for y, heading in ((ROAD_Y[1] + 0.5, -90.0), (ROAD_Y[0] - 0.5, 90.0)):
            pole, lamp = street.light_pole(7.0, arm=1.8)
            b.add("Lighting", "Pole", "light_pole", place(pole, (x, y, KERB_H), heading))
            b.add("Lighting", "Luminaire", "luminaire", place(lamp, (x, y, KERB_H), heading))
    # Benches round the largo.
    for x in np.arange(PLAZA_X[0] + 10.0, PLAZA_X[1] - 5.0, 15.0):
        b.add("Furniture", "Bench", "furniture", place(street.bench(), (x, PLAZA_Y[0] + 3.0, pz), 90.0))
    # Signage: street names at the corners, a stop sign where the street meets the road, the bus stop.
    for x in (STREET_X[0] - 1.0, STREET_X[1] + 1.0):
        b.add("Signage", "StreetName", "signage", place(street.sign(kind="street"), (x, ROAD_SIDEWALK_N[0] + 1.0, KERB_H), -90.0))
    b.add("Signage", "Stop", "signage", place(street.sign(kind="stop"), (STREET_X[1] + 0.8, STREET_Y[0] + 1.5,
                                                                       float(street_z(STREET_Y[0] + 1.5)) + KERB_H), -90.0))
    b.add("Signage", "BusStop", "signage", place(street.sign(kind="bus"), (38.0, ROAD_Y[1] + 0.7, KERB_H), -90.0))
    b.add("Furniture", "BusShelter", "furniture", place(street.bus_shelter(), (44.0, ROAD_SIDEWALK_N[1] - 1.0, KERB_H), -90.0))
    b.add("Furniture", "BikeRack", "furniture", place(street.bike_rack(), (36.0, PLAZA_Y[0] + 6.0, pz)))


def _market(b: TwinBuilder, rng: np.random.Generator) -> None:
    pz = PLAZA_Z + PAVER_H
    canvases = ["CanvasWhite", "CanvasRed", "CanvasBlue", "CanvasYellow"]
    for y, heading in ((13.0, 90.0), (24.0, -90.0)):
        for x in np.arange(-27.0, 25.0, 3.6):
            if rng.random() < 0.15:
                continue  # a gap in the row
            canvas = canvases[int(rng.integers(len(canvases)))]
            b.add("Market", "Tent", "tent", place(market.tent(3.0, canvas=canvas), (x, y, pz), heading))
            b.add("Market", "Stand", "stand", place(market.stand(2.4), (x + 0.2 * np.sign(heading), y, pz), heading))
    # A café corner: tables, chairs and umbrellas.
    for k, (x, y) in enumerate([(31.0, 12.0), (34.5, 12.5), (32.0, 16.5), (35.5, 17.0), (33.5, 21.0)]):
        x += float(rng.uniform(-0.4, 0.4))
        b.add("Market", "Table", "table", place(market.table(), (x, y, pz)))
        for a in (0.0, 120.0, 240.0):
            off = 0.75 * np.array([np.cos(np.radians(a)), np.sin(np.radians(a))])
            b.add("Market", "Chair", "chair", place(market.chair(), (x + off[0], y + off[1], pz), a))
        if k % 2 == 0:
            b.add("Market", "Umbrella", "umbrella", place(market.umbrella(canvas=canvases[k % 4], foot_m=market.TABLE_TOP_M), (x, y, pz)))


def _vehicles(b: TwinBuilder, rng: np.random.Generator) -> None:
    lane = ROAD_Y[0] + 1.3
    for x_from, x_to in ((-70.0, -36.0), (-24.0, 24.0), (36.0, 55.0)):
        x = x_from
        while x < x_to - 4.5:
            if rng.random() < 0.7:
                paint = PAINTS[int(rng.integers(len(PAINTS)))]
                b.add("Vehicles", "Car", "car", place(vehicles.car(float(rng.uniform(3.9, 4.6)), paint=paint), (x + 2.3, lane, 0.0)))
            x += 6.0
    b.add("Vehicles", "Bus", "bus", place(vehicles.bus(), (44.0, ROAD_Y[1] - 1.6, 0.0), 180.0))
    for k in range(3):
        b.add("Vehicles", "Motorcycle", "motorcycle", place(vehicles.motorcycle(), (60.0 + 1.2 * k, lane, 0.0), 60.0))
    # Parked across the rack (whose hoops stand 0.75 m apart along y), one between each pair of hoops: a
    # bicycle is 1.8 m long and 0.5 m wide, so side by side they keep 0.25 m apart.
    for k in range(4):
        b.add("Vehicles", "Bicycle", "bicycle", place(vehicles.bicycle(), (36.0 + 0.3, PLAZA_Y[0] + 4.9 + 0.75 * k, PLAZA_Z + PAVER_H), 0.0))


def _nature(b: TwinBuilder, rng: np.random.Generator) -> None:
    pz = PLAZA_Z + PAVER_H
    for x, y in [(-38.0, 9.0), (-38.0, 30.0), (38.0, 30.0), (-14.0, 30.0), (14.0, 30.0)]:
        b.add("Nature", "GrassBed", "grass", place(nature.grass_bed(4.0, 4.0), (x, y, pz)))
        b.add("Nature", "Tree", "vegetation", place(nature.tree(rng, float(rng.uniform(6.0, 8.0))), (x, y, pz + 0.22)))
    # On the grass slope: clear of the steps and their railings, crowns (reaching at most 2.7 m from the
    # trunk along x or y) clear of each other and of the houses' back walls, trunks planted 10 cm deep.
    for x in (-41.0, -35.5, -23.0):
        b.add("Nature", "Tree", "vegetation", place(nature.tree(rng, float(rng.uniform(5.0, 7.0))), (x, -14.0, slope_z(-14.0) - 0.1)))
    b.add("Nature", "Araucaria", "vegetation", place(nature.araucaria(12.0), (-24.0, -4.0, slope_z(-4.0) - 0.1)))
    for k in range(3):
        at = (float(rng.uniform(-20, 20)), float(rng.uniform(16, 22)), pz)
        b.add("Animals", "Dog", "animal", place(nature.dog(float(rng.uniform(0.8, 1.2))), at, float(rng.uniform(0, 360))))
    # A flock of twelve pigeons, 0.4 m apart at least: a pigeon reaches 0.17 m from its centre, any way it turns.
    cx, cy = float(rng.uniform(-10, 10)), float(rng.uniform(28, 31))
    flock: list[tuple[float, float]] = []
    while len(flock) < 12:
        x, y = cx + float(rng.normal(0, 1.2)), cy + float(rng.normal(0, 0.8))
        if all(np.hypot(x - fx, y - fy) >= 0.4 for fx, fy in flock):
            flock.append((x, y))
            b.add("Animals", "Pigeon", "animal", place(nature.pigeon(), (x, y, pz), float(rng.uniform(0, 360))))


def _mobility_aids(b: TwinBuilder) -> None:
    """Devices standing unattended so that every class appears in the twin; the agents layer brings
    devices in use, with their users."""
    pz = PLAZA_Z + PAVER_H
    spots = {
        "walker": ((-20.0, PLAZA_Y[0] + 2.2, pz), 0.0),
        "manual_wheelchair": ((3.0, PLAZA_Y[1] - 1.5, pz), -90.0),
        "electric_wheelchair": ((41.5, ROAD_SIDEWALK_N[1] - 1.2, KERB_H), 180.0),
        "crutch": ((31.5, 12.5, pz), 0.0),
        "smart_cane": ((-4.6, PLAZA_Y[0] + 2.6, pz), 0.0),
        "wooden_cane": ((10.4, PLAZA_Y[0] + 2.6, pz), 0.0),
        "orthopedic_cane": ((25.4, PLAZA_Y[0] + 2.6, pz), 0.0),
        "tripod_cane": ((-19.4, PLAZA_Y[0] + 2.6, pz), 0.0),
    }
    for name, (at, heading) in spots.items():
        b.add("MobilityAids", name.title().replace("_", ""), name, place(devices.DEVICES[name](), at, heading))


# --- the scenario -----------------------------------------------------------------------------------------

#: Persons per m² of walkable area in the shipped scenario: about 130 people on ~4,500 m², free walking.
AGENT_DENSITY = 0.03

META = StageMetadata(up_axis="Z", meters_per_unit=1.0, time_codes_per_second=24.0, start_time_code=1.0,
                     end_time_code=48.0, default_prim="World")

DISTRICT_CAMERAS = (
    CameraSpec("CCTV_Largo", (-30.0, 6.0, PLAZA_Z + 6.0), (0.0, 20.0, PLAZA_Z), 2.8, 4.8, 3.6,
               "CCTV on a largo lamp post, 6 m up, over the market.", rig_type="cctv"),
    CameraSpec("CCTV_Street", (6.5, -34.0, 6.0), (0.0, -10.0, 1.0), 2.8, 4.8, 3.6,
               "CCTV at the foot of the cobbled street, looking up the slope.", rig_type="cctv"),
    CameraSpec("PedestrianEye_Street", (-6.5, -30.0, float(street_z(-30.0)) + 0.15 + 1.6), (-2.0, 0.0, PLAZA_Z + 1.0),
               24.0, 36.0, 24.0, "Pedestrian eye level (1.6 m) on the cobbled street's west sidewalk, looking uphill.",
               rig_type="pedestrian_eye"),
    CameraSpec("WheelchairEye_Largo", (-12.0, 7.0, PLAZA_Z + 1.24), (10.0, 25.0, PLAZA_Z + 1.0), 24.0, 36.0, 24.0,
               "Seated wheelchair user's eye level (1.2 m) in the largo.", rig_type="wheelchair_eye"),
    CameraSpec("UAV_Oblique", (-60.0, -70.0, 55.0), (0.0, 0.0, 0.0), 24.0, 36.0, 24.0,
               "UAV, oblique 45 degrees over the district.", rig_type="uav_oblique"),
)


#: Cameras aimed at the crowd's mobility-aid users, placed in the written district by the machinery of
#: `synthua cameras author` (rigs.usda, with rigs.report.json beside it): two CCTVs on the two first-ranked aid
#: users (wheelchair users first), a pedestrian's and a seated wheelchair user's eye level, two UAV views, and a
#: dashcam driving the road. Each aimed camera must show its target with DISTRICT_MIN_TARGET_PX visible
#: pixels at 1280x960 at every DISTRICT_RIG_TIME_CODES, or it is reported and left out.
DISTRICT_RIGS = (
    RigSpec("cctv", name="CCTV_AidUser", aim="aid_user", count=2),
    RigSpec("pedestrian_eye", name="PedestrianEye_AidUser", aim="aid_user"),
    RigSpec("wheelchair_eye", name="WheelchairEye_AidUser", aim="aid_user"),
    RigSpec("uav_oblique", name="UAVOblique_AidUser", aim="aid_user", height_m=30.0),
    RigSpec("uav_nadir", name="UAVNadir_AidUser", aim="aid_user", height_m=30.0),
    RigSpec("dashcam", name="Dashcam_Road", aim="none"),
)
DISTRICT_MIN_TARGET_PX = 2000
DISTRICT_RIG_TIME_CODES = (1.0, 12.0, 24.0, 36.0, 48.0)
#: The render settings' camera when it is placed (else CCTV_Largo stays).
DISTRICT_RENDER_RIG = "CCTV_AidUser_1"


def district_aimed_rigs() -> AimedRigs:
    """The district's aimed rigs, placed when the district is written (``synthua create district``)."""
    return AimedRigs(DISTRICT_RIGS, DISTRICT_MIN_TARGET_PX, DISTRICT_RIG_TIME_CODES, DISTRICT_RENDER_RIG)


def district_crowd(model: TwinModel, seed: int = 0, class_map: ClassMap | None = None) -> Crowd:
    """The shipped crowd: ``AGENT_DENSITY`` on the district's walkable surfaces, default aid share."""
    class_map = class_map or ClassMap.default()
    vertices, faces, labels = model.labelled_triangles()
    # The layers store float32 points: populate on exactly the surfaces a stage reader would see.
    vertices = vertices.astype(np.float32).astype(np.float64)
    names = np.array([class_map.resolve(label).name for label in labels], object)
    params = CrowdParams(density_per_m2=AGENT_DENSITY, time_codes=META.time_code_count,
                         time_codes_per_second=META.time_codes_per_second, seed=seed)
    return populate_crowd(vertices, faces, names, params)


def district_scenario(seed: int = 0, agents: bool = True) -> ScenarioSpec:
    """The district for ``seed`` as a scenario: twin, a populated crowd (unless ``agents`` is False), five
    cameras, a clear day and default render settings aimed through ``CCTV_Largo``."""
    model = build_district(seed)
    return ScenarioSpec(doc=f"Largo da Ordem demo district (seed {seed})", metadata=META, twin=model,
                        cameras=DISTRICT_CAMERAS, render_camera="CCTV_Largo",
                        crowd=district_crowd(model, seed) if agents else None)
