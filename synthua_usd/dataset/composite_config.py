"""The composite config (``synthua composite ... --config CFG``) as checked, frozen plain data.

A document is validated by ``schemas/composite.schema.json`` first (types, ranges, unknown keys: the meaning of
every field is documented there, once), then by the rules a schema cannot state (ranges with low <= high, split
ratios summing to 1, some blend weight positive). Any failure raises :class:`InputError` as one line
``<file>: <field>: <found>; <expected>``. The dataclasses own the defaults; a test holds the schema's to them.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path, PurePosixPath
from typing import Any

from synthua_usd.core.errors import InputError
from synthua_usd.core.schemas import read_json, validate_document
from synthua_usd.dataset.config import QAThresholds, SplitRatios
from synthua_usd.dataset.cutout_bank import GROUPS, Light
from synthua_usd.model.box_conventions import CONVENTIONS
from synthua_usd.model.taxonomy import WHEELCHAIRS
from synthua_usd.randomisation.config import EffectsRandomisation, Range, _range

SCHEMA = "composite"
BLEND_MODES = ("hard", "feather", "blur", "poisson")
_SPLIT_TOLERANCE = 1e-6


#: The camera fields that let a labelled photo's people place its horizon (:meth:`CameraSettings.people_heights`).
PEOPLE_HEIGHTS = ("person_height_m", "wheelchair_height_m")


@dataclass(frozen=True)
class CameraSettings:
    """How a photo's camera model is found (schema ``$defs/camera_part``); each range is drawn per composite."""

    horizon_row_share: Range = (0.1, 0.5)
    height_m: Range = (1.1, 1.7)
    focal_width_share: Range = (0.7, 1.1)
    use_exif: bool = True
    pitch_deg: float | None = None
    light: Light | None = None
    person_height_m: float | None = None
    wheelchair_height_m: float | None = None

    def __post_init__(self) -> None:
        for name, lo, hi in (("horizon_row_share", -10.0, 10.0), ("height_m", 0.05, 1000.0),
                             ("focal_width_share", 0.05, 20.0)):
            object.__setattr__(self, name, _range(f"camera.{name}", getattr(self, name), lo, hi))
        for name in PEOPLE_HEIGHTS:
            value = getattr(self, name)
            if value is not None and not 0.5 <= value <= 2.5:
                raise InputError(f"camera.{name}: {value}; expected metres in [0.5, 2.5] or null")

    def to_document(self) -> dict:
        """Every field; the people's heights only where set (they came after datasets were made, whose job keys
        stay)."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out.update({k: list(out[k]) for k in ("horizon_row_share", "height_m", "focal_width_share")})
        out["light"] = None if self.light is None else asdict(self.light)
        for name in PEOPLE_HEIGHTS:
            if out[name] is None:
                del out[name]
        return out

    def people_heights(self) -> dict[str, float]:
        """The height in metres, from the ground up, of each class of the photo's boxes that places its horizon
        (``person`` standing, each wheelchair with its seated user), as set; empty where none is, or where a known
        ``pitch_deg`` places the horizon."""
        if self.pitch_deg is not None:
            return {}
        heights = {"person": self.person_height_m} if self.person_height_m is not None else {}
        if self.wheelchair_height_m is not None:
            heights.update(dict.fromkeys(WHEELCHAIRS, self.wheelchair_height_m))
        return heights


#: What a paste does that finds no column within its overlap limits (schema ``pastes.when_no_room``).
WHEN_NO_ROOM = ("least_overlap", "skip")


@dataclass(frozen=True)
class PasteSettings:
    """How many cut-outs a composite gets, which and where (schema ``pastes``)."""

    per_image: tuple[int, int] = (1, 3)
    height_share: Range = (0.2, 0.9)
    aid_user_share: float = 0.75
    at_least_one_aid_user: bool = True
    aids: tuple[str, ...] | None = None
    groups: tuple[str, ...] | None = None
    elevation_tolerance_deg: float = 10.0
    choose_among: int = 4
    max_overlap: float = 0.3
    placement_tries: int = 12
    max_background_cover: float | None = None
    when_no_room: str = "least_overlap"
    edge_cut: float = 0.0

    def __post_init__(self) -> None:
        lo, hi = _range("pastes.per_image", self.per_image, 0, 100)
        object.__setattr__(self, "per_image", (int(lo), int(hi)))
        object.__setattr__(self, "height_share", _range("pastes.height_share", self.height_share, 0.001, 1.0))
        if self.when_no_room not in WHEN_NO_ROOM:
            raise InputError(f"pastes.when_no_room: {self.when_no_room!r}; expected one of {', '.join(WHEN_NO_ROOM)}")
        if not 0.0 <= self.edge_cut <= 0.9:
            raise InputError(f"pastes.edge_cut: {self.edge_cut}; expected a share in [0, 0.9]")
        if self.max_background_cover is not None and not 0.0 <= self.max_background_cover <= 1.0:
            raise InputError(f"pastes.max_background_cover: {self.max_background_cover}; expected null or a share "
                             f"in [0, 1]")
        for name in ("aids", "groups"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, tuple(getattr(self, name)))


@dataclass(frozen=True)
class BlendSettings:
    """Weights of the blend modes and their parameters (schema ``blend``)."""

    hard: float = 0.25
    feather: float = 0.3
    blur: float = 0.3
    poisson: float = 0.15
    feather_px: Range = (1.0, 3.0)
    blur_sigma_px: Range = (0.5, 1.5)

    def __post_init__(self) -> None:
        if sum(self.weights.values()) <= 0:
            raise InputError(f"blend: weights {self.weights}; expected at least one weight > 0")
        object.__setattr__(self, "feather_px", _range("blend.feather_px", self.feather_px, 0.0, 100.0))
        object.__setattr__(self, "blur_sigma_px", _range("blend.blur_sigma_px", self.blur_sigma_px, 0.0, 100.0))

    @property
    def weights(self) -> dict[str, float]:
        return {mode: float(getattr(self, mode)) for mode in BLEND_MODES}


@dataclass(frozen=True)
class MatchSettings:
    """Exposure, white balance and (where their strengths are > 0) sharpness, contrast and saturation of a paste
    matched to its surroundings (schema ``match``)."""

    exposure_strength: float = 0.5
    exposure_gain: Range = (0.5, 2.0)
    white_balance_strength: float = 0.5
    white_balance_gain: Range = (0.8, 1.25)
    surround_share: float = 0.5
    sharpness_strength: float = 0.0
    sharpness_sigma_px: float = 3.0
    contrast_strength: float = 0.0
    contrast_gain: Range = (0.67, 1.5)
    saturation_strength: float = 0.0
    saturation_gain: Range = (0.5, 1.5)

    def __post_init__(self) -> None:
        for name in ("exposure_gain", "white_balance_gain"):
            object.__setattr__(self, name, _range(f"match.{name}", getattr(self, name), 1e-3, 1e3))
        for name in ("contrast_gain", "saturation_gain"):
            object.__setattr__(self, name, _range(f"match.{name}", getattr(self, name), 0.1, 10.0))
        for name in ("contrast_strength", "saturation_strength"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise InputError(f"match.{name}: {getattr(self, name)}; expected a share in [0, 1]")
        if not 0.0 <= self.sharpness_strength <= 1.0:
            raise InputError(f"match.sharpness_strength: {self.sharpness_strength}; expected a share in [0, 1]")
        if not 0.0 <= self.sharpness_sigma_px <= 50.0:
            raise InputError(f"match.sharpness_sigma_px: {self.sharpness_sigma_px}; expected px in [0, 50]")


@dataclass(frozen=True)
class SharpenSettings:
    """An unsharp mask on a ``share`` of the pastes after their blend (schema ``sharpen``): each sharpened paste's
    ``amount`` and Gaussian ``sigma_px`` drawn uniform from the ranges."""

    share: float = 0.0
    amount: Range = (2.0, 3.0)
    sigma_px: Range = (1.5, 2.5)

    def __post_init__(self) -> None:
        if not 0.0 <= self.share <= 1.0:
            raise InputError(f"sharpen.share: {self.share}; expected a share in [0, 1]")
        object.__setattr__(self, "amount", _range("sharpen.amount", self.amount, 0.0, 10.0))
        object.__setattr__(self, "sigma_px", _range("sharpen.sigma_px", self.sigma_px, 0.3, 10.0))

    @property
    def on(self) -> bool:
        """Whether any paste may be sharpened (and so whether its pastes' records say so)."""
        return self.share > 0


#: The key of ``background_labels.classes`` for every class it does not list (mapped to null: left out).
OTHER_CLASSES = "*"


@dataclass(frozen=True)
class BackgroundLabels:
    """What becomes of a labelled background's boxes (schema ``background_labels``)."""

    classes: tuple[tuple[str, str | None], ...] = ()
    drop_covered_share: float = 0.5
    drop_cropped_share: float = 0.5

    def __post_init__(self) -> None:
        if dict(self.classes).get(OTHER_CLASSES, None) is not None:
            raise InputError(f"background_labels.classes.{OTHER_CLASSES}: {dict(self.classes)[OTHER_CLASSES]!r}; "
                             f"expected null (every class not listed left out)")

    def our_class(self, name: str) -> str | None:
        """The class a box of the set's class ``name`` becomes (None: left out): as listed, else as ``"*"`` says
        (null: every class not listed is left out), else the same name."""
        mapping = dict(self.classes)
        return mapping[name] if name in mapping else None if OTHER_CLASSES in mapping else name


#: The composites' size (width, height) where the config gives no ``output``.
DEFAULT_OUTPUT = (640, 480)


@dataclass(frozen=True)
class CompositeConfig:
    """The whole config; see ``schemas/composite.schema.json`` for every field."""

    name: str = "composite"
    seed: int = 0
    images_per_background: int = 2
    max_images: int | None = None
    output: tuple[int, int] | None = DEFAULT_OUTPUT
    camera: CameraSettings = field(default_factory=CameraSettings)
    folders: tuple[tuple[str, dict], ...] = ()
    pastes: PasteSettings = field(default_factory=PasteSettings)
    blend: BlendSettings = field(default_factory=BlendSettings)
    shadow_strength: Range = (0.6, 1.0)
    match: MatchSettings = field(default_factory=MatchSettings)
    sharpen: SharpenSettings = field(default_factory=SharpenSettings)
    effects: EffectsRandomisation = field(default_factory=EffectsRandomisation)
    background_labels: BackgroundLabels = field(default_factory=BackgroundLabels)
    convention: str = "synthua"
    split: SplitRatios = field(default_factory=SplitRatios)
    qa: QAThresholds = field(default_factory=QAThresholds)
    min_instance_px: int = 32
    workers: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "shadow_strength", _range("shadow.strength", self.shadow_strength, 0.0, 1.0))
        if self.convention not in CONVENTIONS:
            raise InputError(f"convention: {self.convention!r}; expected one of {', '.join(CONVENTIONS)}")
        total = self.split.train + self.split.val + self.split.test
        if abs(total - 1.0) > _SPLIT_TOLERANCE:
            raise InputError(f"split: train + val + test = {total:g}; expected ratios summing to 1")
        groups = self.pastes.groups or ()
        if any(g not in GROUPS for g in groups):
            raise InputError(f"pastes.groups: {list(groups)}; expected some of {', '.join(GROUPS)}")

    @classmethod
    def load(cls, path: str | Path) -> "CompositeConfig":
        return cls.from_document(read_json(path, "a composite config (schemas/composite.schema.json)"), str(path))

    @classmethod
    def from_document(cls, doc: Any, source: str = "(in memory)") -> "CompositeConfig":
        """The config of a document (validated against the schema first); failures name ``source``."""
        validate_document(doc, SCHEMA, source)
        try:
            return _build(doc)
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None

    def sets_people_heights(self) -> bool:
        """Whether ``camera`` or a folder of ``folders`` sets a height of :data:`PEOPLE_HEIGHTS` (the photo's people
        may place its horizon)."""
        return (any(getattr(self.camera, name) is not None for name in PEOPLE_HEIGHTS)
                or any(part.get(name) is not None for _, part in self.folders for name in PEOPLE_HEIGHTS))

    def camera_for(self, relative: str) -> tuple[CameraSettings, dict[str, str]]:
        """The camera settings of the background at ``relative`` (a POSIX path relative to BACKGROUNDS): the
        config's ``camera`` with the fields of the longest folder of ``folders`` holding it, and the source of each
        field (``config`` or ``folder:<name>``)."""
        parents = {str(p) for p in PurePosixPath(relative).parents}
        matching = sorted((f for f, _ in self.folders if f.strip("/") in parents), key=len)
        settings, sources = self.camera, {f.name: "config" for f in fields(CameraSettings)}
        for folder in matching:
            part = dict(self.folders)[folder]
            settings = replace(settings, **_camera_fields(part))
            sources.update({key: f"folder:{folder}" for key in part})
        return settings, sources

    def to_document(self) -> dict:
        """The config as a complete document (every default written out), the dataset's record of what ran."""
        return {
            "name": self.name, "seed": self.seed, "images_per_background": self.images_per_background,
            "max_images": self.max_images,
            "output": None if self.output is None else {"width": self.output[0], "height": self.output[1]},
            "camera": self.camera.to_document(), "folders": {f: dict(part) for f, part in self.folders},
            "pastes": {**asdict(self.pastes), "per_image": list(self.pastes.per_image),
                       "height_share": list(self.pastes.height_share),
                       "aids": None if self.pastes.aids is None else list(self.pastes.aids),
                       "groups": None if self.pastes.groups is None else list(self.pastes.groups)},
            "blend": {**asdict(self.blend), "feather_px": list(self.blend.feather_px),
                      "blur_sigma_px": list(self.blend.blur_sigma_px)},
            "shadow": {"strength": list(self.shadow_strength)},
            "match": _match_document(self.match),
            **({} if self.sharpen == SharpenSettings() else {"sharpen": {  # later than the datasets made before it
                "share": self.sharpen.share, "amount": list(self.sharpen.amount),
                "sigma_px": list(self.sharpen.sigma_px)}}),
            "effects": {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self.effects).items()},
            "background_labels": {"classes": dict(self.background_labels.classes),
                                  "drop_covered_share": self.background_labels.drop_covered_share,
                                  "drop_cropped_share": self.background_labels.drop_cropped_share},
            "convention": self.convention, "split": asdict(self.split),
            "qa": {**asdict(self.qa), "reject": list(self.qa.reject)},
            "min_instance_px": self.min_instance_px, "workers": self.workers,
        }


#: Groups of fields of ``match`` that came after datasets were made: a group is left out of the document while all of
#: its fields hold their defaults (written together otherwise), so the config documents (and job keys) of datasets
#: made before them stay as they were.
LATER_MATCH_GROUPS = (("sharpness_strength", "sharpness_sigma_px"),
                      ("contrast_strength", "contrast_gain", "saturation_strength", "saturation_gain"))
LATER_MATCH_FIELDS = tuple(name for group in LATER_MATCH_GROUPS for name in group)


def _match_document(match: MatchSettings) -> dict:
    out = {name: list(value) if isinstance(value, tuple) else value for name, value in asdict(match).items()}
    for group in LATER_MATCH_GROUPS:
        if all(getattr(match, name) == getattr(MatchSettings, name) for name in group):
            for name in group:
                del out[name]
    return out


def _light(doc) -> Light | None:
    return None if doc is None else Light(float(doc["overcast"]), float(doc.get("sun_elevation_deg", 45.0)),
                                          float(doc.get("sun_azimuth_deg", 0.0)))


def _camera_fields(doc: dict) -> dict[str, Any]:
    """A (partial) ``camera`` object of the schema as :class:`CameraSettings` keyword arguments."""
    out: dict[str, Any] = {}
    for key, value in doc.items():
        if key in ("horizon_row_share", "height_m", "focal_width_share"):
            out[key] = (value, value) if isinstance(value, (int, float)) else tuple(value)
        elif key == "light":
            out[key] = _light(value)
        else:
            out[key] = value
    return out


def _tuples(part: dict) -> dict[str, Any]:
    """A schema object as dataclass keyword arguments: its lists (ranges, choices) as tuples."""
    return {key: tuple(value) if isinstance(value, list) else value for key, value in part.items()}


def _build(doc: dict) -> CompositeConfig:
    defaults = CompositeConfig()
    output = doc.get("output", {"width": DEFAULT_OUTPUT[0], "height": DEFAULT_OUTPUT[1]})
    pastes = dict(doc.get("pastes", {}))
    for key in ("per_image", "height_share"):
        if key in pastes:
            pastes[key] = tuple(pastes[key])
    labels = doc.get("background_labels", {})
    qa = doc.get("qa", {})
    effects = _tuples(doc.get("effects", {}))
    folders = doc.get("folders", {})
    for folder, part in folders.items():  # each folder's fields checked as a camera of their own
        try:
            CameraSettings(**_camera_fields({**CameraSettings().to_document(), **part}))
        except InputError as exc:
            raise InputError(str(exc).replace("camera.", f"folders.{folder.strip('/')}.", 1)) from None
    return CompositeConfig(
        name=doc.get("name", defaults.name), seed=doc.get("seed", defaults.seed),
        images_per_background=doc.get("images_per_background", defaults.images_per_background),
        max_images=doc.get("max_images"),
        output=None if output is None else (output["width"], output["height"]),
        camera=CameraSettings(**_camera_fields(doc.get("camera", {}))),
        folders=tuple(sorted((f.strip("/"), dict(part)) for f, part in folders.items())),
        pastes=PasteSettings(**pastes),
        blend=BlendSettings(**_tuples(doc.get("blend", {}))),
        shadow_strength=tuple(doc.get("shadow", {}).get("strength", defaults.shadow_strength)),
        match=MatchSettings(**_tuples(doc.get("match", {}))),
        sharpen=SharpenSettings(**_tuples(doc.get("sharpen", {}))),
        effects=EffectsRandomisation(**effects),
        background_labels=BackgroundLabels(tuple(sorted(labels.get("classes", {}).items())),
                                           labels.get("drop_covered_share", 0.5),
                                           labels.get("drop_cropped_share", 0.5)),
        convention=doc.get("convention", defaults.convention),
        split=SplitRatios(**doc.get("split", {})),
        qa=QAThresholds(**{**qa, "reject": tuple(qa.get("reject", ()))}),
        min_instance_px=doc.get("min_instance_px", defaults.min_instance_px), workers=doc.get("workers"))
