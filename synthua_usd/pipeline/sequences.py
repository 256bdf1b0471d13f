"""Tracking sequences of ``synthua generate``: their crowds, their frames, and their MOTChallenge files.

1. Crowds. With ``sequences.crowd``, each seed's crowd is populated on the twin's walkable surfaces for the whole
   duration (the agents' rules: routes, speeds, pauses, no collisions), simulated at the sequences' frame rate and
   authored under :data:`SEQUENCE_AGENTS` with a time sample at every frame's time code, beside an ``over`` that
   deactivates the scenario's crowd: ``sequences/crowds/seed_<s>.usdc``, written once (the same seed writes the
   same bytes). A worker composes it over the scenario through the stage's session layer, which also extends the
   stage's time range to the sequence's.
2. Frames. A sequence's frames are cut into shards of consecutive frames; a worker renders them in order from one
   loaded scene (only the sensor, what moved and the sky change between frames: the time-code update path) and
   writes per frame ``img1/<frame>.jpg``, ``instances/<frame>.png`` (16-bit instance ids) and, last,
   ``records/<frame>.json`` (the tracked instances' boxes, masks, occlusion, relations; camera, condition,
   exposure). A run killed at any moment resumes from the records it finds.
3. Files. From the records alone: ``gt/gt.txt``, ``tracks.csv``, ``seqinfo.ini``
   (:mod:`synthua_usd.dataset.formats.mot`), ``preview.mp4`` and, for all sequences, ``annotations/sequences.json``.

Scene randomisation does not apply to sequences: they render the scenario (and their crowd) as composed.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from synthua_usd.core.atomic import write_json_atomic, write_text_atomic
from synthua_usd.core.errors import InputError, OutputError
from synthua_usd.dataset.config import GenerationConfig
from synthua_usd.dataset.formats import mot
from synthua_usd.dataset.layout import Layout
from synthua_usd.dataset.manifest import file_entry, files_written
from synthua_usd.dataset.record import (SEQUENCE_FRAME, FileEntry, SequenceFrameRecord, check_record, read_record,
                                         record_camera)
from synthua_usd.dataset.sequences import PlannedFrame, PlannedSequence
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline.dataset_worker import FLUSH, WorkerJob, init_worker, render_annotated

#: Where a sequence crowd's agents live (the scenario's stay under /World/Agents, deactivated).
SEQUENCE_AGENTS = "/World/SequenceAgents"
#: Frames a worker renders before its shard ends.
SHARD_FRAMES = 50
FRAME_KINDS = ("img1", "instances", "records")


def write_crowds(stage, config: GenerationConfig, class_map: ClassMap, out: Path, first: float,
                 time_codes: tuple[float, ...]) -> dict[int, Path]:
    """Every seed's crowd layer of ``config.sequences`` (when it asks for a crowd) in the dataset ``out``, kept when
    already there; seed -> path. ``time_codes`` are the frames' (one sample each)."""
    from synthua_usd.agents.crowd import CrowdParams, populate_crowd
    from synthua_usd.usd.agents_writer import AGENTS_ROOT, build_agents_layer
    from synthua_usd.usd.authoring import save_layer_atomic
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import stage_metadata

    sequences = config.sequences
    if sequences is None or sequences.crowd is None:
        return {}
    layout = Layout(out)
    wanted = {seed: layout.path(Layout.sequence_crowd(seed)) for seed in sequences.seeds}
    missing = [seed for seed, path in wanted.items() if not path.is_file()]
    if missing:
        snapshot = StageReader(stage, class_map).snapshot(first)
        twin = [m for m in snapshot.meshes if not m.prim_path.startswith(AGENTS_ROOT + "/")]
        vertices, faces, owner = snapshot.world_triangles(twin)
        names = np.array([class_map.by_id(m.class_id).name for m in twin], object)
        # the crowd's layer: in metres, rooted at /World, over the frames' time codes
        meta = replace(stage_metadata(stage), meters_per_unit=1.0, start_time_code=first,
                       end_time_code=time_codes[-1], default_prim="World")
        tcps = meta.time_codes_per_second
        for seed in missing:
            params = CrowdParams(density_per_m2=sequences.crowd.density_per_m2, aid_share=sequences.crowd.aid_share,
                                 time_codes=len(time_codes), time_codes_per_second=sequences.fps, seed=int(seed))
            crowd = populate_crowd(vertices, faces, names[owner] if len(owner) else np.zeros(0, object), params)
            layer = build_agents_layer(crowd, meta, class_map.taxonomy, root_path=SEQUENCE_AGENTS,
                                       time_step=tcps / sequences.fps, deactivate=(AGENTS_ROOT,))
            wanted[seed].parent.mkdir(parents=True, exist_ok=True)
            save_layer_atomic(layer.GetRootLayer(), wanted[seed])
    return wanted


@dataclass(frozen=True)
class SequenceJob:
    """What a sequence worker needs (picklable): the image workers' job (its config without randomisation), the
    crowd layer of each seed (empty: the scenario's crowd) and the last frame's time code."""

    worker: WorkerJob
    crowds: dict = field(default_factory=dict)
    end_time_code: float = 0.0


def sequence_job(job: WorkerJob, crowds: dict[int, Path], end_time_code: float) -> SequenceJob:
    return SequenceJob(replace(job, config=replace(job.config, randomise=None)),
                       {int(k): str(Path(v).resolve()) for k, v in crowds.items()}, float(end_time_code))


def init_sequence_worker(job: SequenceJob):
    state = init_worker(job.worker)
    state.sequence_job = job
    state.crowd_seed = None
    return state


def _use_crowd(state, seed: int) -> None:
    """Compose the crowd of ``seed`` over the stage (in place of another seed's) and reach its time range."""
    from synthua_usd.usd.session_layers import extend_end_time_code, use_session_sublayer

    job = state.sequence_job
    if state.crowd_seed == seed or seed not in job.crowds:
        return
    use_session_sublayer(state.stage, job.crowds[seed], among=job.crowds.values())
    extend_end_time_code(state.stage, job.end_time_code)
    state.crowd_seed = seed


def work_frame(state, item) -> list[dict]:
    """Render and write one frame (or, for :data:`FLUSH`, nothing more); returns the written frames' results."""
    if item == FLUSH:
        return state.writer.drain()
    frame: PlannedFrame = item
    seq = frame.sequence
    _use_crowd(state, seq.seed)
    annotated = render_annotated(state, seq.camera_path, frame.time_code, seq.condition, seq.seed)
    return state.writer.submit(_write_frame, state, frame, annotated)


def _write_frame(state, frame: PlannedFrame, annotated) -> dict:
    from synthua_usd.backends import frame_files

    t0 = time.perf_counter()
    job = state.sequence_job.worker
    layout = Layout(Path(job.out_dir))
    seq = frame.sequence
    files = {kind: Layout.sequence_frame(seq.name, frame.frame, kind) for kind in FRAME_KINDS[:2]}
    for rel in files.values():
        layout.path(rel).parent.mkdir(parents=True, exist_ok=True)
    writers = frame_files.file_writers(jpeg_quality=job.config.sequences.jpeg_quality)
    writers["img1"](layout.path(files["img1"]), annotated.display())
    writers["instances"](layout.path(files["instances"]), annotated.instance_ids)
    tracked = set(mot.tracked(state.class_map))
    rendered = annotated.rendered
    record = SequenceFrameRecord(
        sequence=seq.name, frame=frame.frame, time_code=frame.time_code, seed=seq.seed,
        width=annotated.width, height=annotated.height,
        camera=record_camera(annotated.camera, (job.render.width, job.render.height),
                             (annotated.width, annotated.height), name=seq.camera_name, rig_type=seq.rig_type),
        condition=annotated.condition.to_dict() if annotated.condition is not None else None,
        exposure=rendered.exposure.to_dict() if rendered.exposure is not None else None,
        files=files,
        instances=[e for e in annotated.instances if e["class_name"] in tracked])
    record["checksums"] = {key: file_entry(layout.root, rel) for key, rel in sorted(files.items())}
    relative = Layout.sequence_frame(seq.name, frame.frame, "records")
    check_record(record, SEQUENCE_FRAME, relative)
    path = layout.path(relative)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_json_atomic(path, record, indent=1)
    seconds = dict(annotated.seconds, write=time.perf_counter() - t0)
    return {"record": record, "seconds": seconds}


def complete_frames(layout: Layout, sequences: list[PlannedSequence]) -> dict[tuple[str, int], SequenceFrameRecord]:
    """Records of frames already complete: a record that validates (:func:`read_record`), names its frame, and whose
    files exist with their recorded sizes (:func:`synthua_usd.dataset.manifest.files_written`)."""
    done = {}
    for seq in sequences:
        for k in range(1, seq.frames + 1):
            try:
                record = read_record(layout.path(Layout.sequence_frame(seq.name, k, "records")), SEQUENCE_FRAME)
            except (InputError, OutputError):
                continue  # not there, unreadable or not a frame's record: render it again
            if record["frame"] == k and record["sequence"] == seq.name and files_written(layout.root, record["checksums"]):
                done[(seq.name, k)] = record
    return done


def frame_shards(todo: list[PlannedFrame]) -> list[list]:
    """``todo`` cut into shards of at most :data:`SHARD_FRAMES` consecutive frames of one sequence."""
    shards: list[list] = []
    for frame in todo:
        last = shards[-1] if shards else None
        if (last is None or last[-1].sequence.name != frame.sequence.name or len(last) >= SHARD_FRAMES
                or last[-1].frame + 1 != frame.frame):
            shards.append([frame])
        else:
            last.append(frame)
    return [shard + [FLUSH] for shard in shards]


def assemble_sequences(layout: Layout, sequences: list[PlannedSequence], records: dict, class_map: ClassMap,
                       config: GenerationConfig) -> list[Path]:
    """Every sequence's MOTChallenge files and preview, and ``annotations/sequences.json``; returns their paths."""
    written = []
    video = []
    for seq in sequences:
        frames = [records[(seq.name, k)] for k in range(1, seq.frames + 1)]
        pairs = [(r["frame"], r["instances"]) for r in frames]
        width, height = frames[0]["width"], frames[0]["height"]
        for name, text in (("gt/gt.txt", mot.gt_text(mot.gt_rows(pairs, class_map))),
                           ("tracks.csv", mot.tracks_text(pairs, class_map)),
                           ("seqinfo.ini", mot.seqinfo_text(seq.name, config.sequences.fps, seq.frames, width,
                                                            height))):
            path = layout.path(Layout.sequence_file(seq.name, name))
            path.parent.mkdir(parents=True, exist_ok=True)
            written.append(write_text_atomic(path, text))
        if config.sequences.preview:
            written.append(_preview(layout, seq, frames, config.sequences.fps, class_map))
        video.append({"name": seq.name, "width": width, "height": height, "fps": config.sequences.fps,
                      "frames": [(r["frame"], r["files"]["img1"], r["instances"]) for r in frames]})
    path = layout.path(Layout.SEQUENCES_COCO)
    path.parent.mkdir(parents=True, exist_ok=True)
    written.append(write_json_atomic(path, mot.coco_video(video, class_map), indent=None))
    return written


def boxed_frame(layout: Layout, record: dict, class_map: ClassMap) -> np.ndarray:
    """(H, W, 3) uint8: a sequence frame's image with the amodal box, id and class of every tracked object drawn,
    a device in its user's colour (what the preview video shows)."""
    from synthua_usd.core.images import read_image
    from synthua_usd.backends.video import draw_boxes

    mot_classes = mot.tracked(class_map)
    instances = [e for e in record["instances"] if e["class_name"] in mot_classes]
    user_of = {e["relations"].get("uses"): e["id"] for e in instances}
    boxes = [(*(int(v) for v in e["amodal_bbox"]), user_of.get(e["prim_path"], e["id"]),
              f"{e['id']} {e['class_name']}") for e in instances]
    return draw_boxes(read_image(layout.path(record["files"]["img1"]))[0][..., :3], boxes)


def _preview(layout: Layout, seq: PlannedSequence, frames: list[dict], fps: float, class_map: ClassMap) -> Path:
    from synthua_usd.backends.video import write_preview

    images = (boxed_frame(layout, record, class_map) for record in frames)
    return write_preview(layout.path(Layout.sequence_file(seq.name, "preview.mp4")), images, fps)


def sequence_files(layout: Layout, sequences: list[PlannedSequence], records: dict) -> list[FileEntry]:
    """Manifest entries of every file of every sequence (frames, their records, the sequence files), sorted."""
    entries = []
    for seq in sequences:
        for k in range(1, seq.frames + 1):
            record = records[(seq.name, k)]
            entries += [record["checksums"][key] for key in sorted(record["checksums"])]
            entries.append(file_entry(layout.root, Layout.sequence_frame(seq.name, k, "records")))
    return entries



def plan_stage_sequences(stage, config: GenerationConfig) -> list[PlannedSequence]:
    """The sequences of ``config`` over ``stage`` (its cameras, conditions and time range checked)."""
    from synthua_usd.dataset.sequences import plan_sequences
    from synthua_usd.usd.cameras import camera_paths, camera_rig_type, read_camera
    from synthua_usd.usd.conditions import condition_names
    from synthua_usd.usd.stage_io import time_range

    cameras = [(p, p.rsplit("/", 1)[-1], camera_rig_type(stage, p)) for p in camera_paths(stage)]
    span = time_range(stage)
    sequences = plan_sequences(config.sequences, cameras, condition_names(stage), float(stage.GetStartTimeCode()),
                               span, float(stage.GetTimeCodesPerSecond()), own_crowd=config.sequences.crowd is None)
    for seq in sequences:  # every camera is checked before anything renders
        read_camera(stage, seq.camera_path, seq.time_codes[0])
    return sequences


def render_sequences(stage, config: GenerationConfig, class_map: ClassMap, job: WorkerJob, job_document: dict,
                     request, workers: int, summary, seconds: dict, show_progress: bool) -> dict:
    """Write the sequences' crowds, render every frame not complete yet, and return every frame's record by
    (sequence, frame)."""
    from tqdm import tqdm

    from synthua_usd.core.errors import OutputError
    from synthua_usd.pipeline.executors import run_shards
    from synthua_usd.pipeline.worker_protocol import ExecutorConfig

    out = Path(job.out_dir)
    layout = Layout(out)
    sequences = [PlannedSequence.from_dict(q) for q in job_document["sequences"]]
    times = sequences[0].time_codes if sequences else ()
    crowds = write_crowds(stage, config, class_map, out, times[0], times) if sequences else {}
    done = complete_frames(layout, sequences)
    summary.sequences, summary.frames = len(sequences), sum(q.frames for q in sequences)
    summary.frames_resumed = len(done)
    todo = [PlannedFrame(q, k) for q in sequences for k in range(1, q.frames + 1) if (q.name, k) not in done]
    the_job = sequence_job(job, crowds, times[-1] if times else 0.0)
    bar = tqdm(total=len(todo), desc="sequences", unit="frame", disable=not show_progress)

    def collect(result) -> None:
        for item in result.value:
            key = (item["record"]["sequence"], item["record"]["frame"])
            if key not in done:
                summary.frames_rendered += 1
                bar.update(1)
            done[key] = item["record"]
            for name, value in item["seconds"].items():
                seconds[name] = seconds.get(name, 0.0) + value

    while todo:
        shards = frame_shards(todo)
        executor = ExecutorConfig(kind=request.executor, workers=min(workers, len(shards)), address=request.address,
                                  cpus_per_worker=request.cpus_per_worker)
        import functools

        run_shards(shards, functools.partial(init_sequence_worker, the_job), work_frame, collect, executor)
        missing = [f for f in todo if (f.sequence.name, f.frame) not in done]
        if len(missing) == len(todo):
            raise OutputError(f"{out}: {len(missing)} frames were rendered but none was written; expected their "
                              f"records in {out / Layout.SEQUENCES}")
        todo = missing
    bar.close()
    return done
