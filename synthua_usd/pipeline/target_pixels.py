"""How well candidate cameras see their targets, counted in label passes: the line-of-sight prefilter, the
quick scoring passes at a quarter of the image size, and the exact passes of the report (visible pixels in
the whole scene, and *alone*: in a scene holding only the target). Used by
:mod:`synthua_usd.pipeline.camera_rigs`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.composition.rigs import RigSpec
from synthua_usd.geometry.placement import Placement, Terrain
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.scene import SceneSnapshot
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.targets import Target

#: Candidates per target kept by the line-of-sight test for label passes, and counted at more than the first
#: scoring time code.
PREFILTER_KEEP = 6
SCORE_KEEP = 3


@dataclass(eq=False)
class CandidateGroup:
    """Candidates of one rig for one target (None: a rig that aims at nothing)."""

    rig: int
    target: Target | None
    candidates: list[Placement]
    scores: list[float] = field(default_factory=list)

    def best(self) -> tuple[Placement, float]:
        if not self.scores:
            return self.candidates[0], math.nan
        k = int(np.argmax(self.scores))
        return self.candidates[k], self.scores[k]


def count_pixels(ids: np.ndarray, wanted) -> int:
    return int(np.isin(ids, list(wanted)).sum())


def prefilter(groups: list[CandidateGroup], terrain: Terrain, time_code: float) -> None:
    """Keep the PREFILTER_KEEP candidates of each target with the clearest sight of it (Embree rays from the
    camera to its box's centre and eight points half-way to its corners, against the static twin; agents do
    not block here, the label passes see them), ties broken by the larger image of the target (focal length
    over distance). Only these are scored by label passes."""
    for g in groups:
        if g.target is None or len(g.candidates) <= PREFILTER_KEEP:
            continue
        lo, hi = g.target.boxes[time_code]
        centre = (lo + hi) / 2
        points = np.array([centre] + [centre + 0.5 * (np.array([x, y, z]) - centre)
                                      for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        eyes = np.array([c.camera_to_world(time_code)[:3, 3] for c in g.candidates])
        origins = np.repeat(eyes, len(points), axis=0)
        ends = np.tile(points, (len(eyes), 1))
        dirs = ends - origins
        dist = np.linalg.norm(dirs, axis=1)
        locations, ray_idx, _ = terrain.mesh.ray.intersects_location(origins, dirs / dist[:, None],
                                                                     multiple_hits=False)
        blocked = np.zeros(len(origins), bool)
        blocked[ray_idx] = np.linalg.norm(locations - origins[ray_idx], axis=1) < dist[ray_idx] - 0.3
        clear = (~blocked).reshape(len(eyes), len(points)).sum(axis=1)
        size = np.array([c.focal_length_mm for c in g.candidates]) / np.linalg.norm(eyes - centre, axis=1)
        keep = np.lexsort((-size, -clear))[:PREFILTER_KEEP]
        g.candidates = [g.candidates[i] for i in sorted(keep)]


def score(groups: list[CandidateGroup], reader: StageReader, rigs: tuple[RigSpec, ...], config: RenderConfig,
          report_tcs: list[float], show_progress: bool) -> None:
    """Each aimed candidate's score: the fewest visible target pixels over three report time codes (middle,
    first, last), counted at a quarter of the image size (at least 160 wide) and scaled to the full size. All
    candidates are counted at the middle time code; only the best SCORE_KEEP of each target at the others."""
    aimed = [g for g in groups if g.target is not None and len(g.candidates) > 1]
    if not aimed:
        return
    sw = max(min(config.width, 160), config.width // 4)
    sh = max(1, round(sw * config.height / config.width))
    scale = config.width * config.height / (sw * sh)
    session = RenderSession(RenderConfig(width=sw, height=sh, spp=1, variant=config.variant))
    order = list(dict.fromkeys([report_tcs[len(report_tcs) // 2], report_tcs[0], report_tcs[-1]]))
    counts = {id(g): np.full((len(g.candidates), len(order)), np.inf) for g in aimed}
    for j, tc in enumerate(tqdm(order, desc="placing", unit="time code", disable=not show_progress, leave=False)):
        snap = reader.snapshot(tc)
        for g in aimed:
            spec, c = rigs[g.rig], counts[id(g)]
            todo = range(len(g.candidates)) if j == 0 else np.argsort(-c.min(axis=1), kind="stable")[:SCORE_KEEP]
            for i in todo:
                ids = session.quick_labels(snap, g.candidates[i].camera(spec, "/candidate", tc))
                c[i, j] = count_pixels(ids, g.target.instance_ids) * scale
    for g in aimed:
        c = counts[id(g)]
        seen = np.where(np.isfinite(c), c, 0.0)
        # Candidates not counted at every time code rank below those that were; ties broken by the mean.
        g.scores = list(np.where(np.isfinite(c).all(axis=1), c.min(axis=1), -1.0) + 1e-3 * seen.mean(axis=1))


def evaluate(chosen: list, reader: StageReader, config: RenderConfig, report_tcs: list[float], tracks: list,
             show_progress: bool) -> list:
    """Per chosen rig, a list of per-time-code dicts: target pixels visible and alone, the target's pixels
    per instance, and every aid user's visible pixels."""
    session = RenderSession(config)
    alone = {target.prim_path: RenderSession(config) for _, target in chosen if target is not None}
    users = {a.prim_path: a.instance_ids for a in tracks if a.device}
    paths = {i.id: i.prim_path for i in reader.instances.values()}
    frames = {id(rig): [] for rig, _ in chosen}
    for tc in tqdm(report_tcs, desc="reporting", unit="time code", disable=not show_progress, leave=False):
        snap = reader.snapshot(tc)
        for rig, target in chosen:
            camera = rig.placement.camera(rig.spec, rig.prim_path, tc)
            ids = session.render(snap, camera, rgb=False).instance_ids
            counts = np.bincount(ids.ravel(), minlength=len(paths) + 1)
            entry = {"time_code": tc, "camera_to_world": camera.camera_to_world.tolist(),
                     "aid_users_px": {p: int(counts[list(i)].sum()) for p, i in users.items() if counts[list(i)].sum()}}
            if target is not None:
                only = SceneSnapshot(tc, snap.up_axis, tuple(m for m in snap.meshes if m.instance_id in
                                                             target.instance_ids), snap.materials, snap.lights,
                                     snap.instances)
                alone_px = count_pixels(alone[target.prim_path].render(only, camera, rgb=False).instance_ids,
                                  target.instance_ids)
                visible = int(counts[list(target.instance_ids)].sum())
                entry.update(target_px=visible, alone_px=alone_px,
                             occluded_fraction=None if alone_px == 0 else round(1.0 - visible / alone_px, 4),
                             parts_px={paths[i]: int(counts[i]) for i in target.instance_ids})
            frames[id(rig)].append(entry)
    return [((rig, target), frames[id(rig)]) for rig, target in chosen]
