"""One dataset worker: a render session and the files of each image it renders.

A worker is made once per shard of a ``synthua generate`` run (:func:`init_worker`: open the stage, one
:class:`RenderSession`, one scene load) and then renders its images in order (:func:`work`). Per image it
renders RGB and exact labels, traces amodal masks, measures truncation, annotates every visible instance
(keypoints too: :mod:`synthua_usd.dataset.keypoints`), runs the QA checks, and writes the image's files.
Writing runs on a background thread while the next image renders
(:class:`synthua_usd.pipeline.background.BackgroundWriter`, the mechanism ``synthua render`` uses too); the
image's record (``records/{name}.json``) is written after all its files, so a record on disk means a complete
image and a run killed at any moment resumes from the records it finds.

Every file is written atomically (a temporary sibling renamed into place), and every path is made by
:mod:`synthua_usd.dataset.layout` from safe names, so nothing outside the dataset folder is ever touched.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from synthua_usd.backends import camera_effects, frame_files, previews
from synthua_usd.core import images
from synthua_usd.core.atomic import atomic_path, write_json_atomic
from synthua_usd.dataset import annotations as instance_annotations
from synthua_usd.dataset import keypoints, qa, resample
from synthua_usd.dataset.config import GenerationConfig
from synthua_usd.dataset.formats import cityscapes, yolo
from synthua_usd.dataset.layout import CityscapesName, Layout, image_name
from synthua_usd.dataset.record import (REJECTED, DatasetRecord, ImageRecord, InstanceEntry, QAResult, check_record,
                                         image_kind, record_camera, record_render)
from synthua_usd.dataset.manifest import file_entry
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.pipeline.background import BackgroundWriter
from synthua_usd.randomisation.effects import draw_image_effects

if TYPE_CHECKING:      # the heavy modules a worker loads when it starts, not when it is imported
    from synthua_usd.backends.mitsuba.render import RenderedFrame
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.cameras import PinholeCamera
    from synthua_usd.model.conditions import Condition
    from synthua_usd.model.scene import SceneSnapshot
    from synthua_usd.pipeline.randomiser import ImageRandomisation, Randomiser
    from synthua_usd.pipeline.scenes import SceneKey
    from synthua_usd.usd.reader import StageReader

#: The item that ends a shard: the worker finishes its pending write and returns that record.
FLUSH = "flush"


@dataclass(frozen=True)
class WorkerJob:
    """Everything a worker needs, as plain picklable data (sent to worker processes and Ray actors)."""

    scenario: str
    out_dir: str
    render: RenderConfig
    config: GenerationConfig
    class_map_document: dict
    allow_external_assets: bool = False
    #: Written size when smaller than the render size (resampled), else None.
    output_size: tuple[int, int] | None = None
    city: str = "synthua"
    camera_index: dict = field(default_factory=dict)
    layer_stack: str = ""
    #: Class id -> YOLO class index (:func:`synthua_usd.dataset.formats.yolo.class_index`).
    yolo_classes: dict = field(default_factory=dict)
    #: With randomised districts or settings: scene key -> its scenario in the dataset
    #: (:mod:`synthua_usd.pipeline.scenes`).
    scenes: dict = field(default_factory=dict)
    #: Report the seconds of kernel compiles per image (``render_compile``; a profile's, see RenderSession).
    count_compiles: bool = False


@dataclass
class WorkerState:
    job: WorkerJob
    #: The open pxr ``Usd.Stage`` (typed Any: only synthua_usd.usd imports OpenUSD, type hints included).
    stage: Any
    reader: StageReader
    session: RenderSession
    class_map: ClassMap
    conditions: dict[str | None, Condition | None] = field(default_factory=dict)
    #: Gives each image its randomisation layers (None when the config randomises nothing).
    randomiser: Randomiser | None = None
    #: The scene key whose scenario ``stage`` is (None: the job's scenario).
    scene: SceneKey | None = None
    #: Writes the previous image (its files, then its record) while the next one renders.
    writer: BackgroundWriter = field(default_factory=BackgroundWriter)
    seconds: dict = field(default_factory=lambda: {"render": 0.0, "annotate": 0.0, "write": 0.0})

    def condition(self, name: str | None) -> Condition | None:
        """The condition ``name`` as the stage composes it: read once, or for every image when randomised (the
        view layer moves its sun)."""
        from synthua_usd.usd.conditions import read_condition

        if self.randomiser is not None:
            return read_condition(self.stage, name)
        if name not in self.conditions:
            self.conditions[name] = read_condition(self.stage, name)
        return self.conditions[name]


def init_worker(job: WorkerJob) -> WorkerState:
    """Open the scenario and make the render session (the scene itself loads with the first image)."""
    from synthua_usd.backends.mitsuba.session import RenderSession

    class_map = ClassMap.from_document(job.class_map_document, source="class_map.json")
    stage, reader = _opened(job, job.scenario, None, class_map)
    return WorkerState(job=job, stage=stage, reader=reader, session=RenderSession(job.render, job.count_compiles),
                       class_map=class_map, randomiser=_randomiser(job, stage, class_map))


def _opened(job: WorkerJob, scenario: str, scene: SceneKey | None, class_map: ClassMap) -> tuple[Any, StageReader]:
    """The stage of ``scenario`` (the job's, or a scene's of the dataset) and its reader."""
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    # a scene's scenario is the dataset's own, checked when it was written
    stage = open_stage(scenario, job.allow_external_assets or scene is not None)
    return stage, StageReader(stage, class_map)


def _randomiser(job: WorkerJob, stage: Any, class_map: ClassMap) -> Randomiser | None:
    """What gives each image of ``stage`` its randomisation layers, or None when the config randomises nothing."""
    if job.config.randomise is None:
        return None
    from synthua_usd.pipeline.randomiser import Randomiser

    return Randomiser(stage, job.config.randomise, class_map, (job.render.width, job.render.height))


def _open(state: WorkerState, scenario: str, scene: SceneKey | None) -> None:
    """Make ``scenario`` (the job's, or a scene's of the dataset) the stage the worker renders."""
    if state.randomiser is not None:
        state.randomiser.close()
    state.stage, state.reader = _opened(state.job, scenario, scene, state.class_map)
    state.scene, state.conditions = scene, {}
    state.randomiser = _randomiser(state.job, state.stage, state.class_map)


def work(state: WorkerState, item) -> list[dict]:
    """Render ``item`` (a planned image) and start writing it; returns the results of images whose files
    are now complete: ``{"record": ..., "seconds": ...}`` (the previous image's, or the last one's for
    :data:`FLUSH`)."""
    if item == FLUSH:
        return state.writer.drain()
    image = render_image(state, item)
    return state.writer.submit(write_image, state, image)


@dataclass(eq=False)
class ImageBuffers:
    """One rendered and annotated image (or composite), ready to write."""

    record: DatasetRecord
    arrays: dict = field(repr=False)
    rejected: bool
    seconds: dict


@dataclass(eq=False)
class AnnotatedFrame:
    """One rendered frame with its annotations, before any file is made: what an image of a dataset and a frame
    of a sequence share. ``rgb`` linear, ``class_ids``, ``instance_ids`` and ``depth`` (z, metres) at the written
    size ``width`` x ``height``; ``instances`` the annotation entries (:func:`annotations.annotate`, with keypoints
    and the class of what a person uses); ``seconds`` where the time went."""

    snapshot: SceneSnapshot
    camera: PinholeCamera
    condition: Condition | None
    rendered: RenderedFrame
    rgb: np.ndarray = field(repr=False)
    class_ids: np.ndarray = field(repr=False)
    instance_ids: np.ndarray = field(repr=False)
    depth: np.ndarray = field(repr=False)
    instances: list[InstanceEntry]
    width: int
    height: int
    seconds: dict
    randomised: ImageRandomisation | None = None

    def display(self) -> np.ndarray:
        """The exposed display-referred sRGB image, (H, W, 3) uint8."""
        scale = self.rendered.exposure.scale if self.rendered.exposure is not None else 1.0
        return images.linear_to_display(self.rgb * np.float32(scale))


def render_annotated(state: WorkerState, camera_path: str, time_code: float, condition_name: str | None, seed: int,
                     output_size: tuple[int, int] | None = None) -> AnnotatedFrame:
    """Render one frame (RGB and exact labels), trace the amodal masks the config asks for, measure truncation and
    annotate every visible instance; resampled to ``output_size`` when given."""
    from synthua_usd.geometry.projection import truncations
    from synthua_usd.usd.cameras import read_camera

    job, class_map = state.job, state.class_map
    t0 = time.perf_counter()
    randomised = None
    if state.randomiser is not None:
        from synthua_usd.pipeline.scenes import scene_of

        scene = scene_of(job.config.randomise, seed)
        if scene != state.scene:
            _open(state, job.scenes[scene] if scene is not None else job.scenario, scene)
        state.randomiser.scene(seed, scene)  # (a new seed's scene: drawn and authored; else kept)
        t_scene = time.perf_counter() - t0
        randomised = state.randomiser.apply(seed, camera_path, time_code, condition_name, scene)
    t_randomise = time.perf_counter() - t0
    snapshot = state.reader.snapshot(time_code)
    t_snapshot = time.perf_counter() - t0 - t_randomise
    camera = read_camera(state.stage, camera_path, time_code)
    condition = state.condition(condition_name)
    rendered = state.session.render(snapshot, camera, rgb=True, condition=condition, seed=seed)
    width, height = job.render.width, job.render.height
    visible = [i for i in np.flatnonzero(np.bincount(rendered.instance_ids.reshape(-1))).tolist() if i]
    group_of = {c.id: c.group for c in class_map.classes}
    by_id = {inst.id: inst for inst in snapshot.instances}
    wanted = [i for i in visible if job.config.amodal_wanted(by_id[i].class_name, group_of.get(by_id[i].class_id))]
    t_amodal = time.perf_counter()
    amodal = state.session.amodal(snapshot, camera, wanted) if wanted else {}
    # "render" is all of it (snapshot, session, amodal); the render_* parts say where it went
    seconds = {"render": time.perf_counter() - t0, "render_amodal": time.perf_counter() - t_amodal,
               "render_snapshot": t_snapshot, **{f"render_{key}": value for key, value in rendered.seconds.items()}}
    if randomised is not None:
        # the scene (crowd, looks, materials: drawn and authored for a new seed) and the view (camera, placements,
        # light: drawn and authored for every image)
        seconds["render_randomise_scene"] = t_scene
        seconds["render_randomise_view"] = t_randomise - t_scene

    t0 = time.perf_counter()
    meshes_of: dict[int, list] = {}
    for mesh in snapshot.meshes:
        if mesh.instance_id in by_id:
            meshes_of.setdefault(mesh.instance_id, []).append(mesh)
    parts = [snapshot.world_triangles(meshes_of.get(i, []))[:2] for i in visible]
    truncated = dict(zip(visible, truncations(parts, camera, width, height)))
    rgb, class_ids, instance_ids, depth = (rendered.rgb, rendered.class_ids, rendered.instance_ids,
                                           rendered.hits.z_m)
    if output_size is not None:
        # Images by a filter; labels, depth and amodal sets all copy one source pixel per output pixel (the
        # mode of the joint class and instance label), so they stay consistent and invent no ids.
        out_w, out_h = output_size
        rgb = resample.resample_rgb(rgb, out_w, out_h)
        maps, index = resample.resample_label_maps({"instance": instance_ids, "class": class_ids}, out_w, out_h)
        class_ids, instance_ids = maps["class"], maps["instance"]
        depth = resample.gather(depth, index)
        amodal = {i: resample.resample_pixel_set(pixels, (height, width), index) for i, pixels in amodal.items()}
        width, height = out_w, out_h
    instances = instance_annotations.annotate(class_ids, instance_ids, snapshot.instances, amodal, truncated)
    instance_annotations.mark_ignored(instances, job.config.min_instance_px)
    keypoints.annotate_keypoints(instances, snapshot.keypoints, camera, (job.render.width, job.render.height),
                                 instance_ids, depth)
    seconds["annotate"] = time.perf_counter() - t0
    return AnnotatedFrame(snapshot, camera, condition, rendered, rgb, class_ids, instance_ids, depth, instances,
                          width, height, seconds, randomised)


def render_image(state: WorkerState, planned) -> ImageBuffers:
    """Render, trace amodal masks, annotate and check one planned image (nothing is written here)."""
    job, class_map = state.job, state.class_map
    frame = render_annotated(state, planned.camera_path, planned.time_code, planned.condition, planned.seed,
                             job.output_size)
    t0 = time.perf_counter()
    snapshot, camera, condition, rendered = frame.snapshot, frame.camera, frame.condition, frame.rendered
    rgb, class_ids, instance_ids, depth = frame.rgb, frame.class_ids, frame.instance_ids, frame.depth
    instances, width, height, seconds, randomised = (frame.instances, frame.width, frame.height, frame.seconds,
                                                     frame.randomised)
    ignored = {entry["id"] for entry in instances if entry["ignore"]}
    panoptic_png, segments = instance_annotations.panoptic(class_ids, instance_ids, snapshot.instances, class_map, ignored)
    display = frame.display()
    effects = draw_image_effects(job.config.randomise, planned.seed, planned.camera_path, planned.time_code,
                                 planned.condition)
    if effects is not None:   # camera effects on the display image, before QA measures it; labels untouched
        display = camera_effects.apply_effects(display, effects, frame.depth)
    measures = qa.measure(display, instances)
    verdict, reasons = qa.verdict(measures, job.config.qa)

    name = image_name(planned.id, planned.camera_name, planned.time_code, planned.condition, planned.seed)
    split = planned.split
    cs = CityscapesName(job.city, job.camera_index.get(planned.camera_path, 0), planned.id)
    rejected = verdict == REJECTED
    yolo_text = "" if rejected else yolo.yolo_lines(instances, width, height, job.yolo_classes, instance_ids)
    files, arrays = label_files(name, split, cs, rejected, display, class_ids, instance_ids,
                                snapshot.instances, ignored, panoptic_png, yolo_text, class_map)
    if not rejected:
        outputs = job.config.outputs
        if outputs.depth:
            files["depth"] = Layout.frame_file(name, "depth")
            arrays["depth"] = depth
        if outputs.rgb_exr:
            files["rgb_exr"] = Layout.frame_file(name, "rgb_exr")
            arrays["rgb_exr"] = rgb
        if outputs.onehot:
            files["onehot"] = Layout.frame_file(name, "onehot")
            arrays["onehot"] = (class_ids, max(c.id for c in class_map.classes) + 1)
    record = ImageRecord(
        id=planned.id,
        name=name,
        split=split,
        width=width,
        height=height,
        camera=record_camera(camera, (job.render.width, job.render.height), (width, height),
                             name=planned.camera_name, rig_type=planned.rig_type),
        time_code=planned.time_code,
        seed=planned.seed,
        condition=condition.to_dict() if condition is not None else None,
        exposure=rendered.exposure.to_dict() if rendered.exposure is not None else None,
        render=record_render(job.render, rendered.variant, rendered.denoised),
        layer_stack=job.layer_stack,
        files=files,
        class_pixel_counts={class_map.by_id(int(c)).name: int(n)
                            for c, n in enumerate(np.bincount(class_ids.ravel(), minlength=256)) if n},
        instances=instances,
        panoptic_segments=segments,
        qa=QAResult(verdict=verdict, reasons=list(reasons), measures=measures),
    )
    if randomised is not None:
        record["randomisation"] = randomised.to_dict() | ({} if effects is None else {"effects": effects.to_dict()})
    seconds["annotate"] += time.perf_counter() - t0
    return ImageBuffers(record, arrays, rejected, seconds)


def label_files(name: str, split: str, cs: CityscapesName, rejected: bool, display: np.ndarray, class_ids: np.ndarray,
                instance_ids: np.ndarray, scene_instances, ignored: set[int], panoptic_png: np.ndarray,
                yolo_text: str, class_map: ClassMap) -> tuple[dict, dict]:
    """The image's files (key -> path in the dataset) and their contents (key -> array or text): the RGB image,
    class ids, class colours, instance ids and preview; unless ``rejected`` also the panoptic PNG, the Cityscapes
    files (label ids, instance ids, colours, the RGB image's link) and the YOLO labels ``yolo_text``. What a
    rendered image and a composite (:mod:`synthua_usd.pipeline.composite_worker`) write alike."""
    files = {"rgb_png": Layout.rgb_png(split, name) if not rejected else Layout.frame_file(name, "rgb_png"),
             **{key: Layout.frame_file(name, key) for key in ("class", "semantic", "instance", "instance_preview")}}
    arrays = {"rgb_png": display, "class": class_ids, "semantic": class_map.palette()[class_ids],
              "instance": instance_ids, "instance_preview": previews.instance_preview(instance_ids)}
    if not rejected:
        labels, instance_cs, colour = cityscapes.cityscapes_arrays(class_ids, instance_ids, scene_instances,
                                                                  class_map, ignored)
        files.update({"panoptic": Layout.panoptic_png(split, name),
                      "cs_labelIds": Layout.cityscapes(split, cs, "labelIds"),
                      "cs_instanceIds": Layout.cityscapes(split, cs, "instanceIds"),
                      "cs_color": Layout.cityscapes(split, cs, "color"),
                      "cs_leftImg8bit": Layout.cityscapes(split, cs, "leftImg8bit"),
                      "yolo_label": Layout.yolo_label(split, name)})
        arrays.update({"panoptic": panoptic_png, "cs_labelIds": labels, "cs_instanceIds": instance_cs,
                       "cs_color": colour, "yolo_label": yolo_text})
    return files, arrays


def write_image(state: WorkerState, image: ImageBuffers, writers: dict | None = None) -> dict:
    """Write every file of ``image`` (each atomically, by ``writers``: key -> function(path, data); default
    :data:`synthua_usd.backends.frame_files.WRITERS`), then its record; returns the worker's result. ``state`` needs
    ``job.out_dir`` and ``writer`` only (a composite worker's state has them too)."""
    writers = frame_files.WRITERS if writers is None else writers
    t0 = time.perf_counter()
    layout = Layout(Path(state.job.out_dir))
    record = image.record
    targets = {key: layout.path(rel) for key, rel in record["files"].items()}
    for path in set(p.parent for p in targets.values()):
        path.mkdir(parents=True, exist_ok=True)
    jobs = []
    for key, path in targets.items():
        if key == "cs_leftImg8bit":
            continue  # a link to the RGB image, made once that exists
        jobs.append(state.writer.encoders.submit(_timed, writers[key], path, image.arrays[key]))
    spent = {}
    for key, job in zip([k for k in targets if k != "cs_leftImg8bit"], jobs):
        spent[f"write_{key}"] = job.result()[1]  # seconds of an encoder thread (it overlaps the next render)
    if "cs_leftImg8bit" in targets:
        _link_or_copy(targets["rgb_png"], targets["cs_leftImg8bit"])
    record["checksums"] = {key: file_entry(layout.root, rel) for key, rel in sorted(record["files"].items())}
    check_record(record, image_kind(record), Layout.record(record["name"]))
    record_path = layout.path(Layout.record(record["name"]))
    record_path.parent.mkdir(parents=True, exist_ok=True)
    write_json_atomic(record_path, record, indent=1)
    seconds = dict(image.seconds, write=time.perf_counter() - t0, **spent)
    return {"record": record, "seconds": seconds}


def _timed(writer, path: Path, data) -> tuple[object, float]:
    """``writer(path, data)`` and the seconds it took."""
    t0 = time.perf_counter()
    return writer(path, data), time.perf_counter() - t0


def _link_or_copy(source: Path, target: Path) -> None:
    """``target`` as a hard link to ``source`` (the Cityscapes copy of the RGB image costs no space), or a
    copy where the file system has no hard links; replaced atomically either way."""
    import shutil

    with atomic_path(target) as tmp:
        os.unlink(tmp)
        try:
            os.link(source, tmp)
        except OSError:
            shutil.copyfile(source, tmp)
