"""The indoor settings: a corridor, a hall, a shop, a clinic's waiting area and a lift lobby, each a closed room
(:mod:`synthua_usd.demo.settings.room_shell`) with its fittings, its size and layout drawn from a seeded generator.

Fittings keep the room's ends and corners clear (1.5 m and more), where its cameras stand
(:func:`synthua_usd.demo.settings.layout.room_layout`). Classes beyond the shell's: shelving, rows of seats and
benches ``furniture`` (the class of street benches: people sit on their seats), counters ``stand`` (a shop's till
or a reception desk is what a market stand is: a counter one is served across), small tables ``table``, chairs
``chair``, signs ``signage``, handrails ``railing``, potted plants ``vegetation``, pillars ``building``.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.assets import interior, market, place
from synthua_usd.demo.settings.layout import Layout, room_layout
from synthua_usd.demo.settings.room_shell import Room, ceiling_lights, doors_along
from synthua_usd.demo.twin_builder import TwinBuilder
from synthua_usd.model.materials import WALL_COLOURS
from synthua_usd.model.twin import TwinObject

#: Floors: tiles (the largo's pavers), stone, wood, screed.
FLOORS = ("PaverWarm", "Granite", "Wood", "Concrete")
WALLS = tuple(f"Wall{i}" for i in range(len(WALL_COLOURS))) + ("Stucco", "Whitewash")
SIGNS = ("SignBlue", "SignRed", "PlasticWhite")


def _pick(rng: np.random.Generator, options):
    return options[int(rng.integers(len(options)))]


def _finish(b: TwinBuilder, room: Room, rng: np.random.Generator, spacing: float) -> None:
    room.build(b, _pick(rng, FLOORS), _pick(rng, WALLS))
    ceiling_lights(b, room, spacing, rng)


def _signs_over_doors(b: TwinBuilder, room: Room, rng: np.random.Generator, share: float = 0.6) -> None:
    """A plate above a share of the doors (a room number, an exit)."""
    for o in room.openings:
        if o.kind in ("door", "lift") and rng.random() < share and o.top + 0.3 < room.height:
            at, heading = room.at(o.side, o.along, 0.0, o.top + 0.2)
            b.add("Signage", "DoorSign", "signage", place(interior.wall_sign(0.5, 0.16, _pick(rng, SIGNS)), at, heading))


def _clear_of_sightlines(xy, layout: Layout, clearance: float) -> bool:
    """Whether ``xy`` is ``clearance`` metres or more from every line from a high spot (a CCTV) to the focus."""
    p, f = np.asarray(xy, float), np.asarray(layout.focus[:2], float)
    for spot in layout.high_spots:
        a = np.asarray(spot[:2], float)
        t = np.clip((p - a) @ (f - a) / max(float((f - a) @ (f - a)), 1e-9), 0.0, 1.0)
        if np.linalg.norm(a + t * (f - a) - p) < clearance:
            return False
    return True


def corridor(rng: np.random.Generator) -> tuple[list[TwinObject], Layout]:
    """A corridor 18-32 m long and 2.2-3.2 m wide: doors along both walls every 3-5 m, windows along one wall
    between its doors (half of them), a double door at one end, handrails (60 %), a row of seats in a recess-free
    stretch or two, signs over the doors, ceiling lights every 2.5-3.5 m."""
    b = TwinBuilder()
    length, width, height = float(rng.uniform(18, 32)), float(rng.uniform(2.2, 3.2)), float(rng.uniform(2.6, 3.2))
    room = Room(-length / 2, -width / 2, length / 2, width / 2, height)
    for side in "SN":
        doors_along(room, side, rng, (3.0, 5.0), keep=2.0)
    if rng.random() < 0.5:
        for a, z in room.free_stretches("N", 0.4):
            if z - a > 1.6:
                room.window("N", (a + z) / 2, min(z - a - 0.4, 2.4), 0.9, 2.2)
    room.door("E", 0.0, min(1.8, width - 0.4))
    _finish(b, room, rng, float(rng.uniform(2.5, 3.5)))
    rails = rng.random() < 0.6
    for side in "SN":
        stretches = room.free_stretches(side, 0.15)
        for a, z in stretches:
            if rails and z - a > 0.8:
                at, heading = room.at(side, (a + z) / 2)
                b.add("Railings", "Handrail", "railing", place(interior.handrail(z - a), at, heading))
        if width > 2.5 and side == "S":
            long = [(a, z) for a, z in stretches if z - a > 2.8 and a > room.x0 + 2.0 and z < room.x1 - 2.0]
            for a, z in long[:2]:
                at, heading = room.at(side, (a + z) / 2, 0.35)
                b.add("Furniture", "Seats", "furniture", place(interior.seat_row(3), at, heading))
    _signs_over_doors(b, room, rng)
    return b.objects, room_layout(room.x0, room.y0, room.x1, room.y1, height)


def hall(rng: np.random.Generator) -> tuple[list[TwinObject], Layout]:
    """A station or entrance hall 16-26 x 12-18 m, 4.5-6.5 m high: tall windows along its south wall, entrance
    doors in the north wall, pillars every 6 m (none within 1 m of a CCTV's line of sight to the focus), rows of
    seats, a kiosk counter, signs on posts and hanging, potted plants, ceiling lights every 3.5 m."""
    b = TwinBuilder()
    length, width, height = float(rng.uniform(16, 26)), float(rng.uniform(12, 18)), float(rng.uniform(4.5, 6.5))
    room = Room(-length / 2, -width / 2, length / 2, width / 2, height)
    for x in np.arange(room.x0 + 3.0, room.x1 - 2.0, float(rng.uniform(3.5, 5.0))):
        room.window("S", float(x), 2.2, 0.6, 3.8)
    for x in (-3.0, 3.0):
        room.door("N", x + float(rng.uniform(-1, 1)), 1.8)
    room.door("W", float(rng.uniform(-2, 2)), 1.6)
    _finish(b, room, rng, 3.5)
    layout = room_layout(room.x0, room.y0, room.x1, room.y1, height)
    pillars = [(float(x), float(y)) for x in np.arange(-6.0, length / 2 - 3.0, 6.0) for y in (-width / 4, width / 4)
               if _clear_of_sightlines((float(x), float(y)), layout, 1.0)]
    for x, y in pillars:
        b.add("Structure", "Pillar", "building", place(interior.pillar(0.5, height), (x, y, 0.0)))
    rows = int(rng.integers(2, 5))
    for k in range(rows):
        y = -width / 4 + 1.5 + 1.3 * k
        b.add("Furniture", "Seats", "furniture", place(interior.seat_row(int(rng.integers(4, 7))), (-length / 4, y, 0.0), 90.0))
    at = (length / 4, width / 2 - 1.2, 0.0)
    b.add("Shop", "Kiosk", "stand", place(interior.counter(2.4, 1.1), at, -90.0))
    for x, y in pillars[:: 2]:
        b.add("Signage", "HangingSign", "signage",
              place(interior.hanging_sign(1.4, 0.4, 1.2, _pick(rng, SIGNS)), (x + 1.5, y, height)))
    for x, y in pillars[1::3]:
        b.add("Nature", "Plant", "vegetation", place(interior.potted_plant(float(rng.uniform(1.0, 1.6))), (x + 0.7, y + 0.7, 0.0)))
    return b.objects, layout


def shop(rng: np.random.Generator) -> tuple[list[TwinObject], Layout]:
    """A shop 10-16 x 8-12 m, 3.0-3.6 m high: a glazed front (south) with a double door, gondola shelving along the
    room in rows either side of a middle aisle (aisles 1.6-2.0 m wide, a cross aisle halfway), shelving along the
    back wall, a counter by the door, signs hanging over the aisles, ceiling lights every 2.5 m."""
    b = TwinBuilder()
    length, width, height = float(rng.uniform(10, 16)), float(rng.uniform(8, 12)), float(rng.uniform(3.0, 3.6))
    room = Room(-length / 2, -width / 2, length / 2, width / 2, height)
    door = float(rng.uniform(-length / 4, length / 4))
    room.door("S", door, 1.8)
    for a, z in room.free_stretches("S", 0.2):
        if z - a > 1.2:
            room.window("S", (a + z) / 2, z - a - 0.2, 0.4, 2.6)
    _finish(b, room, rng, 2.5)
    aisle = float(rng.uniform(1.6, 2.0))
    goods = _pick(rng, ("Goods", "PlasticWhite", "CanvasRed", "CanvasBlue", "CanvasYellow"))
    run = (length - 5.0 - 1.6) / 2  # each half of a row, a cross aisle between them
    y = aisle / 2 + 0.25
    while y + 0.25 < width / 2 - 2.2:  # the front 2.2 m (door, till) and the back wall's shelving kept clear
        for side in (-1.0, 1.0):
            if side < 0 or y + 0.25 < width / 2 - 1.5:
                for x in (-(run + 1.6) / 2, (run + 1.6) / 2):
                    b.add("Furniture", "Shelving", "furniture", place(interior.shelf(run, 1.8, goods=goods),
                                                                      (x, side * y, 0.0), 90.0))
        y += 0.5 + aisle
    for x in (-(run + 1.6) / 2, (run + 1.6) / 2):
        b.add("Signage", "AisleSign", "signage", place(interior.hanging_sign(0.9, 0.3, 0.5, _pick(rng, SIGNS)),
                                                        (x, 0.0, height)))
    for x in np.arange(room.x0 + 2.0, room.x1 - 2.0, 2.1):
        at, heading = room.at("N", float(x), 0.3)
        b.add("Furniture", "WallShelving", "furniture", place(interior.shelf(2.0, 2.0, 0.5, goods=goods), at, heading))
    till = door + (2.5 if door < 0 else -2.5)
    b.add("Shop", "Counter", "stand", place(interior.counter(2.0), (till, room.y0 + 1.2, 0.0), 90.0))
    return b.objects, room_layout(room.x0, room.y0, room.x1, room.y1, height)


def clinic(rng: np.random.Generator) -> tuple[list[TwinObject], Layout]:
    """A clinic's waiting area 10-16 x 7-10 m, 2.7-3.1 m high: a reception counter, rows of seats along the walls
    and facing each other in the middle, small tables, consulting-room doors with numbers, windows (half of
    them), potted plants, ceiling lights every 2.5 m."""
    b = TwinBuilder()
    length, width, height = float(rng.uniform(10, 16)), float(rng.uniform(7, 10)), float(rng.uniform(2.7, 3.1))
    room = Room(-length / 2, -width / 2, length / 2, width / 2, height)
    doors_along(room, "N", rng, (2.5, 3.5), keep=2.0)
    room.door("E", float(rng.uniform(-1, 1)), 1.6)
    if rng.random() < 0.5:
        for x in np.arange(room.x0 + 2.5, room.x1 - 2.0, 2.5):
            room.window("S", float(x), 1.4, 0.9, 2.3)
    _finish(b, room, rng, 2.5)
    # the reception desk along the north wall near the west end, off the room's middle line (where eye-level
    # cameras look along the room)
    b.add("Reception", "Desk", "stand", place(interior.counter(2.4, 1.05, 0.7), (room.x0 + 3.3, room.y1 - 1.4, 0.0), -90.0))
    seat = _pick(rng, ("Seat", "CanvasBlue", "CanvasRed", "PlasticWhite"))
    for x in np.arange(room.x0 + 4.5, room.x1 - 2.5, 2.6):
        at, heading = room.at("S", float(x), 0.35)
        b.add("Furniture", "Seats", "furniture", place(interior.seat_row(4, seat=seat), at, heading))
    for x in np.arange(-length / 2 + 5.0, length / 2 - 3.0, 3.6):
        b.add("Furniture", "Seats", "furniture", place(interior.seat_row(3, seat=seat), (float(x), 0.2, 0.0), -90.0))
        b.add("Furniture", "Table", "table", place(market.table(0.3), (float(x) + 1.6, 0.5, 0.0)))
    _signs_over_doors(b, room, rng, share=0.9)
    for x, y in ((room.x1 - 1.0, room.y0 + 0.5), (room.x0 + 4.0, room.y1 - 0.5)):
        b.add("Nature", "Plant", "vegetation", place(interior.potted_plant(float(rng.uniform(0.9, 1.5))), (x, y, 0.0)))
    return b.objects, room_layout(room.x0, room.y0, room.x1, room.y1, height)


def lift_lobby(rng: np.random.Generator) -> tuple[list[TwinObject], Layout]:
    """A lift lobby 7-11 x 5-8 m, 2.7-3.2 m high: two or three lifts in the north wall (steel doors in steel
    surrounds, a call panel beside each, a floor indicator above), a door to the stairs, a bench or a row of seats
    facing the lifts, windows (half of them), a potted plant, ceiling lights every 2.5 m."""
    b = TwinBuilder()
    length, width, height = float(rng.uniform(7, 11)), float(rng.uniform(5, 8)), float(rng.uniform(2.7, 3.2))
    room = Room(-length / 2, -width / 2, length / 2, width / 2, height)
    lifts = int(rng.integers(2, 4))
    xs = np.linspace(-(lifts - 1) * 1.1, (lifts - 1) * 1.1, lifts)
    for x in xs:
        room.door("N", float(x), float(rng.uniform(0.9, 1.1)), kind="lift")
    room.door("E", float(rng.uniform(-1, 1)), 1.0)
    if rng.random() < 0.5:
        room.window("S", float(rng.uniform(-1.5, 1.5)), 2.4, 0.9, 2.3)
    _finish(b, room, rng, 2.5)
    for x in xs:
        at, heading = room.at("N", float(x) + 0.75, 0.0, 1.1)
        b.add("Signage", "CallPanel", "signage", place(interior.wall_sign(0.12, 0.3, "Metal"), at, heading))
        at, heading = room.at("N", float(x), 0.0, 2.45)
        b.add("Signage", "FloorIndicator", "signage", place(interior.wall_sign(0.4, 0.12, "PaintBlack"), at, heading))
    at, heading = room.at("S", float(rng.uniform(-length / 4, length / 4)), 0.35)
    b.add("Furniture", "Seats", "furniture", place(interior.seat_row(int(rng.integers(2, 4))), at, heading))
    b.add("Nature", "Plant", "vegetation", place(interior.potted_plant(1.2), (room.x0 + 0.6, room.y1 - 1.4, 0.0)))
    return b.objects, room_layout(room.x0, room.y0, room.x1, room.y1, height)
