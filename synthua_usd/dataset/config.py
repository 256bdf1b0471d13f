"""The generation config (``synthua generate --config GEN.json``) as checked, frozen plain data.

A document is first validated by ``schemas/generate.schema.json`` (types, ranges, unknown keys), then by the
rules a schema cannot state (split ratios summing to 1, quota counts within ``images``, a resample size within
the render size, a time-code spec that parses). Either kind of failure raises :class:`InputError` (the
schema's as :class:`SchemaError`) with one line ``<file>: <field>: <found>; <expected>``.

The meaning of every field is documented once, in the schema's descriptions; the dataclasses here mirror it.
Checks that need the stage (camera paths, condition names, the stage's time range and resolution) happen
where the stage is known: :func:`synthua_usd.dataset.sampling.candidates`, :meth:`GenerationConfig.output_size`
(the render size is settled by :func:`synthua_usd.model.render_config.resolve_render`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from synthua_usd.composition.rigs import RIG_TYPES
from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import load_schema, read_json, validate_document
from synthua_usd.dataset.record import REJECTED
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.timecodes import parse_time_code_spec
from synthua_usd.randomisation.config import RandomisationConfig

SCHEMA = "generate"
#: Rig-type key of cameras that carry no ``synthua:rig:type``.
NO_RIG = "none"
RIG_KEYS = (*RIG_TYPES, NO_RIG)
QA_CHECKS = ("blur", "shadows", "highlights", "aid_size", "aid_occlusion")
#: Most time codes one spec string may expand to.
_RATIO_TOLERANCE = 1e-6


def schema_default(path: str) -> Any:
    """The default the schema documents for a field, by a dotted path whose first part may name a ``$defs``
    entry (``"qa.blur_min"`` reads ``$defs.qa.properties.blur_min.default``). The dataclasses below own the
    defaults; a test holds the schema's documentation to them."""
    schema = load_schema(SCHEMA)
    first, *rest = path.split(".")
    node = schema["$defs"][first] if rest else schema["properties"][first]
    for key in rest:
        node = node["properties"][key]
    return node["default"]


@dataclass(frozen=True)
class RenderSettings:
    """The config's ``render`` block; a field left None is the stage's render settings', else
    :class:`RenderConfig`'s (:func:`synthua_usd.model.render_config.resolve_render`). See the schema's ``render``."""

    width: int | None = None
    height: int | None = None
    spp: int | None = None
    max_depth: int = RenderConfig.max_depth
    pixel_filter: str = RenderConfig.pixel_filter
    denoise: bool = RenderConfig.denoise

    def render_values(self) -> dict:
        """The block as :func:`synthua_usd.model.render_config.resolve_render`'s ``config`` source."""
        return dict(vars(self))


@dataclass(frozen=True)
class CameraSelector:
    """One item of ``cameras``: a prim path or glob ``pattern``, or a set of ``rig_types`` (keys of
    :data:`RIG_KEYS`)."""

    pattern: str | None = None
    rig_types: tuple[str, ...] = ()

    def to_document(self) -> str | dict:
        return self.pattern if self.pattern is not None else {"rig_types": list(self.rig_types)}


@dataclass(frozen=True)
class AidUserQuota:
    """At least ``min_share`` of the images show an aid user of ``min_pixels`` visible pixels (person and
    device together), at most ``max_occlusion`` occluded when given."""

    min_share: float
    min_pixels: int
    max_occlusion: float | None = None

    def images(self, total: int) -> int:
        """Images the quota asks for out of ``total``: ceil(min_share × total)."""
        return math.ceil(self.min_share * total - 1e-9)

    def qualifies(self, visible_pixels: int, occlusion: float | None) -> bool:
        """Whether one aid user counts for the quota. An unknown occlusion (the planner's label pass counts
        visible pixels only) passes ``max_occlusion``; the images' records, which know it, are what
        ``coverage.json`` reports as achieved."""
        if visible_pixels < self.min_pixels:
            return False
        return self.max_occlusion is None or occlusion is None or occlusion <= self.max_occlusion


@dataclass(frozen=True)
class CountQuota:
    """Images per key (condition name or rig type): explicit minimum ``counts``, or ``balanced``."""

    balanced: bool = False
    counts: tuple[tuple[str, int], ...] = ()

    def targets(self, keys: list[str], total: int) -> dict[str, int]:
        """Images asked per key. Balanced: ``total`` shared over ``keys`` as evenly as possible, the first
        keys taking the remainder; explicit: the counts (keys not swept included, so that they show up as
        shortfalls)."""
        if not self.balanced:
            return dict(self.counts)
        if not keys:
            return {}
        base, extra = divmod(total, len(keys))
        return {key: base + (1 if k < extra else 0) for k, key in enumerate(keys)}

    def to_document(self) -> str | dict:
        return "balanced" if self.balanced else dict(self.counts)


@dataclass(frozen=True)
class Quotas:
    aid_users: AidUserQuota | None = None
    per_condition: CountQuota | None = None
    per_rig_type: CountQuota | None = None


@dataclass(frozen=True)
class SplitRatios:
    """Train/val/test shares (summing to 1) and the seed of the camera order; see :mod:`sampling`."""

    train: float = 0.8
    val: float = 0.1
    test: float = 0.1
    seed: int = 0

    @property
    def ratios(self) -> dict[str, float]:
        return {"train": self.train, "val": self.val, "test": self.test}


@dataclass(frozen=True)
class QAThresholds:
    """Thresholds of :func:`synthua_usd.dataset.qa.verdict` (None turns a check off) and the checks that
    reject rather than flag. Units: ``blur_min`` squared 8-bit levels (variance of the Laplacian of luma);
    the clipped maxima are shares of pixels 0..1; ``aid_min_pixels`` pixels; ``aid_max_occlusion`` 0..1."""

    blur_min: float | None = 10.0
    shadows_clipped_max: float | None = 0.5
    highlights_clipped_max: float | None = 0.25
    aid_min_pixels: int | None = 100
    aid_max_occlusion: float | None = 0.9
    reject: tuple[str, ...] = ()

    def action(self, check: str) -> str:
        """``rejected`` or ``flagged``: what failing ``check`` does to an image."""
        return REJECTED if check in self.reject else "flagged"


@dataclass(frozen=True)
class Outputs:
    rgb_exr: bool = False
    depth: bool = True
    onehot: bool = False


@dataclass(frozen=True)
class Resample:
    """Written size in pixels (at most the render size on each side)."""

    width: int
    height: int


@dataclass(frozen=True)
class SequenceCrowd:
    """The crowd populated for sequences (persons per m² of walkable area, share using mobility aids)."""

    density_per_m2: float = 0.03
    aid_share: float = 0.3


#: Most frames one sequence may have.
MAX_SEQUENCE_FRAMES = 10_000
#: Fewest: a track of one frame is no tracking sequence.
MIN_SEQUENCE_FRAMES = 2


@dataclass(frozen=True)
class SequencesConfig:
    """Tracking sequences: one per camera x condition x seed, ``duration_s`` of scene time at ``fps``; field
    meanings in the schema's ``$defs.sequences``."""

    cameras: tuple[CameraSelector, ...] = ()
    conditions: str | tuple[str, ...] = ()
    seeds: tuple[int, ...] = (0,)
    duration_s: float = 10.0
    fps: float = 10.0
    start_time_code: float | None = None
    crowd: SequenceCrowd | None = field(default_factory=SequenceCrowd)
    jpeg_quality: int = 95
    preview: bool = True

    @property
    def frames(self) -> int:
        """Frames per sequence: ``duration_s * fps``, rounded (a config is refused below
        :data:`MIN_SEQUENCE_FRAMES`)."""
        return max(1, int(round(self.duration_s * self.fps)))

    def time_codes(self, start: float, time_codes_per_second: float) -> tuple[float, ...]:
        """The frames' time codes from ``start``: one every ``time_codes_per_second / fps``."""
        return tuple(float(start + k * time_codes_per_second / self.fps) for k in range(self.frames))

    def to_document(self) -> dict:
        return {"cameras": [c.to_document() for c in self.cameras],
                "conditions": self.conditions if isinstance(self.conditions, str) else list(self.conditions),
                "seeds": list(self.seeds), "duration_s": self.duration_s, "fps": self.fps,
                "start_time_code": self.start_time_code,
                "crowd": None if self.crowd is None else dict(vars(self.crowd)),
                "jpeg_quality": self.jpeg_quality, "preview": self.preview}


@dataclass(frozen=True)
class GenerationConfig:
    """One generation run; field meanings in ``schemas/generate.schema.json``.

    ``time_codes`` is already expanded from a spec string (empty: the stage's whole time codes);
    ``conditions`` is ``"all"``, a tuple of names, or empty (the stage's own condition).
    """

    name: str
    images: int
    render: RenderSettings = field(default_factory=RenderSettings)
    cameras: tuple[CameraSelector, ...] = ()
    time_codes: tuple[float, ...] = ()
    conditions: str | tuple[str, ...] = ()
    seeds: tuple[int, ...] = (0,)
    sampling_seed: int = 0
    quotas: Quotas = field(default_factory=Quotas)
    split: SplitRatios = field(default_factory=SplitRatios)
    qa: QAThresholds = field(default_factory=QAThresholds)
    outputs: Outputs = field(default_factory=Outputs)
    resample: Resample | None = None
    amodal_groups: tuple[str, ...] = ("person", "accessibility", "vehicle", "furniture", "animal")
    #: Thing instances with fewer visible pixels are ignore regions in every format (the schema says how).
    min_instance_px: int = 32
    workers: int | None = None
    #: Scene randomisation (None: the scenario rendered as composed).
    randomise: RandomisationConfig | None = None
    #: Tracking sequences (None: none).
    sequences: SequencesConfig | None = None

    @classmethod
    def load(cls, path: str | Path) -> "GenerationConfig":
        """Read, schema-check and rule-check the config at ``path``."""
        return cls.from_document(read_json(path, "a generation config (schemas/generate.schema.json)"),
                                 source=str(path))

    @classmethod
    def from_document(cls, document: Any, source: str = "(in memory)") -> "GenerationConfig":
        """Build from a parsed JSON document; :class:`InputError` names ``source`` and the field."""
        validate_document(document, SCHEMA, source)
        return _Builder(document, shown(source)).build()

    def to_document(self) -> dict:
        """The config with every default made explicit (written to the dataset as ``generate.json``);
        ``from_document(to_document())`` gives an equal config."""
        quotas = self.quotas
        return {
            "name": self.name,
            "images": self.images,
            "render": {k: v for k, v in vars(self.render).items() if v is not None},
            "cameras": [c.to_document() for c in self.cameras],
            "time_codes": list(self.time_codes),
            "conditions": self.conditions if isinstance(self.conditions, str) else list(self.conditions),
            "seeds": list(self.seeds),
            "sampling_seed": self.sampling_seed,
            "quotas": {
                "aid_users": None if quotas.aid_users is None else dict(vars(quotas.aid_users)),
                "per_condition": None if quotas.per_condition is None else quotas.per_condition.to_document(),
                "per_rig_type": None if quotas.per_rig_type is None else quotas.per_rig_type.to_document(),
            },
            "split": dict(vars(self.split)),
            "qa": {**vars(self.qa), "reject": list(self.qa.reject)},
            "outputs": dict(vars(self.outputs)),
            "resample": None if self.resample is None else dict(vars(self.resample)),
            "amodal_groups": list(self.amodal_groups),
            "min_instance_px": self.min_instance_px,
            "workers": self.workers,
            # absent when off, so that configs without it keep the documents (and job keys) they had
            **({} if self.randomise is None else {"randomise": self.randomise.to_document()}),
            **({} if self.sequences is None else {"sequences": self.sequences.to_document()}),
        }

    def output_size(self, render_width: int, render_height: int) -> tuple[int, int]:
        """(width, height) of the written images: the resample size, else the render size. A resample size
        larger than the render (possible when the render size comes from the stage) raises InputError."""
        if self.resample is None:
            return render_width, render_height
        if self.resample.width > render_width or self.resample.height > render_height:
            raise InputError(f"resample: {self.resample.width}x{self.resample.height}; expected at most the render "
                             f"size {render_width}x{render_height} (resampling only shrinks)")
        return self.resample.width, self.resample.height

    def check_amodal_groups(self, groups, class_names, source: str = "amodal_groups") -> None:
        """Refuse names of ``amodal_groups`` that are neither a group nor a class of the class map in use."""
        known = set(groups) | set(class_names)
        unknown = [name for name in self.amodal_groups if name not in known]
        if unknown:
            raise InputError(f"{source}: {', '.join(map(echo, unknown))} is not a class group or class; expected "
                             f"among the groups {', '.join(sorted(set(groups)))} or a class name")

    def amodal_wanted(self, class_name: str, group: str | None) -> bool:
        """Whether instances of ``class_name`` (in ``group``) get amodal masks."""
        return class_name in self.amodal_groups or group in self.amodal_groups


class _Builder:
    """Turns a schema-valid document into a :class:`GenerationConfig`, checking the cross-field rules."""

    def __init__(self, document: dict, source: str):
        self.doc, self.source = document, source

    def fail(self, where: str, found: str, expected: str):
        raise InputError(f"{self.source}: {where}: {found}; {expected}")

    def build(self) -> GenerationConfig:
        doc = self.doc
        images = doc["images"]
        render = RenderSettings(**doc.get("render", {}))
        resample = None
        if doc.get("resample") is not None:
            resample = Resample(doc["resample"]["width"], doc["resample"]["height"])
            for side in ("width", "height"):
                rendered = getattr(render, side)
                if rendered is not None and getattr(resample, side) > rendered:
                    self.fail(f"resample.{side}", f"{getattr(resample, side)} > render.{side} {rendered}",
                              "expected at most the render size (resampling only shrinks)")
        conditions = doc.get("conditions", [])
        conditions = conditions if isinstance(conditions, str) else tuple(conditions)
        quotas = self.quotas(doc.get("quotas", {}), images, conditions)
        split = SplitRatios(**doc.get("split", {}))
        total = split.train + split.val + split.test
        if abs(total - 1.0) > _RATIO_TOLERANCE:
            self.fail("split", f"train + val + test = {total:g}", "expected ratios summing to 1")
        qa_doc = doc.get("qa", {})
        qa = QAThresholds(**{**qa_doc, "reject": tuple(qa_doc.get("reject", ()))})
        outputs = Outputs(**doc.get("outputs", {}))
        cameras = self.cameras(doc.get("cameras", []))
        return GenerationConfig(
            name=doc["name"], images=images, render=render, cameras=cameras,
            time_codes=self.time_codes(doc.get("time_codes", [])), conditions=conditions,
            seeds=tuple(doc.get("seeds", GenerationConfig.seeds)),
            sampling_seed=doc.get("sampling_seed", GenerationConfig.sampling_seed),
            quotas=quotas, split=split, qa=qa, outputs=outputs, resample=resample,
            amodal_groups=tuple(doc.get("amodal_groups", GenerationConfig.amodal_groups)),
            min_instance_px=doc.get("min_instance_px", GenerationConfig.min_instance_px),
            workers=doc.get("workers"), randomise=self.randomise(doc.get("randomise")),
            sequences=self.sequences(doc.get("sequences"), images))

    @staticmethod
    def cameras(items) -> tuple[CameraSelector, ...]:
        return tuple(CameraSelector(pattern=c) if isinstance(c, str) else CameraSelector(rig_types=tuple(c["rig_types"]))
                     for c in items)

    def sequences(self, doc, images: int) -> SequencesConfig | None:
        if doc is None:
            if images == 0:
                self.fail("images", "0 without a sequences block", "expected at least 1 image, or sequences")
            return None
        conditions = doc.get("conditions", [])
        crowd = doc.get("crowd", vars(SequenceCrowd()))
        config = SequencesConfig(
            cameras=self.cameras(doc.get("cameras", [])),
            conditions=conditions if isinstance(conditions, str) else tuple(conditions),
            seeds=tuple(doc.get("seeds", SequencesConfig.seeds)), duration_s=float(doc.get("duration_s", 10.0)),
            fps=float(doc.get("fps", 10.0)), start_time_code=doc.get("start_time_code"),
            crowd=None if crowd is None else SequenceCrowd(**crowd),
            jpeg_quality=int(doc.get("jpeg_quality", 95)), preview=bool(doc.get("preview", True)))
        if config.duration_s * config.fps > MAX_SEQUENCE_FRAMES:
            self.fail("sequences", f"duration_s x fps = {config.duration_s * config.fps:g} frames",
                      f"expected at most {MAX_SEQUENCE_FRAMES} frames a sequence")
        if round(config.duration_s * config.fps) < MIN_SEQUENCE_FRAMES:
            self.fail("sequences.duration_s", f"{config.duration_s:g} s at fps {config.fps:g} is "
                      f"{config.duration_s * config.fps:g} frames", f"expected at least {MIN_SEQUENCE_FRAMES} frames a "
                      f"sequence (a track needs two): a longer duration_s or a higher fps")
        return config

    def randomise(self, doc) -> RandomisationConfig | None:
        try:
            return RandomisationConfig.from_document(doc)
        except InputError as exc:
            raise InputError(f"{self.source}: {exc}") from None

    def time_codes(self, value) -> tuple[float, ...]:
        if isinstance(value, list):
            return tuple(dict.fromkeys(float(v) for v in value))
        try:
            return parse_time_code_spec(value)
        except ValueError as exc:
            self.fail("time_codes", f"{echo(value)!r}", f"expected {exc}")

    def quotas(self, doc: dict, images: int, conditions) -> Quotas:
        aid = doc.get("aid_users")
        aid_quota = None if aid is None else AidUserQuota(aid["min_share"], aid["min_pixels"], aid.get("max_occlusion"))
        per_condition = self.count_quota(doc.get("per_condition"), "per_condition", images)
        per_rig = self.count_quota(doc.get("per_rig_type"), "per_rig_type", images)
        if per_rig is not None:
            unknown = [k for k, _ in per_rig.counts if k not in RIG_KEYS]
            if unknown:
                self.fail("quotas.per_rig_type", f"{', '.join(map(echo, unknown))} is not a rig type",
                          f"expected keys among {', '.join(RIG_KEYS)}")
        if per_condition is not None and not per_condition.balanced:
            if isinstance(conditions, tuple) and not conditions:
                self.fail("quotas.per_condition", "counts per condition while conditions is empty (the stage's own "
                          "condition only)", "expected conditions to list the conditions or be \"all\"")
            if isinstance(conditions, tuple):
                missing = [k for k, _ in per_condition.counts if k not in conditions]
                if missing:
                    self.fail("quotas.per_condition", f"{', '.join(map(echo, missing))} is not among conditions",
                              f"expected keys among {', '.join(conditions)}")
        return Quotas(aid_quota, per_condition, per_rig)

    def count_quota(self, value, name: str, images: int) -> CountQuota | None:
        if value is None:
            return None
        if value == "balanced":
            return CountQuota(balanced=True)
        total = sum(value.values())
        if total > images:
            self.fail(f"quotas.{name}", f"counts sum to {total}", f"expected at most images = {images}")
        return CountQuota(counts=tuple(sorted(value.items())))
