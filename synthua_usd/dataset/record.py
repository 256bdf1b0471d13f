"""The record of a dataset image and of a tracking sequence's frame, typed: their keys written once.

``records/{name}.json`` holds an :class:`ImageRecord`, ``sequences/{sequence}/records/{frame}.json`` a
:class:`SequenceFrameRecord`; both are documents of ``schemas/record.schema.json`` (its ``$defs/image`` and
``$defs/sequence_frame``), whose descriptions say what each field means. The writers
(:mod:`synthua_usd.pipeline.dataset_worker`, :mod:`synthua_usd.pipeline.sequences`) build these TypedDicts and
validate each record before writing it (:func:`check_record`); the readers (``synthua verify``, the dataset
formats, analytics, ``synthua randomise --record``) take them, and verify reports a record that does not
validate as a problem of the dataset (:func:`record_problem`). A test holds the keys here to the schema's.
"""

from __future__ import annotations

from typing import Any, NotRequired, TypedDict

from synthua_usd.core.schemas import schema_problem, validate_document

SCHEMA = "record"
#: The schema's definitions of the two kinds of record.
IMAGE, SEQUENCE_FRAME = "image", "sequence_frame"


class FileEntry(TypedDict):
    """A file's path (relative to the dataset folder), size and SHA-256 (the manifest's entries too)."""

    path: str
    sha256: str
    bytes: int


class RecordCamera(TypedDict):
    """The camera of a record (``$defs/camera``): ``K`` at the written size, extrinsics, lens."""

    prim_path: str
    name: str
    rig_type: str | None
    K: list[list[float]]
    camera_to_world: list[list[float]]
    world_to_camera_opencv: list[list[float]]
    focal_length_mm: float
    horizontal_aperture_mm: float
    vertical_aperture_mm: float
    clipping_range_m: list[float]
    distortion: dict[str, Any] | None


class RecordRender(TypedDict):
    """What an image was rendered with (``$defs/render``; :func:`synthua_usd.model.render_config.resolve_render`)."""

    variant: str
    spp: int
    pixel_filter: str
    max_depth: int
    width: int
    height: int
    denoise: dict[str, Any] | None


class InstanceEntry(TypedDict):
    """One visible instance (``$defs/instance``; :func:`synthua_usd.dataset.annotations.annotate` makes it)."""

    id: int
    category_id: int
    class_name: str
    isthing: bool
    prim_path: str
    area: int
    bbox: list[float]
    segmentation: dict[str, Any]
    amodal_area: int
    amodal_bbox: list[float]
    amodal_segmentation: dict[str, Any]
    occlusion: float
    truncation: float
    relations: dict[str, str]
    #: Set by :func:`synthua_usd.dataset.annotations.mark_ignored` (every written entry has it).
    ignore: NotRequired[bool]
    #: Only instances of a class with keypoints (:mod:`synthua_usd.dataset.keypoints`).
    keypoints: NotRequired[dict[str, Any]]


class PanopticSegment(TypedDict):
    """One segment of the image's panoptic PNG (``$defs/panoptic_segment``)."""

    id: int
    category_id: int
    area: int
    bbox: list[float]
    iscrowd: int


class QAResult(TypedDict):
    """The QA verdict of an image, its reasons and measures (``$defs/qa``; :mod:`synthua_usd.dataset.qa`)."""

    verdict: str
    reasons: list[str]
    measures: dict[str, float]


class FrameRecord(TypedDict):
    """What the record of an image and of a sequence frame share: one rendered view and its files."""

    width: int
    height: int
    camera: RecordCamera
    time_code: float
    seed: int
    condition: dict[str, Any] | None
    exposure: dict[str, Any] | None
    files: dict[str, str]
    instances: list[InstanceEntry]
    #: Added once the files are written (every record on disk has it).
    checksums: NotRequired[dict[str, FileEntry]]


class ImageRecord(FrameRecord):
    """``records/{name}.json`` (``$defs/image``)."""

    id: int
    name: str
    split: str
    render: RecordRender
    layer_stack: str
    class_pixel_counts: dict[str, int]
    panoptic_segments: list[PanopticSegment]
    qa: QAResult
    #: Only in a randomised dataset.
    randomisation: NotRequired[dict[str, Any]]


class SequenceFrameRecord(FrameRecord):
    """``sequences/{sequence}/records/{frame}.json`` (``$defs/sequence_frame``)."""

    sequence: str
    frame: int


def check_record(record: ImageRecord | SequenceFrameRecord, kind: str, source: str) -> None:
    """Raise :class:`SchemaError` naming ``source`` and the field when ``record`` is not a valid record of
    ``kind`` (:data:`IMAGE` or :data:`SEQUENCE_FRAME`)."""
    validate_document(record, SCHEMA, source, kind)


def record_problem(document: Any, kind: str) -> str | None:
    """Why ``document`` is not a valid record of ``kind`` (``<field>: <found>; expected ...``), or None."""
    return schema_problem(document, SCHEMA, kind)
