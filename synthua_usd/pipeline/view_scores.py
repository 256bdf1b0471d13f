"""The sampler's view scores: which mobility-aid users each candidate view of a ``generate`` job shows.

Every (camera, time code) view of the pool, and with scene randomisation every (seed, camera, time code) view in
its own randomised scene, gets one label pass at the render size (1 spp is enough: labels come from one ray per
pixel centre); the visible aid users (:func:`synthua_usd.dataset.qa.aid_users`, the one definition QA and coverage
use too) and their pixel counts, scaled to the written size, are its score. With randomisation a view costs
seconds (the scene of its seed authored, read and loaded once, then the view's placements authored, read and the
scene's geometry updated), so the views are scored on the job's workers, a seed's views on one worker
(:func:`score_views`); a view's score depends on the view only, so any worker gives the same numbers.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from synthua_usd.dataset import qa, sampling
from synthua_usd.dataset.annotations import relation_entries
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.taxonomy import ClassMap

#: (scene key or None, seed or None, time code, camera path): one view of the pool.
View = tuple
#: Views a worker scores before it takes the next shard (a seed's views stay together where they fit).
SHARD_VIEWS = 16


@dataclass(frozen=True)
class ScoreJob:
    """What a scorer needs, as plain picklable data (sent to worker processes and Ray actors). ``scenes``: with
    randomised districts or settings, scene key -> its scenario in the dataset (:mod:`synthua_usd.pipeline.scenes`)."""

    scenario: str
    render: RenderConfig
    output_size: tuple[int, int]
    class_map_document: dict
    randomise: object = None
    scenes: dict = field(default_factory=dict)
    allow_external_assets: bool = False


class ViewScorer:
    """Scores views one after the other, keeping the stage, the randomiser (its scene of the last seed) and the
    label session between them: views of one scene and seed in a row cost a scene once."""

    def __init__(self, job: ScoreJob, stage=None) -> None:
        from synthua_usd.backends.mitsuba.session import RenderSession

        self.job = job
        self.class_map = ClassMap.from_document(job.class_map_document, source="class_map.json")
        render = job.render
        self.session = RenderSession(RenderConfig(width=render.width, height=render.height, spp=1,
                                                  variant=render.variant))
        self.scale = job.output_size[0] * job.output_size[1] / (render.width * render.height)
        self._stage = stage  # the job's scenario, when the caller has it open
        self._scene: object = object()
        self.reader = self.randomiser = None

    def _open(self, scene) -> None:
        from synthua_usd.usd.reader import StageReader
        from synthua_usd.usd.stage_io import open_stage

        if self.randomiser is not None:
            self.randomiser.close()
        if scene is None:
            if self._stage is None:
                self._stage = open_stage(self.job.scenario, self.job.allow_external_assets)
            stage = self._stage
        else:  # the dataset's own scenario of the scene, checked when it was written
            stage = open_stage(self.job.scenes[scene], allow_external_assets=True)
        self.reader = StageReader(stage, self.class_map)
        self.randomiser = None
        if self.job.randomise is not None:
            from synthua_usd.pipeline.randomiser import Randomiser

            self.randomiser = Randomiser(stage, self.job.randomise, self.class_map,
                                         (self.job.render.width, self.job.render.height))
        self._scene = scene

    def score(self, view: View) -> sampling.ViewScore:
        """The aid users ``view`` shows."""
        from synthua_usd.usd.cameras import read_camera

        scene, seed, tc, path = view
        if scene != self._scene:
            self._open(scene)
        if self.randomiser is not None:
            self.randomiser.apply(seed, path, tc, None, scene)
        snapshot = self.reader.snapshot(tc)
        ids = self.session.quick_labels(snapshot, read_camera(self.reader.stage, path, tc))
        counts = np.bincount(ids.ravel(), minlength=len(snapshot.instances) + 1)
        class_of = {inst.prim_path: inst.class_name for inst in snapshot.instances}
        visible = [{"class_name": inst.class_name, "prim_path": inst.prim_path,
                    "area": int(round(counts[inst.id] * self.scale)),
                    "relations": relation_entries(inst.relations, class_of)}
                   for inst in snapshot.instances if counts[inst.id]]
        users = tuple(sampling.AidUserView(aid_type=u.aid_type, person_pixels=u.person_pixels,
                                           device_pixels=u.device_pixels) for u in qa.aid_users(visible))
        return sampling.ViewScore(camera_path=path, time_code=tc, aid_users=users, seed=seed)

    def close(self) -> None:
        if self.randomiser is not None:
            self.randomiser.close()
            self.randomiser = None


def pool_views(pool, randomise, scenes: dict) -> list[View]:
    """The distinct views of the candidate ``pool``, in scoring order: without randomisation one per (time code,
    camera); with it one per (seed, camera, time code), grouped by scene and seed."""
    from synthua_usd.pipeline.scenes import scene_of

    if randomise is None:
        return [(None, None, tc, path) for tc, path in sorted(dict.fromkeys((c.time_code, c.camera_path)
                                                                             for c in pool))]
    return sorted(dict.fromkeys((scene_of(randomise, c.seed) if scenes else None, c.seed, c.time_code,
                                 c.camera_path) for c in pool), key=lambda v: (v[0] is not None, v))


def init_scorer(job: ScoreJob) -> ViewScorer:
    return ViewScorer(job)


def score_item(scorer: ViewScorer, view: View) -> dict:
    return scorer.score(tuple(view)).to_dict()


def score_views(job: ScoreJob, views: list[View], executor=None, stage=None,
                show_progress: bool = False) -> list[sampling.ViewScore]:
    """The score of every view of ``views``, in their order. With ``executor`` (an
    :class:`~synthua_usd.pipeline.worker_protocol.ExecutorConfig` of more than one worker) and more than one
    seed's scene, on its workers, each seed's views on one; else here, in this process (``stage``: the job's
    scenario, open)."""
    from tqdm import tqdm

    bar = tqdm(total=len(views), desc="score views", unit="view", disable=not show_progress)
    try:
        scenes = {v[:2] for v in views}
        if executor is not None and executor.workers > 1 and len(scenes) > 1:
            from synthua_usd.pipeline.executors import cut_shards, run_shards

            shards = cut_shards(views, lambda v: v[:2], executor.workers, most=SHARD_VIEWS)
            by_view: dict = {}

            def collect(result) -> None:
                view = shards[result.shard][result.index]
                by_view[tuple(view)] = result.value
                bar.update(1)

            run_shards(shards, functools.partial(init_scorer, job), score_item, collect, executor)
            return [score_from_dict(by_view[tuple(v)]) for v in views]
        scorer = ViewScorer(job, stage)
        try:
            out = []
            for view in views:
                out.append(scorer.score(view))
                bar.update(1)
            return out
        finally:
            scorer.close()
    finally:
        bar.close()


def score_from_dict(document: dict) -> sampling.ViewScore:
    return sampling.ViewScore(camera_path=document["camera_path"], time_code=document["time_code"],
                              aid_users=tuple(sampling.AidUserView(**a) for a in document["aid_users"]),
                              seed=document.get("seed"))
