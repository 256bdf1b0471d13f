"""What a cut-out bank draws (``synthua cutouts``): the config (``schemas/cutouts.schema.json``) as checked,
frozen plain data, and the draws of its groups and views.

A bank is ``count`` cut-outs: ``ceil(count / views_per_group)`` groups, each an aid user (with probability
``people.aid_user_share``: the aid by ``people.aids``' weights, pushed by a companion or accompanied by one or two
with the shares given, else alone) or a pedestrian, dressed as a randomised crowd is (the ``randomise`` block's
looks, hair and devices); each group seen ``views_per_group`` times: a camera at a height and ground distance
drawn from ``camera`` (uniform), at any angle around the group, a condition of ``conditions`` with its sun drawn
X
``stream(seed, g, "view", v)``: a bank of more cut-outs starts with the same ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.schemas import validate_document
from synthua_usd.model.render_config import takes_exactly
from synthua_usd.randomisation.config import AID_CLASSES, RandomisationConfig, _range
from synthua_usd.randomisation.streams import stream

Range = tuple[float, float]
#: The conditions a cut-out's light can come from: those with daylight (night needs the street's lamps, which a
#: studio has not) and without image-space weather that a photo would have to share.
CUTOUT_CONDITIONS = ("clear_day", "sunset", "day_fog")


@dataclass(frozen=True)
class FrameSettings:
    """The rendered frame of each view: ``width`` x ``height`` pixels, ``spp`` samples (a count Mitsuba's
    multi-jittered sampler takes exactly), denoised or not, path length ``max_depth``; the group fills ``fill``
    (a range) of the frame's height or width, whichever it reaches first."""

    width: int = 384
    height: int = 512
    spp: int = 16
    denoise: bool = True
    max_depth: int = 6
    fill: Range = (0.6, 0.85)

    def __post_init__(self) -> None:
        for name, low, high in (("width", 32, 4096), ("height", 32, 4096), ("spp", 1, 1024), ("max_depth", 2, 16)):
            value = getattr(self, name)
            if not isinstance(value, int) or not low <= value <= high:
                raise InputError(f"frame.{name}: {value!r}; expected an integer in {low}..{high}")
        if not takes_exactly(self.spp):
            raise InputError(f"frame.spp: {self.spp}; expected a count the multi-jittered sampler takes as it is "
                             f"(1, 2, 3, 4, 6, 8, 9, 12, 16, 20, 25, 30, 36, ...)")
        object.__setattr__(self, "fill", _range("frame.fill", self.fill, 0.1, 0.95))


@dataclass(frozen=True)
class PeopleSettings:
    """Who a group is: an aid user with probability ``aid_user_share`` (its aid drawn by the weights of
    ``aids``), pushed (manual wheelchairs) with probability ``pushed_share``, else accompanied with probability
    ``accompanied_share``; else a pedestrian."""

    aid_user_share: float = 0.8
    aids: dict = field(default_factory=lambda: {"manual_wheelchair": 3.0, "electric_wheelchair": 2.0, "walker": 1.0,
                                                "crutch": 1.0, "smart_cane": 0.5, "wooden_cane": 0.5,
                                                "orthopedic_cane": 0.5, "tripod_cane": 0.5})
    pushed_share: float = 0.3
    accompanied_share: float = 0.2

    def __post_init__(self) -> None:
        for name in ("aid_user_share", "pushed_share", "accompanied_share"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and 0.0 <= value <= 1.0):
                raise InputError(f"people.{name}: {value!r}; expected a share in [0, 1]")
        unknown = [a for a in self.aids if a not in AID_CLASSES]
        if unknown or not self.aids or any(not (isinstance(w, (int, float)) and w >= 0) for w in self.aids.values()) \
                or sum(self.aids.values()) <= 0:
            raise InputError(f"people.aids: {echo(str(self.aids))}; expected weights >= 0 (not all 0) of aid classes "
                             f"among {', '.join(AID_CLASSES)}")


@dataclass(frozen=True)
class CameraSettings:
    """Where each view's camera stands: ``height_m`` above the group's ground and ``distance_m`` from the group
    on the ground (uniform in each range), at any angle around it, aimed at the group's middle."""

    height_m: Range = (0.8, 6.0)
    distance_m: Range = (2.5, 12.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "height_m", _range("camera.height_m", self.height_m, 0.3, 30.0))
        object.__setattr__(self, "distance_m", _range("camera.distance_m", self.distance_m, 1.0, 100.0))


@dataclass(frozen=True)
class CutoutsConfig:
    """A bank's config (see the module)."""

    name: str = "cutouts"
    count: int = 120
    seed: int = 0
    views_per_group: int = 4
    frame: FrameSettings = field(default_factory=FrameSettings)
    people: PeopleSettings = field(default_factory=PeopleSettings)
    camera: CameraSettings = field(default_factory=CameraSettings)
    conditions: tuple[str, ...] = CUTOUT_CONDITIONS
    randomise: RandomisationConfig = field(default_factory=RandomisationConfig)
    workers: int | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.count, int) or not 1 <= self.count <= 1_000_000:
            raise InputError(f"count: {self.count!r}; expected an integer in 1..1000000")
        if not isinstance(self.views_per_group, int) or not 1 <= self.views_per_group <= 64:
            raise InputError(f"views_per_group: {self.views_per_group!r}; expected an integer in 1..64")
        unknown = [c for c in self.conditions if c not in CUTOUT_CONDITIONS]
        if unknown or not self.conditions:
            raise InputError(f"conditions: {', '.join(map(echo, unknown)) or 'none'}; expected one or more of "
                             f"{', '.join(CUTOUT_CONDITIONS)}")

    @property
    def groups(self) -> int:
        return math.ceil(self.count / self.views_per_group)

    @classmethod
    def from_document(cls, doc: dict, source: str = "cutouts config") -> "CutoutsConfig":
        """From a document ``schemas/cutouts.schema.json`` accepts (checked here)."""
        validate_document(doc, "cutouts", source)
        parts = {}
        for name, kind in (("frame", FrameSettings), ("people", PeopleSettings), ("camera", CameraSettings)):
            values = {k: tuple(v) if isinstance(v, list) else v for k, v in doc.get(name, {}).items()}
            try:
                parts[name] = kind(**values)
            except InputError as exc:
                raise InputError(f"{source}: {exc}") from None
        try:
            randomise = RandomisationConfig.from_document(doc.get("randomise", {}), source=f"{source}: randomise")
            return cls(name=doc.get("name", "cutouts"), count=doc.get("count", 120), seed=doc.get("seed", 0),
                       views_per_group=doc.get("views_per_group", 4), conditions=tuple(doc.get("conditions",
                                                                                              CUTOUT_CONDITIONS)),
                       randomise=randomise, workers=doc.get("workers"), **parts)
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None

    @classmethod
    def load(cls, path) -> "CutoutsConfig":
        from synthua_usd.core.schemas import read_json

        return cls.from_document(read_json(path, "a cut-out bank config"), source=str(path))

    def to_document(self) -> dict:
        from dataclasses import asdict

        def plain(value):
            return list(value) if isinstance(value, tuple) else value

        return {"name": self.name, "count": self.count, "seed": self.seed, "views_per_group": self.views_per_group,
                "frame": {k: plain(v) for k, v in asdict(self.frame).items()},
                "people": {k: plain(v) for k, v in asdict(self.people).items()},
                "camera": {k: plain(v) for k, v in asdict(self.camera).items()},
                "conditions": list(self.conditions), "randomise": self.randomise.to_document(),
                "workers": self.workers}


@dataclass(frozen=True)
class GroupDraw:
    """What group ``index`` is: a pedestrian (``aid`` None) or a user of ``aid``, ``group`` one of
    :data:`UNIT_GROUPS`, facing ``heading_deg``."""

    index: int
    aid: str | None
    group: str
    heading_deg: float


@dataclass(frozen=True)
class CutoutView:
    """View ``index`` of a group: the camera's ``height_m`` and ground ``distance_m``, its ``azimuth_deg`` around
    the group (0: in front of it, 90: on its left), the group's ``fill`` of the frame, the ``condition`` name."""

    index: int
    height_m: float
    distance_m: float
    azimuth_deg: float
    fill: float
    condition: str


def draw_group(config: CutoutsConfig, index: int) -> tuple[GroupDraw, np.random.Generator]:
    """Group ``index``'s kind, and the generator its people are drawn from next."""
    rng = stream(config.seed, index, "cutout_group")
    people = config.people
    aid, group = None, "alone"
    if rng.random() < people.aid_user_share:
        names = sorted(people.aids)
        weights = np.array([people.aids[n] for n in names], float)
        aid = names[int(rng.choice(len(names), p=weights / weights.sum()))]
        u = rng.random()
        if aid == "manual_wheelchair" and u < people.pushed_share:
            group = "pushed"
        elif rng.random() < people.accompanied_share:
            group = "accompanied"
    heading = float(rng.uniform(0.0, 360.0))
    return GroupDraw(index, aid, group, heading), rng


def draw_view(config: CutoutsConfig, group: int, index: int) -> tuple[CutoutView, np.random.Generator]:
    """View ``index`` of group ``group``, and the generator its light is drawn from next."""
    rng = stream(config.seed, group, "cutout_view", str(index))
    camera = config.camera
    view = CutoutView(index=index, height_m=float(rng.uniform(*camera.height_m)),
                      distance_m=float(rng.uniform(*camera.distance_m)), azimuth_deg=float(rng.uniform(0.0, 360.0)),
                      fill=float(rng.uniform(*config.frame.fill)),
                      condition=config.conditions[int(rng.integers(len(config.conditions)))])
    return view, rng
