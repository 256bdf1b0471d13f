"""Distractors as plain data: objects scattered in a scene, in the manner of domain-randomisation papers (Tobin et
al. 2017; Tremblay et al. 2018): primitive shapes, everyday objects and hard negatives (strollers, shopping
trolleys, empty wheelchairs) of :mod:`synthua_usd.assets.distractor_objects`, in random colours or random
two-colour patterns, on the walkable ground and on the tops of tables, counters and shelves.

Drawn once per scene (seed) from a stream of its own (``distractors``), after the scene's crowd, so turning them on
moves no other draw; placed by rays against the twin (:class:`~synthua_usd.randomisation.view.WalkArea`): a ground
distractor stands on a flat walkable spot whose footprint and height nothing of the twin enters, away from the
cameras and the bench seats; a surface one on a flat top with room over it. The crowd, placed per view afterwards,
keeps clear of the ground distractors' discs, and the distractors count as occluders when aid users are placed in
view, so they never hide the aid users placed to be seen.
"""

from __future__ import annotations

import colorsys
import math
from dataclasses import asdict, dataclass

import numpy as np

from synthua_usd.assets import place
from synthua_usd.assets.distractor_objects import CATALOGUE, DISTRACTOR_OBJECTS, KEPT_MATERIALS
from synthua_usd.assets.look_images import FABRICS
from synthua_usd.core.errors import InputError
from synthua_usd.geometry.uv import box_uvs
from synthua_usd.model.materials import PALETTE
from synthua_usd.model.scene import Material
from synthua_usd.model.srgb import to_linear

Range = tuple[float, float]
#: Classes whose level tops take surface distractors, and the heights of those tops above the ground (a table's
#: 0.75 m, a counter's 1.05 m, shelf boards; not bench seats, where people sit).
SURFACE_CLASSES = ("table", "stand", "furniture")
SURFACE_HEIGHT_M = (0.6, 1.9)
#: The size of surface distractors (primitives only), metres.
SURFACE_SIZE_M = (0.06, 0.3)
TRIES = 30


@dataclass(frozen=True)
class DistractorRandomisation:
    """Objects scattered in each scene: on the ground ~Poisson(``ground_per_100m2`` per 100 m² of walkable area,
    drawn per scene), at most ``max_ground``; on table, counter and shelf tops U{``on_surfaces``} small primitives;
    each of ``objects`` uniformly, primitives ``primitive_size_m`` along each axis, in random colours (HSV uniform),
    a share ``textured_share`` with a random two-colour pattern; none within ``camera_clearance_m`` of a camera.
    Off by default: a config that does not ask for it renders as before."""

    enabled: bool = False
    ground_per_100m2: Range = (1.0, 4.0)
    max_ground: int = 60
    on_surfaces: Range = (0, 6)
    objects: tuple[str, ...] = DISTRACTOR_OBJECTS
    primitive_size_m: Range = (0.15, 0.8)
    textured_share: float = 0.5
    camera_clearance_m: float = 1.5

    def __post_init__(self) -> None:
        from synthua_usd.randomisation.config import low_high, names_among

        object.__setattr__(self, "ground_per_100m2", low_high("distractors.ground_per_100m2", self.ground_per_100m2,
                                                            0.0, 50.0))
        if isinstance(self.max_ground, bool) or not isinstance(self.max_ground, int) or not 0 <= self.max_ground <= 500:
            raise InputError(f"distractors.max_ground: {self.max_ground!r}; expected a whole number in [0, 500]")
        surfaces = low_high("distractors.on_surfaces", self.on_surfaces, 0, 50)
        if not all(float(v).is_integer() for v in surfaces):
            raise InputError(f"distractors.on_surfaces: {list(surfaces)}; expected two whole numbers")
        object.__setattr__(self, "on_surfaces", (int(surfaces[0]), int(surfaces[1])))
        object.__setattr__(self, "objects", names_among("distractors.objects", self.objects, DISTRACTOR_OBJECTS))
        object.__setattr__(self, "primitive_size_m", low_high("distractors.primitive_size_m", self.primitive_size_m,
                                                            0.02, 3.0))
        for name, hi in (("textured_share", 1.0), ("camera_clearance_m", 50.0)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value)
                                                                                        and 0 <= value <= hi):
                raise InputError(f"distractors.{name}: {value!r}; expected a number in [0, {hi:g}]")
            object.__setattr__(self, name, float(value))


@dataclass(frozen=True)
class Pattern:
    """A random two-colour pattern on a distractor's first part: a look image's mask (``fabric``) between the
    part's colour and ``second`` (linear RGB), repeating every ``tile_m`` metres."""

    fabric: str
    second: tuple[float, float, float]
    tile_m: float


@dataclass(frozen=True)
class Distractor:
    """One distractor: ``object`` (a name of the catalogue), its ``label``, where it stands (``position`` (3,) world
    metres, its footprint centre on the surface under it; ``heading_deg`` about Z), ``size_m`` (primitives: the box
    it fills; None for objects) and ``scale`` (objects: of their own size), one colour per part (linear RGB; parts
    of :data:`KEPT_MATERIALS` keep theirs), ``roughness`` and ``metallic``, its ``pattern`` or None, ``on`` the
    ``ground`` or a ``surface``, its footprint ``radius_m`` and ``height_m``."""

    object: str
    label: str
    position: tuple[float, float, float]
    heading_deg: float
    size_m: tuple[float, float, float] | None
    scale: float
    colours: tuple[tuple[float, float, float], ...]
    roughness: float
    metallic: float
    pattern: Pattern | None
    on: str
    radius_m: float
    height_m: float

    def parts(self) -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray | None, Material]]:
        """(part name, points (n, 3) world metres, triangles (m, 3), st (n, 2) or None, material) of each part."""
        built = CATALOGUE[self.object].build(self.size_m or (1.0, 1.0, 1.0))
        built = place([p.moved(p.points * self.scale) for p in built], self.position, self.heading_deg)
        out = []
        for k, (part, colour) in enumerate(zip(built, self.colours)):
            points, triangles, uvs = part.points, part.triangles, None
            if part.material in KEPT_MATERIALS:
                material = PALETTE[part.material]
            elif k == 0 and self.pattern is not None:
                from synthua_usd.randomisation.wear import masked_material

                material = masked_material(part.name, f"fabric_{self.pattern.fabric}", colour, self.pattern.second,
                                           self.roughness, normal=False, metallic=self.metallic)
                points, triangles, uvs = box_uvs(points, triangles, self.pattern.tile_m)
            else:
                material = Material(part.name, colour, self.roughness, self.metallic)
            out.append((part.name, points, triangles, uvs, material))
        return out


@dataclass(frozen=True)
class DistractorsDraw:
    """The distractors of one scene, in the order they were drawn (ground ones first)."""

    items: tuple[Distractor, ...]

    def discs(self) -> tuple[tuple[float, float, float], ...]:
        """(x, y, radius) of the ground distractors: what the crowd keeps clear of."""
        return tuple((d.position[0], d.position[1], d.radius_m) for d in self.items if d.on == "ground")

    def to_dict(self) -> dict:
        """As a record holds it (JSON types: tuples as lists)."""
        return {"items": [_lists(asdict(d)) for d in self.items]}


def _lists(value):
    if isinstance(value, dict):
        return {k: _lists(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_lists(v) for v in value]
    return value


@dataclass(frozen=True, eq=False)
class SurfaceTops:
    """Level tops of :data:`SURFACE_CLASSES` at :data:`SURFACE_HEIGHT_M` above the ground: ``corners`` (k, 3, 3)
    world metres of their triangles and ``weights`` (k,) their share of the area."""

    corners: np.ndarray
    weights: np.ndarray

    @classmethod
    def find(cls, vertices: np.ndarray, faces: np.ndarray, face_class: np.ndarray, area) -> "SurfaceTops":
        """From the twin's triangles (``vertices`` (n, 3), ``faces`` (m, 3), ``face_class`` (m,) names) and its
        :class:`~synthua_usd.randomisation.view.WalkArea` ``area`` (the ground under them)."""
        tris = vertices[faces[np.isin(np.asarray(face_class, object), SURFACE_CLASSES)]] if len(faces) else np.zeros((0, 3, 3))
        normal = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]) if len(tris) else np.zeros((0, 3))
        size = np.linalg.norm(normal, axis=1)
        level = (size > 1e-9) & (normal[:, 2] > 0.999 * np.maximum(size, 1e-12))
        tris, size = tris[level], size[level]
        keep = np.zeros(len(tris), bool)
        for k, centre in enumerate(tris.mean(axis=1)):
            ground = area.height_below(centre - [0.0, 0.0, 0.02])
            keep[k] = ground is not None and SURFACE_HEIGHT_M[0] <= centre[2] - ground <= SURFACE_HEIGHT_M[1]
        tris, size = tris[keep], size[keep]
        return cls(tris, size / size.sum() if len(size) else size)


def _colour(rng: np.random.Generator) -> tuple[float, float, float]:
    """A colour uniform in hue, saturation and value (value from 0.1), as linear Rec.709."""
    h, s, v = rng.random(3)
    return tuple(float(c) for c in to_linear(np.array(colorsys.hsv_to_rgb(h, s, 0.1 + 0.9 * v))))


def _look(rng: np.random.Generator, name: str, config: DistractorRandomisation, size: Range) -> dict:
    """Everything of a distractor but where it stands."""
    entry = CATALOGUE[name]
    size_m, scale = None, 1.0
    if entry.group == "primitive":
        size_m = tuple(float(v) for v in rng.uniform(*size, 3))
    else:
        scale = float(rng.uniform(0.9, 1.1))
    parts = entry.build(size_m or (1.0, 1.0, 1.0))
    points = np.concatenate([p.points for p in parts]) * scale
    colours = tuple(_colour(rng) for _ in parts)
    pattern = None
    if rng.random() < config.textured_share:
        pattern = Pattern(FABRICS[int(rng.integers(len(FABRICS)))], _colour(rng), float(rng.uniform(0.05, 0.4)))
    metallic = float(rng.uniform(0.5, 1.0)) if rng.random() < 0.2 else 0.0
    return dict(object=name, label=entry.label, heading_deg=float(rng.uniform(0.0, 360.0)), size_m=size_m, scale=scale,
                colours=colours, roughness=float(rng.uniform(0.2, 0.9)), metallic=metallic, pattern=pattern,
                radius_m=float(np.max(np.hypot(points[:, 0], points[:, 1]))), height_m=float(points[:, 2].max()))


def _flat_and_free(area, xy: np.ndarray, z: float, radius: float, height: float, tolerance: float) -> bool:
    """Whether rays down from above the footprint (its centre and 8 points on its rim) first meet the twin within
    ``tolerance`` of ``z``: a flat spot with nothing of the twin in the object's volume."""
    rim = np.array([[0.0, 0.0]] + [[math.cos(a), math.sin(a)] for a in np.linspace(0, 2 * math.pi, 8, endpoint=False)])
    points = xy + radius * rim
    origins = np.column_stack([points, np.full(len(points), z + height + 0.1)])
    locations, ray, _ = area.occluders.ray.intersects_location(origins, np.tile([0.0, 0.0, -1.0], (len(points), 1)),
                                                               multiple_hits=False)
    return len(set(ray.tolist())) == len(points) and bool(np.all(np.abs(locations[:, 2] - z) <= tolerance))


def _clear(xy, radius: float, taken) -> bool:
    return all(math.hypot(xy[0] - x, xy[1] - y) >= radius + r + 0.1 for x, y, r in taken)


def draw_distractors(rng: np.random.Generator, config: DistractorRandomisation, area, tops: SurfaceTops,
                     cameras_xy: np.ndarray) -> DistractorsDraw:
    """The distractors of one scene (``rng`` its ``distractors`` stream) in the twin of ``area`` (a
    :class:`~synthua_usd.randomisation.view.WalkArea`), whose level tops are ``tops``, with cameras at
    ``cameras_xy`` (k, 2) world metres. A distractor for which no place turns up in :data:`TRIES` tries is left out."""
    density = float(rng.uniform(*config.ground_per_100m2))
    count = min(config.max_ground, int(rng.poisson(density * area.area_m2() / 100.0)))
    on_tops = int(rng.integers(config.on_surfaces[0], config.on_surfaces[1] + 1))
    seats = [(s.origin[0], s.origin[1], 0.5) for s in area.seats]
    cams = np.asarray(cameras_xy, float).reshape(-1, 2)
    items, taken = [], []
    for _ in range(count if len(area.nodes) else 0):
        look = _look(rng, config.objects[int(rng.integers(len(config.objects)))], config, config.primitive_size_m)
        for _ in range(TRIES):
            i, j = area.nodes[int(rng.integers(len(area.nodes)))]
            xy = area.grid.centre(i, j)[:2] + rng.uniform(-0.4, 0.4, 2) * area.grid.cell_m
            if (len(cams) and np.min(np.hypot(*(cams - xy).T)) < config.camera_clearance_m + look["radius_m"]) or \
                    not _clear(xy, look["radius_m"], taken + seats):
                continue
            z = float(area.ground_z(xy[None], np.array([area.grid.z[i, j]]))[0])
            if _flat_and_free(area, xy, z, look["radius_m"], look["height_m"], 0.03):
                items.append(Distractor(position=(float(xy[0]), float(xy[1]), z), on="ground", **look))
                taken.append((float(xy[0]), float(xy[1]), look["radius_m"]))
                break
    small = [name for name in config.objects if CATALOGUE[name].group == "primitive"]
    above: list[tuple[float, float, float, float]] = []
    for _ in range(on_tops if small and len(tops.weights) else 0):
        look = _look(rng, small[int(rng.integers(len(small)))], config, SURFACE_SIZE_M)
        for _ in range(TRIES):
            tri = tops.corners[int(rng.choice(len(tops.weights), p=tops.weights))]
            u, v = rng.random(2)
            if u + v > 1.0:
                u, v = 1.0 - u, 1.0 - v
            point = tri[0] + u * (tri[1] - tri[0]) + v * (tri[2] - tri[0])
            near = [(x, y, r) for x, y, z, r in above if abs(z - point[2]) < 0.1]
            if _clear(point[:2], look["radius_m"], near) and _flat_and_free(area, point[:2], float(point[2]),
                                                                           look["radius_m"], look["height_m"], 0.01):
                items.append(Distractor(position=tuple(float(c) for c in point), on="surface", **look))
                above.append((float(point[0]), float(point[1]), float(point[2]), look["radius_m"]))
                break
    return DistractorsDraw(tuple(items))
