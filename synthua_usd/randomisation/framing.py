"""Views framed as photographers frame aid users (the ``framing`` part of the ``randomise`` block): the camera a
few metres from one aid user, at a standing or seated eye height, aimed at the user, zoomed so that the user fills
a drawn share of the frame height (as real photos of wheelchair users do: 40-90 % of the height, where rig
cameras show them at 5-25 %).

A framed view is drawn after the crowd is placed (for the rig's camera, which puts aid users in view): one of the
aid users placed in view, a distance and a direction from it whose spot is on the walkable ground near the user's
height, with a clear line of sight past the twin and the other people; a draw that finds no such spot in
:data:`TRIES` tries leaves the view to its rig. Everything is drawn from the view's own ``framing`` stream.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

from synthua_usd.agents.profiles import PROFILES
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.meshes import look_at
from synthua_usd.randomisation.config import FramingRandomisation

#: Spots tried for the camera before the view is left to its rig.
TRIES = 24
#: A seated aid user's height above the ground: this share of the body's standing height plus the seat's.
SEATED_SHARE_OF_HEIGHT = 0.52
SEAT_HEIGHT_M = 0.5


@dataclass(frozen=True)
class FramingDraw:
    """A framed view: the cast index of the aid user it frames, the camera's ground ``distance_m`` and
    ``azimuth_deg`` (world, from the user), its ``height_m`` above the ground under it and whether that is a
    ``seated`` height, the ``height_share`` of the frame the user is to fill (of its ``subject_height_m``), and the
    camera it makes: ``camera_to_world`` (4x4 column-vector, world metres) and ``focal_length_mm``."""

    user: int
    distance_m: float
    azimuth_deg: float
    height_m: float
    seated: bool
    height_share: float
    subject_height_m: float
    camera_to_world: tuple
    focal_length_mm: float

    def camera(self, base: PinholeCamera) -> PinholeCamera:
        """``base`` (the rig's camera: its film and clipping) moved and zoomed to this framing."""
        return replace(base, camera_to_world=np.array(self.camera_to_world, float), focal_length_mm=self.focal_length_mm)

    def to_dict(self) -> dict:
        return asdict(self)


def subject_height(member, bank) -> float:
    """How tall ``member`` (a cast member) stands, or sits on its device, above the ground (metres)."""
    height = float(bank.height_m[member.body])
    if PROFILES[member.profile].seated:
        return SEATED_SHARE_OF_HEIGHT * height + SEAT_HEIGHT_M
    return height


def draw_framing(rng: np.random.Generator, config: FramingRandomisation, cast, placements, area,
                 camera: PinholeCamera, size: tuple[int, int], bank) -> FramingDraw | None:
    """The framing of one view (None: not framed, the share said no, or no aid user or free spot): ``cast`` and
    ``placements`` the scene's people where this view put them, ``area`` the
    :class:`~synthua_usd.randomisation.view.WalkArea`, ``camera`` the rig's (its film), ``size`` the render size,
    ``bank`` the body bank (heights)."""
    if rng.random() >= config.share:
        return None
    users = [k for k, (m, p) in enumerate(zip(cast, placements)) if m.aid is not None and p is not None]
    aimed = [k for k in users if placements[k].in_view]
    pool = aimed or users
    if not pool:
        return None
    k = pool[int(rng.integers(len(pool)))]
    seated = bool(rng.random() < config.seated_share)
    height = float(rng.uniform(*(config.seated_height_m if seated else config.eye_height_m)))
    share = float(rng.uniform(*config.height_share))
    subject = subject_height(cast[k], bank)
    user = np.asarray(placements[k].position, float)
    others = [(np.asarray(p.position, float), PROFILES[m.profile].radius_m) for j, (m, p) in
              enumerate(zip(cast, placements)) if p is not None and j != k]
    target = user + [0.0, 0.0, subject / 2]
    for _ in range(TRIES):
        distance = float(rng.uniform(*config.distance_m))
        azimuth = float(rng.uniform(0.0, 360.0))
        a = math.radians(azimuth)
        xy = user[:2] + distance * np.array([math.cos(a), math.sin(a)])
        ground = area.height_below(np.array([xy[0], xy[1], user[2] + 2.0]))
        i, j = area.grid.cell_of(float(xy[0]), float(xy[1]))
        inside = 0 <= i < area.grid.z.shape[0] and 0 <= j < area.grid.z.shape[1] and bool(area.grid.walkable[i, j])
        if ground is None or not inside or abs(ground - user[2]) > 1.0:
            continue
        eye = np.array([xy[0], xy[1], ground + height])
        if _blocked(area, eye, target, others):
            continue
        camera_to_world = look_at(eye, target)
        aimed_camera = replace(camera, camera_to_world=camera_to_world)
        depth = float((target - eye) @ aimed_camera.axes()[2])
        # the user's height in pixels is focal_px * subject / depth: the focal length that makes it share x H
        focal_px = float(aimed_camera.intrinsics(*size)[1, 1])
        focal_mm = camera.focal_length_mm * (share * size[1] * depth / subject) / focal_px
        return FramingDraw(k, distance, azimuth, height, seated, share, subject,
                           tuple(map(tuple, camera_to_world.tolist())), float(focal_mm))
    return None


def _blocked(area, eye: np.ndarray, target: np.ndarray, others) -> bool:
    """Whether the twin or another person (a disc of its radius) stands between ``eye`` and ``target``."""
    direction = target - eye
    length = float(np.linalg.norm(direction))
    direction = direction / length
    hits, _, _ = area.occluders.ray.intersects_location(eye[None], direction[None], multiple_hits=False)
    if len(hits) and np.linalg.norm(hits[0] - eye) < length - 0.3:
        return True
    flat = target[:2] - eye[:2]
    span = float(flat @ flat)
    for position, radius in others:
        t = float(np.clip((position[:2] - eye[:2]) @ flat / max(span, 1e-12), 0.0, 1.0))
        if np.linalg.norm(eye[:2] + t * flat - position[:2]) < radius + 0.1 and t < 0.95:
            return True
    return False
