"""Trees, grass beds and animals (dogs, pigeons)."""

from __future__ import annotations

import numpy as np

from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart


def tree(rng: np.random.Generator, height: float = 7.0) -> list[TwinPart]:
    """A broadleaf tree: trunk and a crown of a few overlapping blobs, jittered by ``rng``."""
    trunk_h = height * 0.45
    blobs = []
    for _ in range(4):
        off = rng.uniform(-0.8, 0.8, 3) * [1, 1, 0.5]
        r = rng.uniform(1.2, 1.9)
        blobs.append(geo.ellipsoid((off[0], off[1], trunk_h + 1.4 + off[2]), (r, r, r * 0.85), subdivisions=3))
    return [TwinPart.of("Trunk", geo.cylinder((0, 0, trunk_h / 2 + 0.3), 0.18, trunk_h + 0.6, sections=12), "Bark"),
            TwinPart.of("Crown", geo.merge(*blobs), "Leaves")]


def araucaria(height: float = 12.0) -> list[TwinPart]:
    """Paraná pine, Curitiba's emblem: a tall bare trunk and a flat, candelabra-like crown."""
    crown = geo.merge(geo.ellipsoid((0, 0, height - 0.8), (3.2, 3.2, 0.9), subdivisions=3),
                      geo.ellipsoid((0, 0, height - 2.0), (2.6, 2.6, 0.7), subdivisions=2))
    return [TwinPart.of("Trunk", geo.cylinder((0, 0, (height - 1.5) / 2), 0.22, height - 1.5, sections=12), "Bark"),
            TwinPart.of("Crown", crown, "Leaves")]


def grass_bed(length: float, width: float, height: float = 0.25) -> list[TwinPart]:
    """A raised bed: kerb stones around a grass surface."""
    l, w = length / 2, width / 2
    return [TwinPart.of("Grass", geo.box((-l + 0.1, -w + 0.1, 0.0), (l - 0.1, w - 0.1, height - 0.03)), "Grass")]


def dog(size: float = 1.0) -> list[TwinPart]:
    s = size
    legs = [geo.box((x - 0.03 * s, y - 0.03 * s, 0.0), (x + 0.03 * s, y + 0.03 * s, 0.3 * s))
            for x in (-0.22 * s, 0.22 * s) for y in (-0.08 * s, 0.08 * s)]
    return [TwinPart.of("Body", geo.merge(geo.box((-0.3 * s, -0.1 * s, 0.28 * s), (0.3 * s, 0.1 * s, 0.48 * s)),
                                    geo.box((0.28 * s, -0.08 * s, 0.42 * s), (0.45 * s, 0.08 * s, 0.58 * s)),
                                    geo.box((-0.45 * s, -0.02 * s, 0.42 * s), (-0.3 * s, 0.02 * s, 0.46 * s)), *legs),
                  "Fur")]


def pigeon() -> list[TwinPart]:
    return [TwinPart.of("Body", geo.merge(geo.ellipsoid((0, 0, 0.1), (0.15, 0.07, 0.07), subdivisions=1),
                                    geo.sphere((0.13, 0, 0.19), 0.04, subdivisions=1)), "Feathers")]
