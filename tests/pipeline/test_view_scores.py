"""The sampler's view scores (issue 39): scored on the job's workers, a seed's views on one, they are the scores
one process computes alone; and a randomised job of many seeds, with QA measures and relations, writes every
record it plans (a NumPy value in a record once stopped such a run after 47 images)."""

from __future__ import annotations

import json

from conftest import RANDOM_CONFIG, SCENARIO, generate_dataset
from dataset_runs import records
from synthua_usd.dataset.config import GenerationConfig
from synthua_usd.dataset.record import IMAGE, record_problem
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline.verify import verify
from synthua_usd.pipeline.view_scores import ScoreJob, score_views
from synthua_usd.pipeline.worker_protocol import ExecutorConfig


def test_views_scored_on_two_workers_are_those_one_process_scores():
    config = GenerationConfig.load(RANDOM_CONFIG)
    job = ScoreJob(scenario=str(SCENARIO), render=RenderConfig(width=96, height=72, spp=1), output_size=(96, 72),
                   class_map_document=ClassMap.default().document(), randomise=config.randomise)
    views = [(None, seed, 24.0, camera) for seed in (0, 1, 2)
             for camera in ("/World/Cameras/CCTV", "/World/Cameras/PedestrianEye")]
    alone = score_views(job, views)
    shared = score_views(job, views, ExecutorConfig(kind="local", workers=2))
    assert shared == alone
    assert [(s.seed, s.camera_path) for s in alone] == [(v[1], v[3]) for v in views]
    assert sum(len(s.aid_users) for s in alone) >= 3  # the randomiser aims aid users into view


def test_a_randomised_job_of_many_seeds_writes_every_record(tmp_path):
    document = json.loads(RANDOM_CONFIG.read_text(encoding="utf-8"))
    document.update(name="many-seeds", images=14, seeds=list(range(14)), workers=2,
                    render={"width": 64, "height": 48, "spp": 1, "max_depth": 3, "denoise": False},
                    conditions=["clear_day", "snow", "day_rain_fog"])
    document["randomise"]["crowd"] = {"density_per_m2": [0.08, 0.12], "aid_share": [0.6, 0.8],
                                      "pushed_share": [0.6, 0.8], "accompanied_share": [0.6, 0.8],
                                      "aid_users_in_view": [2, 4]}
    config = tmp_path / "many.json"
    config.write_text(json.dumps(document), encoding="utf-8")
    summary = generate_dataset(tmp_path / "dataset", config=config)
    recs = records(tmp_path / "dataset")
    assert summary.planned == len(recs) >= 14 and verify(tmp_path / "dataset").ok
    assert all(record_problem(r, IMAGE) is None for r in recs)
    relations = {k for r in recs for i in r["instances"] for k in (i.get("relations") or {})}
    assert {"uses", "pushes", "accompanies"} <= relations
    assert any(not p["in_view"] for r in recs for p in r["randomisation"]["view"]["placements"])
    assert all(isinstance(v, (int, float)) for r in recs for v in r["qa"]["measures"].values() if v is not None)
