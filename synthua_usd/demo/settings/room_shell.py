"""A closed room as plain data: floor, walls with doors and windows in them, ceiling, ceiling lights, and where
fittings go along its walls. What every indoor setting (:mod:`synthua_usd.demo.settings.indoor`) is built in.

Frame: x east, y north, Z up, metres; the room's inside spans ``[x0, x1] x [y0, y1]`` from the floor (z = 0) to
the ceiling (z = ``height``). Walls are :data:`WALL_M` thick outside that box and reach 0.3 m below the floor; the
floor slab covers the inside only (so the walkable grid never finds floor under a wall), the ceiling slab the
walls too.

Classes (the class map has no room classes; the nearest honest ones): the floor is ``sidewalk`` (what people walk
on, and what the walkable grid and the crowd take as walkable), the walls and the ceiling are one ``building``
(a room's walls are its building's), doors and lift doors ``door``, window panes ``window``, ceiling lights
``luminaire`` (their diffusers lamps of role ``ceiling``, on under every condition).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from synthua_usd.assets import interior, place
from synthua_usd.demo.twin_builder import TwinBuilder
from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart

WALL_M = 0.2
#: Sides of a room: the inward heading of a fitting on that wall (its +X into the room), degrees.
HEADING = {"S": 90.0, "N": -90.0, "W": 0.0, "E": 180.0}
DOOR_HEIGHT_M = 2.1


@dataclass(frozen=True)
class Opening:
    """A hole in the wall ``side`` (S, N, W, E) centred ``along`` it (x for S and N, y for W and E), ``width``
    wide from ``bottom`` to ``top`` above the floor, filled by a ``kind``: ``door``, ``lift`` (steel doors in a
    steel surround) or ``window`` (a pane)."""

    side: str
    along: float
    width: float
    bottom: float
    top: float
    kind: str


@dataclass
class Room:
    """A room's inside ``[x0, x1] x [y0, y1]`` and ``height``; openings are collected, then :meth:`build` adds
    the shell to a :class:`TwinBuilder`."""

    x0: float
    y0: float
    x1: float
    y1: float
    height: float
    openings: list[Opening] = field(default_factory=list)

    @property
    def centre(self) -> tuple[float, float]:
        return (self.x0 + self.x1) / 2, (self.y0 + self.y1) / 2

    def span(self, side: str) -> tuple[float, float]:
        """The inside's extent along ``side``."""
        return (self.x0, self.x1) if side in "SN" else (self.y0, self.y1)

    def at(self, side: str, along: float, inset: float = 0.0, z: float = 0.0) -> tuple[tuple[float, float, float], float]:
        """(point, heading) of a fitting on the wall ``side`` at ``along``, ``inset`` metres in from its face:
        heading turns an asset's +X into the room."""
        if side == "S":
            return (along, self.y0 + inset, z), HEADING[side]
        if side == "N":
            return (along, self.y1 - inset, z), HEADING[side]
        if side == "W":
            return (self.x0 + inset, along, z), HEADING[side]
        return (self.x1 - inset, along, z), HEADING[side]

    def door(self, side: str, along: float, width: float = 0.95, kind: str = "door") -> None:
        self.openings.append(Opening(side, along, width, 0.0, DOOR_HEIGHT_M, kind))

    def window(self, side: str, along: float, width: float, sill: float, head: float) -> None:
        self.openings.append(Opening(side, along, width, sill, min(head, self.height - 0.3), "window"))

    def free_stretches(self, side: str, margin: float = 0.3) -> list[tuple[float, float]]:
        """The stretches of the wall ``side`` between its openings (each opening widened by ``margin``)."""
        lo, hi = self.span(side)
        cuts = sorted((o.along - o.width / 2 - margin, o.along + o.width / 2 + margin) for o in self.openings
                      if o.side == side)
        out, start = [], lo
        for a, b in cuts:
            if a > start:
                out.append((start, a))
            start = max(start, b)
        if hi > start:
            out.append((start, hi))
        return out

    def build(self, b: TwinBuilder, floor: str, wall: str, ceiling: str = "Whitewash") -> None:
        """Add the floor (``sidewalk``), the walls and ceiling (one ``building``) and what fills the openings."""
        x0, y0, x1, y1, h, t = self.x0, self.y0, self.x1, self.y1, self.height, WALL_M
        b.add("Room", "Floor", "sidewalk", [TwinPart.of("Surface", geo.box((x0, y0, -0.3), (x1, y1, 0.0)), floor)])
        walls, fills = [], []
        for side in "SNWE":
            pieces, holes = self._wall(side, t, h)
            walls += pieces
            fills += holes
        stem = b.add("Room", "Shell", "building", [TwinPart.of("Walls", geo.merge(*walls), wall),
                                                   TwinPart.of("Ceiling", geo.box((x0 - t, y0 - t, h), (x1 + t, y1 + t, h + 0.2)),
                                                               ceiling)])
        for k, (opening, label, parts) in enumerate(fills):
            b.sub(stem, opening.kind.title(), k, label, parts)
            if opening.kind == "lift":
                at, heading = self.at(opening.side, opening.along)
                b.add("Room", "LiftSurround", "building", place(interior.lift_frame(opening.width, opening.top), at, heading))

    def _wall(self, side: str, t: float, h: float) -> tuple[list[geo.Mesh], list[tuple[Opening, str, list[TwinPart]]]]:
        """The wall ``side`` as boxes round its openings, and each opening's fill (door panel, lift doors, pane)."""
        lo, hi = self.span(side)
        if side in "SN":  # the long walls run past the corners
            lo, hi = lo - t, hi + t
        face = {"S": self.y0, "N": self.y1, "W": self.x0, "E": self.x1}[side]
        out = -1.0 if side in "SW" else 1.0  # the wall lies outside the face

        def box(a: float, b: float, z0: float, z1: float, d0: float = 0.0, d1: float = t) -> geo.Mesh:
            """A box from ``a`` to ``b`` along the wall, ``d0``-``d1`` out from the face."""
            c0, c1 = sorted((face + out * d0, face + out * d1))
            return geo.box((a, c0, z0), (b, c1, z1)) if side in "SN" else geo.box((c0, a, z0), (c1, b, z1))

        pieces, fills, start = [], [], lo
        for o in sorted((o for o in self.openings if o.side == side), key=lambda o: o.along):
            a, b = o.along - o.width / 2, o.along + o.width / 2
            if a > start:
                pieces.append(box(start, a, -0.3, h))
            pieces += [box(a, b, -0.3, o.bottom), box(a, b, o.top, h)]
            start = b
            if o.kind == "window":  # a pane recessed 8 cm, 2 cm thick, in a 5 cm frame of the wall
                fills.append((o, "window", [TwinPart.of("Pane", box(a, b, o.bottom, o.top, 0.08, 0.1), "Glass")]))
            elif o.kind == "lift":
                at, heading = self.at(side, o.along, -0.06)
                fills.append((o, "door", place(interior.lift_door(o.width - 0.02, o.top), at, heading)))
            else:  # a door leaf recessed 5 cm, 5 cm thick
                fills.append((o, "door", [TwinPart.of("Leaf", box(a + 0.01, b - 0.01, 0.0, o.top - 0.01, 0.05, 0.1),
                                                      "DoorWood")]))
        if hi > start:
            pieces.append(box(start, hi, -0.3, h))
        return pieces, fills


def ceiling_lights(b: TwinBuilder, room: Room, spacing: float, rng: np.random.Generator, margin: float = 1.0) -> None:
    """Ceiling panels (``luminaire``) in a grid of about ``spacing`` metres over the inside, ``margin`` from the
    walls; a square panel or (one room in three) a 1.2 m strip."""
    strip = rng.random() < 0.33
    for x in _steps(room.x0 + margin, room.x1 - margin, spacing):
        for y in _steps(room.y0 + margin, room.y1 - margin, spacing):
            parts = interior.ceiling_panel(0.6)
            if strip:
                parts = [p.moved(p.points * [1.0, 2.0, 1.0]) for p in parts]
            b.add("Lighting", "CeilingLight", "luminaire", place(parts, (x, y, room.height)))


def _steps(lo: float, hi: float, spacing: float) -> np.ndarray:
    """Evenly spaced points from ``lo`` to ``hi`` about ``spacing`` apart (at least one, the middle)."""
    if hi <= lo:
        return np.array([(lo + hi) / 2])
    count = max(int(round((hi - lo) / spacing)) + 1, 1)
    return np.linspace(lo, hi, count) if count > 1 else np.array([(lo + hi) / 2])


def doors_along(room: Room, side: str, rng: np.random.Generator, every: tuple[float, float], keep: float = 1.5,
                width: tuple[float, float] = (0.9, 1.0)) -> list[float]:
    """Doors on the wall ``side`` every U(``every``) metres, ``keep`` clear of its ends; returns where they are."""
    lo, hi = room.span(side)
    at, out = lo + keep + float(rng.uniform(0.0, every[0])), []
    while at < hi - keep:
        room.door(side, at, float(rng.uniform(*width)))
        out.append(at)
        at += float(rng.uniform(*every))
    return out
