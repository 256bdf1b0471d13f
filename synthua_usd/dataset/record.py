"""The record of a dataset image and of a tracking sequence's frame, typed: their keys written once.

``records/{name}.json`` holds an :class:`ImageRecord` (a composite of ``synthua composite``: a
:class:`CompositeRecord`), ``sequences/{sequence}/records/{frame}.json`` a :class:`SequenceFrameRecord`; all are
documents of ``schemas/record.schema.json`` (its ``$defs/image``, ``$defs/composite_image`` and
``$defs/sequence_frame``), whose descriptions say what each field means. The writers
(:mod:`synthua_usd.pipeline.dataset_worker`, :mod:`synthua_usd.pipeline.composite_worker`,
:mod:`synthua_usd.pipeline.sequences`) build these TypedDicts and
validate each record before writing it (:func:`check_record`); every reader of a record on disk (``synthua verify``
and replay, generate's and the sequences' resumption, analytics, ``synthua randomise --record``, the tools) reads it
with :func:`read_record`, which validates it, so a reader takes the keys the schema requires as given (no
``.get`` with a default). An image QA rejected (:func:`is_rejected`) stays in the metadata table and ``rejected.csv``
and is left out of everything else. A test holds the keys here to the schema's; mypy (``make test``) checks the
readers' use of them.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Final, Literal, NotRequired, TypedDict, final, overload

from synthua_usd.core.errors import SchemaError
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import read_json, schema_problem, validate_document

if TYPE_CHECKING:
    from synthua_usd.model.cameras import PinholeCamera
    from synthua_usd.model.render_config import RenderConfig

SCHEMA = "record"
#: The schema's definitions of the kinds of record.
IMAGE: Final = "image"
COMPOSITE: Final = "composite_image"
SEQUENCE_FRAME: Final = "sequence_frame"
#: What a message calls each kind.
_WHAT = {IMAGE: "an image record", COMPOSITE: "an image record", SEQUENCE_FRAME: "a sequence frame's record"}
#: The QA verdict that leaves an image out of every annotation format, analysis and training set
#: (:func:`is_rejected`); the others are ``accepted`` and ``flagged``.
REJECTED: Final = "rejected"


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


@final  # no record is a subtype of another: ``"composite" in record`` tells the kinds apart for mypy
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


class PhotoCameraEntry(TypedDict):
    """The camera model of a composite's photo (``$defs/photo_camera``;
    :class:`synthua_usd.dataset.composite_plan.DrawnCamera`)."""

    width_px: int
    height_px: int
    horizon_row_px: float
    height_m: float
    focal_px: float
    pitch_deg: float
    K: list[list[float]]
    sources: dict[str, str]
    exif_focal_35mm: float | None
    light: dict[str, float] | None


class CompositeEntry(TypedDict):
    """What a composite was made of (``$defs/composite``): its background, bank, pastes (``$defs/paste``), the
    background's boxes (``$defs/background_box``) and the camera effects."""

    background: dict[str, Any]
    bank: dict[str, str]
    pastes: list[dict[str, Any]]
    background_boxes: list[dict[str, Any]]
    effects: dict[str, Any] | None


@final
class CompositeRecord(TypedDict):
    """``records/{name}.json`` of a composite (``$defs/composite_image``)."""

    id: int
    name: str
    split: str
    width: int
    height: int
    seed: int
    camera: PhotoCameraEntry
    files: dict[str, str]
    class_pixel_counts: dict[str, int]
    instances: list[InstanceEntry]
    panoptic_segments: list[PanopticSegment]
    qa: QAResult
    composite: CompositeEntry
    #: Added once the files are written (every record on disk has it).
    checksums: NotRequired[dict[str, FileEntry]]


@final
class SequenceFrameRecord(FrameRecord):
    """``sequences/{sequence}/records/{frame}.json`` (``$defs/sequence_frame``)."""

    sequence: str
    frame: int


#: The record of a dataset image (``records/{name}.json``): rendered, or a composite (it holds ``composite``).
DatasetRecord = ImageRecord | CompositeRecord


def record_camera(camera: PinholeCamera, render_size: tuple[int, int], written_size: tuple[int, int], *, name: str,
                  rig_type: str | None) -> RecordCamera:
    """The camera block of a record (``$defs/camera``), and the shared part of ``frame.json``'s: ``K`` at the
    written size (the render size's, scaled: (3, 3), pixels, OpenCV's axes, pixel centres at +0.5), USD's
    ``camera_to_world`` (column vectors, looking down -Z), OpenCV's ``world_to_camera_opencv``, the lens in mm, the
    clipping range in metres and the distortion (None for an ideal pinhole). ``render_size`` and ``written_size`` are
    (width, height) in pixels; ``name`` and ``rig_type`` are the planned camera's."""
    (render_w, render_h), (width, height) = render_size, written_size
    K = camera.intrinsics(render_w, render_h).copy()
    K[0] *= width / render_w
    K[1] *= height / render_h
    return RecordCamera(prim_path=camera.path, name=name, rig_type=rig_type,
                        K=K.tolist(), camera_to_world=camera.camera_to_world.tolist(),
                        world_to_camera_opencv=camera.world_to_camera_opencv().tolist(),
                        focal_length_mm=camera.focal_length_mm, horizontal_aperture_mm=camera.horizontal_aperture_mm,
                        vertical_aperture_mm=camera.vertical_aperture_mm,
                        clipping_range_m=[camera.clip_near_m, camera.clip_far_m],
                        distortion=camera.distortion.to_dict() if camera.distortion is not None else None)


def record_render(config: RenderConfig, variant: str, denoise: dict[str, Any] | None) -> RecordRender:
    """The render block of a record (``$defs/render``), and the shared part of ``frame.json``'s: the settings an
    image was rendered with (``config``: :func:`synthua_usd.model.render_config.resolve_render`'s), the Mitsuba
    ``variant`` that ran and what the denoiser did (None: not denoised)."""
    return RecordRender(variant=variant, spp=config.spp, pixel_filter=config.pixel_filter, max_depth=config.max_depth,
                        width=config.width, height=config.height, denoise=denoise)


def image_kind(record: Any) -> str:
    """The kind of record a dataset image's record is: :data:`COMPOSITE` when it holds ``composite``, else
    :data:`IMAGE`."""
    return COMPOSITE if isinstance(record, dict) and "composite" in record else IMAGE


def is_rejected(record: DatasetRecord) -> bool:
    """True when QA rejected the image (:data:`REJECTED`): it is listed in the metadata table and ``rejected.csv``,
    never in an annotation format, an analysis or a training set. The manifest copies each image's verdict, and
    :func:`synthua_usd.dataset.manifest.kept_images` keeps its images by this rule."""
    return record["qa"]["verdict"] == REJECTED


def check_record(record: ImageRecord | CompositeRecord | SequenceFrameRecord, kind: str, source: str) -> None:
    """Raise :class:`SchemaError` naming ``source`` and the field when ``record`` is not a valid record of
    ``kind`` (:data:`IMAGE`, :data:`COMPOSITE` or :data:`SEQUENCE_FRAME`)."""
    validate_document(record, SCHEMA, source, kind)


def record_problem(document: Any, kind: str) -> str | None:
    """Why ``document`` is not a valid record of ``kind`` (``<field>: <found>; expected ...``), or None."""
    return schema_problem(document, SCHEMA, kind)


@overload
def read_record(path: str | Path, kind: None = None) -> DatasetRecord: ...
@overload
def read_record(path: str | Path, kind: Literal["image"]) -> ImageRecord: ...
@overload
def read_record(path: str | Path, kind: Literal["composite_image"]) -> CompositeRecord: ...
@overload
def read_record(path: str | Path, kind: Literal["sequence_frame"]) -> SequenceFrameRecord: ...
@overload
def read_record(path: str | Path, kind: str | None) -> ImageRecord | CompositeRecord | SequenceFrameRecord: ...
def read_record(path: str | Path, kind: str | None = None) -> ImageRecord | CompositeRecord | SequenceFrameRecord:
    """The record at ``path``: read with the limits of every JSON input (:func:`synthua_usd.core.schemas.read_json`)
    and validated against ``$defs/<kind>`` of ``schemas/record.schema.json`` (``kind`` None: a dataset image's
    record, of the kind :func:`image_kind` says). Anything else raises :class:`InputError` in one line naming the
    file (and the field: ``<path>: not an image record: qa.verdict: 'maybe' is not one of ...``)."""
    document = read_json(path, _WHAT[kind or IMAGE])
    kind = kind or image_kind(document)
    problem = record_problem(document, kind)
    if problem is not None:
        raise SchemaError(f"{shown(path)}: not {_WHAT[kind]}: {problem}")
    return document
