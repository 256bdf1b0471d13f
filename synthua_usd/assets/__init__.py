"""Parametric low-poly assets as plain geometry: each builder returns named parts in local metres.

A builder returns ``list[TwinPart]`` (part name, points, triangles, material key of
:mod:`synthua_usd.model.materials`). Local frames put the asset's footprint centre at the origin on z = 0 with
its front facing +X, unless a docstring says otherwise. Placement (translation, rotation about Z) is done
by :func:`place`.
"""

from __future__ import annotations

import numpy as np

from synthua_usd.model.twin import TwinPart


def place(parts: list[TwinPart], at, heading_deg: float = 0.0) -> list[TwinPart]:
    """Rotate ``parts`` about Z by ``heading_deg`` then move them to ``at`` (x, y, z)."""
    a = np.radians(heading_deg)
    rot = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    return [p.moved(p.points @ rot.T + np.asarray(at, float)) for p in parts]
