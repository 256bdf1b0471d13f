"""``synthua generate``: a scenario and a generation config in, a complete, verifiable dataset out.

1. Plan. The config's sweep (cameras × time codes × conditions × seeds) is the pool of candidate images.
   A cheap label pass scores every (camera, time code) view for visible mobility-aid users, and the
   sampler (:mod:`synthua_usd.dataset.sampling`) picks the images that meet the quotas and assigns the
   train/val/test splits. The plan is written to ``generate.json`` with the config, so a rerun of the same
   command finds it and resumes.
2. Render. Images without a record are cut into shards; each shard runs start to end on one worker (one
   render session, one scene load, :mod:`synthua_usd.pipeline.dataset_worker`) of a local process pool
   or a Ray cluster (:mod:`synthua_usd.pipeline.executors`). An image's files are written as it finishes,
   its record last.
3. Assemble. From the records alone: COCO instances and panoptic files per split, YOLO's ``data.yaml``,
   the metadata table, the coverage report, the rejected list, the class map and, last, the manifest.

An image's bytes depend only on the scenario, the config and the image (box pixel filter; see the
docs/datasets.md, Reproducibility), never on which worker rendered it or what it rendered before: a resumed run,
a run on more workers and a run on Ray give the same dataset, byte for byte.
"""

from __future__ import annotations

import functools
import json
import logging
import os
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Callable, Sequence


from synthua_usd import __version__
from synthua_usd.core.atomic import write_json_atomic, write_text_atomic
from synthua_usd.core.errors import InputError, OutputError, StageError
from synthua_usd.core.input_guard import check_not_inputs
from synthua_usd.core.resources import check_frame_memory
from synthua_usd.dataset import coverage, sampling
from synthua_usd.dataset.config import GenerationConfig
from synthua_usd.dataset.formats import cityscapes, coco, panoptic, tables, yolo
from synthua_usd.dataset.layout import SPLITS, Layout, cityscapes_city
from synthua_usd.dataset.manifest import document_digest, file_entry, files_written, manifest_document
from synthua_usd.dataset.record import IMAGE, DatasetRecord, ImageRecord, is_rejected, read_record
from synthua_usd.model.render_config import RenderConfig, resolve_render
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline import view_scores
from synthua_usd.pipeline.dataset_worker import FLUSH, WorkerJob, init_worker, work

log = logging.getLogger(__name__)

#: Images a worker renders before its shard ends and a fresh worker takes the next one (bounded so that
#: work spreads over workers and a failure costs little).
SHARD_IMAGES = 16
#: Rounds of replacing images QA rejected (each round replaces the rejections of the one before).
REPLACEMENT_ROUNDS = 3


@dataclass(frozen=True)
class GenerateRequest:
    scenario: Path
    config_path: Path
    out_dir: Path
    executor: str = "local"
    workers: int | None = None
    address: str | None = None
    #: CPUs Ray reserves for each worker (ray only): give each a node's share, since a session uses many threads.
    cpus_per_worker: float = 1.0
    variant: str | None = None
    class_map_path: Path | None = None
    allow_external_assets: bool = False
    #: Workers report the seconds of kernel compiles (a benchmark's profile; Dr.Jit's kernel history).
    count_compiles: bool = False


@dataclass
class GenerateSummary:
    """What a run did: images planned, rendered now, found complete, rejected; where time went; memory."""

    out_dir: Path
    planned: int = 0
    rendered: int = 0
    resumed: int = 0
    rejected: int = 0
    flagged: int = 0
    seconds: dict = field(default_factory=dict)
    wall_seconds: float = 0.0
    peak_rss_mib: dict = field(default_factory=dict)
    bytes_per_image: float = 0.0
    shortfalls: list = field(default_factory=list)
    #: (images rendered so far, worker, its peak resident memory in MiB) after each result: memory over a run.
    rss_trace: list = field(default_factory=list)
    #: Per split (train, val, test): the config's share, the images kept (QA rejections left out) and the cameras
    #: they come from.
    splits: dict = field(default_factory=dict)
    #: Tracking sequences: how many, their frames, frames rendered now and found complete.
    sequences: int = 0
    frames: int = 0
    frames_rendered: int = 0
    frames_resumed: int = 0


def _versions(variant: str) -> dict:
    from importlib.metadata import version

    return {"synthua": __version__, "usd-core": version("usd-core"), "mitsuba": version("mitsuba"),
            "mitsuba_variant": variant}


def _stage_facts(request: GenerateRequest, config: GenerationConfig, class_map: ClassMap):
    """Open the scenario and resolve the sweep against it: the candidate pool (cameras with their rig types ×
    time codes × conditions × seeds), the render settings (:func:`resolve_render`: the stage's UsdRender
    settings under the config's ``render`` block) and the layer stack digest."""
    import math

    from synthua_usd.usd.cameras import camera_paths, camera_rig_type, read_camera
    from synthua_usd.usd.conditions import condition_names
    from synthua_usd.usd.render_settings import render_defaults
    from synthua_usd.usd.stage_io import layer_stack_digest, open_stage

    stage = open_stage(request.scenario, request.allow_external_assets)
    defaults = render_defaults(stage)
    config.check_amodal_groups({c.group for c in class_map.classes}, [c.name for c in class_map.classes],
                               source=f"{request.config_path}: amodal_groups")
    cityscapes.check_class_map(class_map)
    cameras = [(p, p.rsplit("/", 1)[-1], camera_rig_type(stage, p)) for p in camera_paths(stage)]
    if not cameras:
        raise StageError(f"{request.scenario}: has no cameras; expected a scenario with at least one UsdGeom.Camera")
    start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
    stage_times = [float(t) for t in range(math.ceil(start), math.floor(end) + 1)] or [float(start)]
    try:
        pool = sampling.candidates(config, cameras, stage_times, condition_names(stage))
    except InputError as exc:
        raise InputError(f"{request.config_path}: {exc}") from None
    chosen = list(dict.fromkeys((c.camera_path, c.camera_name, c.rig_type) for c in pool))
    for path, _, _ in chosen:  # every camera is checked before anything renders
        read_camera(stage, path, pool[0].time_code)
    render = resolve_render(stage=defaults.render_values(), config=config.render.render_values())
    return stage, pool, chosen, render, layer_stack_digest(stage)


def write_scenes(request: GenerateRequest, config: GenerationConfig, pool, class_map: ClassMap,
                 out: Path) -> dict:
    """With randomised districts or settings: every scenario the pool's seeds draw, written into the dataset's
    ``scenes/`` (kept from an earlier run of the job); scene key -> its scenario
    (:mod:`synthua_usd.pipeline.scenes`). Empty otherwise."""
    from synthua_usd.pipeline.scenes import write_dataset_scenes

    try:
        return write_dataset_scenes(request.scenario, config.randomise, sorted({c.seed for c in pool}), class_map, out)
    except InputError as exc:
        raise InputError(f"{request.config_path}: {exc}") from None


def generate(request: GenerateRequest, show_progress: bool = False) -> GenerateSummary:
    """Plan (or find the plan of an earlier run), render what is missing, replace what QA rejected, assemble
    the dataset files."""
    from tqdm import tqdm

    from synthua_usd.backends.mitsuba import variants
    from synthua_usd.pipeline.worker_protocol import ExecutorConfig

    started = time.perf_counter()
    # the executor's options are checked before anything is planned or written
    ExecutorConfig(kind=request.executor, workers=request.workers or 1, address=request.address,
                   cpus_per_worker=request.cpus_per_worker)
    if request.executor == "ray" and request.address not in (None, "auto"):
        from synthua_usd.pipeline.ray_executor import check_reachable

        check_reachable(request.address)
    # the dataset folder is generate's own: an input inside it could be replaced (district scenes, generate.json)
    check_not_inputs([request.out_dir], {"SCENARIO": request.scenario, "--config": request.config_path,
                                         "--class-map": request.class_map_path}, whole_folder=True)
    config = GenerationConfig.load(request.config_path)
    class_map = ClassMap.load_or_bundled(request.class_map_path)
    stage, pool, cameras, render, stack = _stage_facts(request, config, class_map)
    output_size = config.output_size(render.width, render.height)  # a resample larger than the render is refused here
    check_frame_memory(render.width, render.height)
    variant = variants.activate(request.variant).variant()
    render = replace(render, variant=variant)
    out = Path(request.out_dir)
    layout = Layout(out)
    # What makes a dataset this one: the composed layers (by content, wherever they are), the config (its
    # worker count aside), the class map and the variant. Resuming asks for the same.
    job_key = {"layer_stack": stack["digest"], "config": _config_document(config), "class_map": class_map.document(),
               "variant": variant}
    job_document = _read_job(out)
    if job_document is not None and job_document.get("job_key_digest") != document_digest(job_key):
        raise OutputError(f"{out}: holds a dataset generated from another scenario, config, class map or Mitsuba "
                          f"variant (its generate.json differs); expected an empty folder or the same job to "
                          f"resume: pick another --out or remove it")
    scenes = write_scenes(request, config, pool, class_map, out)
    if job_document is None:
        scores = []
        if config.images:
            score_job = view_scores.ScoreJob(
                scenario=str(Path(request.scenario).resolve()), render=render, output_size=output_size,
                class_map_document=class_map.document(), randomise=config.randomise,
                scenes={d: str(p) for d, p in scenes.items()}, allow_external_assets=request.allow_external_assets)
            scores = view_scores.score_views(score_job, view_scores.pool_views(pool, config.randomise, scenes),
                                             _executor(request, config), stage, show_progress)
        plan = sampling.plan(pool, scores, config) if config.images else []
        job_document = {"synthua": __version__, "job_key": job_key, "job_key_digest": document_digest(job_key),
                        "scenario": str(Path(request.scenario).resolve()),
                        "allow_external_assets": request.allow_external_assets, "layer_stack": stack,
                        "render": asdict(render), "cameras": [list(c) for c in cameras],
                        "quota_targets": sampling.quota_targets(pool, config),
                        "pool": sampling.pool_summary(pool, scores, config), "scores": [s.to_dict() for s in scores],
                        "plan": [p.to_dict() for p in plan]}
        if config.sequences is not None:
            from synthua_usd.pipeline.sequences import plan_stage_sequences

            job_document["sequences"] = [q.to_dict() for q in plan_stage_sequences(stage, config)]
        _write_job(out, job_document)
    plan = [sampling.PlannedImage(**p) for p in job_document["plan"]]
    scores = [view_scores.score_from_dict(s) for s in job_document["scores"]]
    summary = GenerateSummary(out_dir=out)
    _remove_partial_files(out)
    done = _complete_records(layout, plan)
    todo = [p for p in plan if p.id not in done]
    summary.resumed = len(done)
    # the scenario as this run names it (it may have moved since the plan; its layers are the same)
    job = replace(worker_job_from_document(job_document, out, scenario=request.scenario,
                                           allow_external_assets=request.allow_external_assets),
                  count_compiles=request.count_compiles)
    seconds = {"render": 0.0, "annotate": 0.0, "write": 0.0}
    peaks: dict = {}
    config_workers = request.workers or config.workers or default_workers()
    bar = tqdm(total=len(todo), desc="generate", unit="img", disable=not show_progress)

    def collect(result) -> None:
        for item in result.value:
            if item["record"]["id"] not in done:
                summary.rendered += 1
                bar.update(1)
            done[item["record"]["id"]] = item["record"]
            for key, value in item["seconds"].items():  # render, annotate, write and the parts of render
                seconds[key] = seconds.get(key, 0.0) + value
        peaks[result.worker] = max(peaks.get(result.worker, 0.0), result.peak_rss_mib)
        summary.rss_trace.append((summary.rendered, result.worker, result.peak_rss_mib))

    # Images QA rejects are replaced by others of the pool (their quotas counted), round by round, on the same
    # workers; the plan records each image's round, so a resumed run goes on where the killed one stood.
    def next_round() -> list:
        rejected = {p.id for p in plan if is_rejected(done[p.id])}
        last_round = max((p.round for p in plan), default=0)
        todo = (sampling.replacements(pool, scores, config, plan, rejected, round=last_round + 1)
                if rejected and last_round < REPLACEMENT_ROUNDS else [])
        if todo:
            plan.extend(todo)
            job_document["plan"] = [p.to_dict() for p in plan]
            _write_job(out, job_document)
            bar.total += len(todo)
            bar.refresh()
        return todo

    _render_all(todo, done, job, request, config_workers, collect, out, next_round)
    bar.close()
    summary.planned = len(plan)
    records = [done[p.id] for p in plan]
    frames = {}
    if config.sequences is not None:
        from synthua_usd.pipeline.sequences import render_sequences

        frames = render_sequences(stage, config, class_map, job, job_document, request, config_workers, summary,
                                  seconds, show_progress)
    assemble(layout, records, class_map, config, job_document, frames)
    summary.rejected = sum(is_rejected(r) for r in records)
    summary.flagged = sum(r["qa"]["verdict"] == "flagged" for r in records)
    summary.seconds = seconds
    summary.peak_rss_mib = peaks
    summary.wall_seconds = time.perf_counter() - started
    summary.bytes_per_image = _dataset_bytes(out) / max(1, len(records))
    summary.shortfalls = json.loads(layout.path(Layout.COVERAGE).read_text(encoding="utf-8")).get("shortfalls", [])
    summary.splits = achieved_splits(records, config)
    _warn_empty_splits(summary.splits)
    return summary


def achieved_splits(records: list[ImageRecord], config: GenerationConfig) -> dict[str, dict]:
    """Per split: the config's share, the images kept (not rejected by QA) and the distinct cameras they come
    from."""
    out = {}
    for split in SPLITS:
        kept = [r for r in records if r["split"] == split and not is_rejected(r)]
        out[split] = {"share": config.split.ratios[split], "images": len(kept),
                      "cameras": len({r["camera"]["prim_path"] for r in kept})}
    return out


def _warn_empty_splits(splits: dict[str, dict]) -> None:
    """A split the config gives a share that ends up with no image: the split is by camera, so fewer cameras
    than splits (or a camera whose every image was rejected) leave one empty."""
    cameras = sum(v["cameras"] for v in splits.values())
    for split, counts in splits.items():
        share = counts["share"]
        if share > 0 and counts["images"] == 0:
            log.warning(f"split {split}: no image, though the config gives it {share:g}; expected a camera of its "
                        f"own (images are split by camera, and {cameras} camera(s) have kept images): add cameras "
                        f"or set split.{split} to 0")


def _config_document(config: GenerationConfig) -> dict:
    """The config as the dataset records it: everything but ``workers`` (how many workers made a dataset
    does not change a byte of it)."""
    document = config.to_document()
    document.pop("workers", None)
    return document


def _dataset_bytes(out: Path) -> int:
    """Bytes the dataset holds on disk, each file once (the Cityscapes images are hard links)."""
    seen, total = set(), 0
    for path in out.rglob("*"):
        if path.is_file():
            st = path.stat()
            if (st.st_dev, st.st_ino) not in seen:
                seen.add((st.st_dev, st.st_ino))
                total += st.st_size
    return total


def worker_job_from_document(document: dict, out_dir: Path, scenario: Path | None = None,
                             allow_external_assets: bool | None = None, dataset: Path | None = None) -> WorkerJob:
    """The workers' job from a run's ``generate.json``: the one place a :class:`WorkerJob` is made, for a
    run, its resumption and ``synthua replay`` alike. ``scenario`` and ``allow_external_assets`` default to
    what the run that planned the dataset used; ``dataset`` is where its districts are (default ``out_dir``:
    replay writes elsewhere)."""
    key = document["job_key"]
    config = GenerationConfig.from_document(key["config"], source=Layout.CONFIG)
    class_map = ClassMap.from_document(key["class_map"], source=Layout.CONFIG)
    render = RenderConfig.from_dict(document["render"])
    cameras = [tuple(c) for c in document["cameras"]]
    size = config.output_size(render.width, render.height)
    from synthua_usd.pipeline.scenes import scene_paths

    scenes = scene_paths(config.randomise, config.seeds, Path(dataset or out_dir))
    return WorkerJob(scenario=str(Path(scenario).resolve()) if scenario is not None else document["scenario"],
                     out_dir=str(Path(out_dir).resolve()), render=render, config=config,
                     class_map_document=key["class_map"],
                     allow_external_assets=(document.get("allow_external_assets", False)
                                            if allow_external_assets is None else allow_external_assets),
                     output_size=None if size == (render.width, render.height) else size,
                     city=cityscapes_city(config.name), camera_index={p: i for i, (p, _, _) in enumerate(cameras)},
                     layer_stack=document["layer_stack"]["digest"], yolo_classes=yolo.class_index(class_map),
                     scenes=scenes)


def _render_all(todo, done: dict, job: WorkerJob, request: GenerateRequest, workers: int, collect, out: Path,
                next_round: Callable[[], list]) -> None:
    """Render every planned image of ``todo`` on the executor, in shards, and then the images of each
    ``next_round()`` until it gives none; one pool of workers (their scenes loaded) runs every round. A round
    repeats the images a lost worker took with it before the next one starts."""
    from synthua_usd.pipeline.executors import cut_shards, run_shards
    from synthua_usd.pipeline.worker_protocol import ExecutorConfig

    # a shard's images follow one another in the order that changes least in its loaded scene: the condition
    # first (wetness and a sun below the horizon mean a reload), then camera and time code; with randomisation
    # the district and the seed come first (each seed is a scene of its own, loaded once)
    if job.config.randomise is not None:
        from synthua_usd.pipeline.scenes import scene_of, scene_order

        def order(p):
            return (scene_order(scene_of(job.config.randomise, p.seed)), p.seed, p.condition or "", p.camera_path,
                    p.time_code, p.id)

        def scene(p):  # each seed is a scene of its own
            return order(p)[:2]
    else:
        order = lambda p: (p.condition or "", p.camera_path, p.time_code, p.seed, p.id)  # noqa: E731
        scene = lambda p: p.condition or ""  # noqa: E731

    def shards_of(images) -> list:
        # every worker gets work (a job of few images too), and a seed's scene is built once where it fits a shard
        return [shard + [FLUSH] for shard in cut_shards(sorted(images, key=order), scene, workers, SHARD_IMAGES)]

    current = list(todo)

    def more() -> list:
        nonlocal current
        missing = [p for p in current if p.id not in done]
        if missing and len(missing) == len(current):
            raise OutputError(f"{out}: {len(missing)} images were rendered but none was written; expected "
                              f"their records in {out / 'records'}")
        current = missing or next_round()
        return shards_of(current)

    executor = ExecutorConfig(kind=request.executor, workers=workers, address=request.address,
                              cpus_per_worker=request.cpus_per_worker)
    run_shards(shards_of(current), functools.partial(init_worker, job), work, collect, executor, more=more)


def _executor(request: GenerateRequest, config: GenerationConfig):
    """The executor of the job's workers: ``--workers``, else the config's, else :func:`default_workers`."""
    from synthua_usd.pipeline.worker_protocol import ExecutorConfig

    return ExecutorConfig(kind=request.executor, workers=request.workers or config.workers or default_workers(),
                          address=request.address, cpus_per_worker=request.cpus_per_worker)


def default_workers() -> int:
    """One render worker per 8 cores: a Mitsuba LLVM session already uses every core it is given, so more
    workers on a small machine only compete (``--workers`` overrides)."""
    return max(1, (os.cpu_count() or 1) // 8)


def _read_job(out: Path) -> dict | None:
    path = out / Layout.CONFIG
    if not path.exists():
        if out.exists() and not out.is_dir():
            raise OutputError(f"{out}: is a file; expected a dataset folder or a path that does not exist")
        from synthua_usd.pipeline.scenes import SCENES_FOLDER

        # a run killed before its plan was written may have left the districts it writes first
        if out.is_dir() and any(not p.name.startswith(".") and p.name != SCENES_FOLDER for p in out.iterdir()):
            raise OutputError(f"{out}: is not empty and holds no generate.json; expected an empty folder, a "
                              f"path that does not exist, or a dataset to resume")
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise OutputError(f"{path}: unreadable ({exc}); expected the generate.json of an earlier run") from None


def _write_job(out: Path, document: dict) -> None:
    out.mkdir(parents=True, exist_ok=True)
    _write_json(out / Layout.CONFIG, document)


def _write_json(path: Path, document) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_json_atomic(path, document, indent=1)


def _remove_partial_files(out: Path) -> None:
    """Delete what a killed run left half-written: the temporary files of atomic writes (dot files; the
    dataset's own files never start with a dot, see :mod:`synthua_usd.dataset.layout`)."""
    for path in sorted(out.rglob(".*")):
        if path.is_file() or path.is_symlink():
            path.unlink()


def _complete_records(layout: Layout, plan) -> dict[int, ImageRecord]:
    """Records of planned images already complete: a record that validates (:func:`read_record`), names the planned
    image, and whose files all exist with their recorded sizes (checksums are ``synthua verify``'s job)."""
    from synthua_usd.dataset.layout import image_name

    done = {}
    for p in plan:
        name = image_name(p.id, p.camera_name, p.time_code, p.condition, p.seed)
        try:
            record = read_record(layout.path(Layout.record(name)), IMAGE)
        except (InputError, OutputError):
            continue  # not there, unreadable or not a record: render it again
        if record["id"] == p.id and files_written(layout.root, record["checksums"]):
            done[p.id] = record
    return done


def assemble(layout: Layout, records: Sequence[DatasetRecord], class_map: ClassMap, config: GenerationConfig | None,
             job_document: dict, frames: dict | None = None, provenance: dict | None = None) -> None:
    """Every dataset-level file, from the records alone (the images', and the sequences' ``frames``: (sequence,
    frame) -> record); the manifest last. Another command's dataset (``synthua composite``) gives its own
    ``provenance`` and no generation ``config`` (no quotas, districts or sequences)."""
    root = layout.root
    written = []
    for split in SPLITS:
        instances = coco.coco_instances(records, class_map, split)
        written.append(_write_json(layout.path(Layout.coco_instances(split)), instances))
        written.append(_write_json(layout.path(Layout.coco_person_keypoints(split)), coco.person_keypoints(instances)))
        written.append(_write_json(layout.path(Layout.coco_panoptic(split)),
                                   panoptic.coco_panoptic(records, class_map, split)))
    written.append(write_text_atomic(layout.path(Layout.DATA_YAML), yolo.data_yaml(class_map)))
    rows = tables.metadata_rows(records, class_map)
    tables.write_tables(rows, layout.path(Layout.METADATA_CSV), layout.path(Layout.METADATA_PARQUET))
    written += [layout.path(Layout.METADATA_CSV), layout.path(Layout.METADATA_PARQUET)]
    written.append(_write_json(layout.path(Layout.COVERAGE), coverage.coverage(
        records, config, job_document.get("quota_targets"), job_document.get("pool"))))
    written.append(tables.write_rejected(records, layout.path(Layout.REJECTED)))
    written.append(_write_json(layout.path(Layout.CLASS_MAP), class_map.document()))
    if provenance is None:
        key = job_document["job_key"]
        provenance = {**_versions(key["variant"]), "config": key["config"],
                      "config_digest": document_digest(key["config"]), "scenario": Path(job_document["scenario"]).name,
                      "layer_stack": job_document["layer_stack"]}
    images = [{"id": r["id"], "name": r["name"], "split": r["split"], "seed": r["seed"],
               **({"layer_stack": r["layer_stack"]} if "layer_stack" in r else {}), "qa": r["qa"]["verdict"],
               "files": [r["checksums"][k] for k in sorted(r["checksums"])]
               + [file_entry(root, Layout.record(r["name"]))]} for r in records]
    dataset_files = [file_entry(root, p.relative_to(root).as_posix()) for p in written]
    dataset_files.append(file_entry(root, Layout.CONFIG))
    from synthua_usd.pipeline.scenes import SCENES_FOLDER

    dataset_files += [file_entry(root, p.relative_to(root).as_posix()) for p in sorted((root / SCENES_FOLDER).rglob("*"))
                      if p.is_file()] if (root / SCENES_FOLDER).is_dir() else []
    if config is not None and config.sequences is not None:
        from synthua_usd.dataset.sequences import PlannedSequence
        from synthua_usd.pipeline.sequences import assemble_sequences, sequence_files

        sequences = [PlannedSequence.from_dict(q) for q in job_document["sequences"]]
        for path in assemble_sequences(layout, sequences, frames or {}, class_map, config):
            dataset_files.append(file_entry(root, path.relative_to(root).as_posix()))
        dataset_files += sequence_files(layout, sequences, frames or {})
        crowds = root / Layout.SEQUENCES / "crowds"
        dataset_files += [file_entry(root, p.relative_to(root).as_posix()) for p in sorted(crowds.glob("*.usdc"))]
    _write_json(layout.path(Layout.MANIFEST), manifest_document(provenance=provenance, images=images,
                                                                dataset_files=sorted(dataset_files,
                                                                                     key=lambda e: e["path"])))
