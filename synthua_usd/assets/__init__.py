"""Parametric low-poly assets as plain geometry: each builder returns named parts in local metres.

A builder returns ``list[Piece]``: (part name, (points, triangles), material key). Local frames put the
asset's footprint centre at the origin on z = 0 with its front facing +X, unless a docstring says
otherwise. Placement (translation, rotation about Z) is done by :func:`place`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from synthua_usd.geometry import Mesh


class Piece(NamedTuple):
    name: str
    mesh: Mesh
    material: str


def place(pieces: list[Piece], at, heading_deg: float = 0.0) -> list[Piece]:
    """Rotate ``pieces`` about Z by ``heading_deg`` then move them to ``at`` (x, y, z)."""
    a = np.radians(heading_deg)
    rot = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    out = []
    for name, (pts, tris), mat in pieces:
        out.append(Piece(name, (pts @ rot.T + np.asarray(at, float), tris), mat))
    return out
