"""The outdoor settings: a park, and a street where a bus or a van has its wheelchair ramp down by a kerb ramp,
their size and layout drawn from a seeded generator. Conditions apply as in the district (sun, sky, weather).

Classes as the district's: lawns ``grass``, park paths and sidewalks ``sidewalk`` (walkable), the street
``road``, kerb ramps ``curb_ramp``, the zebra ``crosswalk``, trees ``vegetation``, benches and the bus shelter
``furniture``, light poles and their lanterns ``light_pole`` and ``luminaire``, signs ``signage``, houses
``building`` with their doors and windows; the bus ``bus`` and the van ``car`` (Cityscapes counts vans as cars),
each with its ramp as one of its parts.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.assets import buildings, nature, place, street, vehicles
from synthua_usd.demo.district import KERB_H, RAMP_HALF_W, RAMP_LEN, sidewalk_x_strip
from synthua_usd.demo.settings.layout import OUTDOOR_CCTV_M, Layout
from synthua_usd.demo.twin_builder import TwinBuilder
from synthua_usd.model import meshes as geo
from synthua_usd.model.materials import WALL_COLOURS
from synthua_usd.model.twin import TwinObject, TwinPart

PATH_TOP_M = 0.03
PAINTS = ("PaintRed", "PaintBlue", "PaintBlack", "PaintWhite", "PaintSilver")


def _pick(rng: np.random.Generator, options):
    return options[int(rng.integers(len(options)))]


def _clear(xy, taken: list[tuple[float, float, float]], radius: float) -> bool:
    return all(np.hypot(xy[0] - x, xy[1] - y) >= radius + r for x, y, r in taken)


def park(rng: np.random.Generator) -> tuple[list[TwinObject], Layout]:
    """A park 40-60 x 30-44 m: a lawn crossed by a main path (2.5-4 m wide) and a cross path (2-3 m), benches
    along the main path facing it, lanterns along it, flower beds and 8-16 trees on the lawn (clear of the paths
    and of the cameras), a sign at the crossing."""
    b = TwinBuilder()
    length, width = float(rng.uniform(40, 60)), float(rng.uniform(30, 44))
    x0, y0, x1, y1 = -length / 2, -width / 2, length / 2, width / 2
    py, pw = float(rng.uniform(-width / 6, width / 6)), float(rng.uniform(2.5, 4.0))
    px, cw = float(rng.uniform(-length / 5, length / 5)), float(rng.uniform(2.0, 3.0))
    surface = _pick(rng, ("Concrete", "PaverWarm", "Granite"))
    b.add("Nature", "Lawn", "grass", [TwinPart.of("Surface", geo.box((x0 - 3, y0 - 3, -1.0), (x1 + 3, y1 + 3, 0.0)), "Grass")])
    b.add("Paths", "MainPath", "sidewalk", [TwinPart.of("Surface", geo.box((x0, py - pw / 2, -0.3), (x1, py + pw / 2, PATH_TOP_M)),
                                                        surface)])
    for a, z in ((y0, py - pw / 2), (py + pw / 2, y1)):  # the cross path meets the main path, never overlaps it
        b.add("Paths", "CrossPath", "sidewalk", [TwinPart.of("Surface", geo.box((px - cw / 2, a, -0.3), (px + cw / 2, z, PATH_TOP_M)),
                                                             surface)])
    top = PATH_TOP_M
    eyes = ((x0 + 1.0, py, top), (x1 - 1.0, py, top))
    highs = ((x0 + 4.0, py + pw / 2 + 1.5, top + OUTDOOR_CCTV_M), (x1 - 4.0, py - pw / 2 - 1.5, top + OUTDOOR_CCTV_M),
             (px + cw / 2 + 1.5, y0 + 4.0, top + OUTDOOR_CCTV_M), (px - cw / 2 - 1.5, y1 - 4.0, top + OUTDOOR_CCTV_M))
    taken = [(x, y, 2.5) for x, y, _ in eyes + highs]
    side = 1.0
    for x in np.arange(x0 + 6.0, x1 - 5.0, float(rng.uniform(8.0, 12.0))):
        if abs(x - px) < cw / 2 + 1.5:
            continue
        y = py + side * (pw / 2 + 0.25)
        b.add("Furniture", "Bench", "furniture", place(street.bench(), (float(x), y, 0.0), -90.0 * side))
        taken.append((float(x), y, 1.2))
        side = -side
    for x in np.arange(x0 + 8.0, x1 - 4.0, 15.0):
        y = py - side * (pw / 2 + 0.4)
        pole, lamp = street.light_pole(4.0)
        b.add("Lighting", "Pole", "light_pole", place(pole, (float(x), y, 0.0)))
        b.add("Lighting", "Lantern", "luminaire", place(lamp, (float(x), y, 0.0)))
        taken.append((float(x), y, 0.6))
    b.add("Signage", "ParkSign", "signage", place(street.sign(kind="street"), (px + cw / 2 + 0.6, py + pw / 2 + 0.6, 0.0), -90.0))

    def on_lawn(radius: float, tries: int = 200):
        for _ in range(tries):
            xy = (float(rng.uniform(x0 + 2, x1 - 2)), float(rng.uniform(y0 + 2, y1 - 2)))
            if (abs(xy[1] - py) > pw / 2 + radius + 0.5 and abs(xy[0] - px) > cw / 2 + radius + 0.5
                    and _clear(xy, taken, radius)):
                taken.append((*xy, radius))
                return xy
        return None

    for _ in range(int(rng.integers(2, 5))):
        xy = on_lawn(2.0)
        if xy is not None:
            b.add("Nature", "FlowerBed", "grass", place(nature.grass_bed(3.0, 2.0), (*xy, 0.0), float(rng.uniform(0, 180))))
    for _ in range(int(rng.integers(8, 17))):
        xy = on_lawn(3.0)
        if xy is not None:
            b.add("Nature", "Tree", "vegetation", place(nature.tree(rng, float(rng.uniform(5.0, 8.0))), (*xy, -0.1)))
    return b.objects, Layout((px, py, top + 0.8), eyes, highs)


def vehicle_ramp(rng: np.random.Generator) -> tuple[list[TwinObject], Layout]:
    """A street 36-50 m long (two lanes, 7 m) between sidewalks 3-4.5 m deep with a zebra crossing and a kerb ramp
    at each end of it; at the north kerb a low-floor bus with its front door's ramp down onto the sidewalk, at a
    stop with a sign and a shelter (half of the streets), else a van with its rear doors open and its ramp down to
    the road; cars parked along the south kerb, light poles, row houses behind both sidewalks."""
    b = TwinBuilder()
    length, depth = float(rng.uniform(36, 50)), float(rng.uniform(3.0, 4.5))
    half, road = length / 2, 3.5
    xc = float(rng.uniform(-half + 6.0, -half / 3))
    b.add("Nature", "Ground", "grass", [TwinPart.of("Surface", geo.box((-half - 1, -40.0, -1.0), (half + 1, 40.0, -0.02)), "Grass")])
    b.add("Streets", "Road", "road", [TwinPart.of("Surface", geo.box((-half, -road, -0.3), (half, road, 0.0)), "Asphalt")])
    for name, kerb, back in (("North", road, road + depth), ("South", -road, -road - depth)):
        b.add("Sidewalks", name, "sidewalk", sidewalk_x_strip(-half, half, kerb, back, [xc]))
        sgn = 1.0 if back > kerb else -1.0
        ya, yb = sorted((kerb, kerb + sgn * RAMP_LEN))
        low, high = (ya, yb) if sgn > 0 else (yb, ya)
        pts, tris = geo.ramp(xc - RAMP_HALF_W, xc + RAMP_HALF_W, low, high, 0.005, KERB_H, -0.3)
        b.add("CurbRamps", "Ramp", "curb_ramp", [TwinPart.of("Surface", (pts, tris), "RampConcrete")])
    bars = [geo.box((xc - 1.5, y, 0.0), (xc + 1.5, y + 0.5, 0.01)) for y in np.arange(-road + 0.25, road - 0.4, 1.0)]
    b.add("Crosswalks", "Zebra", "crosswalk", [TwinPart.of("Bars", geo.merge(*bars), "RoadPaint")])
    if rng.random() < 0.5:  # a bus heading west, its right side (the door) at the north kerb, 0.25 m from it
        xv = float(rng.uniform(xc + 10.0, half - 7.0))
        gap = 0.25
        ramp = gap + 0.2 + 0.6
        b.add("Vehicles", "Bus", "bus", place(vehicles.bus(ramp_m=ramp, kerb_m=KERB_H), (xv, road - 1.275 - gap, 0.0), 180.0))
        foot = (xv - 4.5, road + ramp - gap)
        b.add("Signage", "BusStop", "signage", place(street.sign(kind="bus"), (foot[0] - 2.0, road + 0.6, KERB_H), -90.0))
        b.add("Furniture", "BusShelter", "furniture", place(street.bus_shelter(), (foot[0] + 3.0, road + depth - 0.9, KERB_H), -90.0))
    else:  # a van heading west at the north kerb, its ramp down behind it onto the road
        xv = float(rng.uniform(xc + 6.0, half - 7.0))
        ramp = float(rng.uniform(1.4, 1.8))
        b.add("Vehicles", "Van", "car", place(vehicles.van(paint=_pick(rng, PAINTS), ramp_m=ramp), (xv, road - 1.0 - 0.3, 0.0), 180.0))
        foot = (xv + 2.6 + ramp, road - 1.3)
    x = -half + 3.0
    while x < half - 3.0:  # cars along the south kerb, clear of the crossing
        if abs(x - xc) > 4.5 and rng.random() < 0.6:
            b.add("Vehicles", "Car", "car", place(vehicles.car(float(rng.uniform(3.9, 4.6)), paint=_pick(rng, PAINTS)),
                                                  (x, -road + 1.2, 0.0)))
        x += 6.0
    for x in np.arange(-half + 4.0, half - 2.0, float(rng.uniform(12.0, 16.0))):
        for y, heading in ((road + 0.6, -90.0), (-road - 0.6, 90.0)):
            pole, lamp = street.light_pole(7.0, arm=1.8)
            b.add("Lighting", "Pole", "light_pole", place(pole, (float(x), y, KERB_H), heading))
            b.add("Lighting", "Luminaire", "luminaire", place(lamp, (float(x), y, KERB_H), heading))
    house_depth = 10.0
    for front, heading in ((road + depth, -90.0), (-road - depth, 90.0)):
        x = -half - 2.0
        while x < half + 2.0:
            width = float(rng.uniform(6.0, 9.0))
            at = (x + width / 2, front + np.sign(front) * house_depth / 2, KERB_H)
            parts = buildings.row_house(rng, width, house_depth, int(rng.integers(2, 4)),
                                        f"Wall{int(rng.integers(len(WALL_COLOURS)))}", foundation_m=0.5)
            stem = b.add("Buildings", "House", "building", place(parts.structure, at, heading))
            for k, door in enumerate(parts.doors):
                b.sub(stem, "Door", k, "door", place(door, at, heading))
            for k, window in enumerate(parts.windows):
                b.sub(stem, "Window", k, "window", place(window, at, heading))
            x += width
    fx, fy = foot
    walk = road + depth / 2
    eyes = ((max(fx - 9.0, -half + 1.5), walk, KERB_H), (min(fx + 9.0, half - 1.5), walk, KERB_H))
    z = KERB_H + OUTDOOR_CCTV_M
    # all on the north sidewalk (a bus at the north kerb hides its ramp from the south side), either side of the
    # ramp: at its back edge and over its middle (the light poles stand by the kerb)
    highs = ((fx - 10.0, road + depth - 0.6, z), (fx + 10.0, road + depth - 0.6, z), (fx - 7.0, walk, z),
             (fx + 7.0, walk, z))
    return b.objects, Layout((fx, min(fy, walk), KERB_H + 0.8), eyes, highs)
