"""What scene randomisation varies and within which ranges: the ``randomise`` block of a generation config
(``schemas/generate.schema.json``, ``$defs.randomise``) as checked, frozen plain data.

Every range is ``(low, high)`` with ``low <= high`` (equal ends fix the value). Each part has ``enabled``
(default true; ``district``, ``effects``, ``framing``, ``settings`` and ``distractors`` default false; the last two
are defined in :mod:`synthua_usd.randomisation.settings` and :mod:`synthua_usd.randomisation.distractors`), so a
part is switched off without deleting its ranges; a config without a ``randomise`` block (or with ``null``)
randomises nothing and renders the scenario as composed, as before. The meaning of
every field is documented once, in the schema's descriptions; the defaults are owned here and a test holds
the schema's documentation to them.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.schemas import unknown_key
from synthua_usd.assets.devices import DEVICE_MODELS
from synthua_usd.assets.hair import HAIR_STYLES
from synthua_usd.assets.look_images import LOWER_FABRICS, SHOES, UPPER_FABRICS
from synthua_usd.model.materials import DEVICE_FINISHES, HAIR_COLOURS, RECOLOUR_PALETTES, UPPER_PALETTES
from synthua_usd.model.ranges import SEED
from synthua_usd.randomisation.distractors import DistractorRandomisation
from synthua_usd.randomisation.settings import SettingsRandomisation

#: The mobility-aid classes a randomised crowd can use (the device classes of the agent profiles).
AID_CLASSES = ("manual_wheelchair", "electric_wheelchair", "walker", "crutch", "smart_cane", "wooden_cane",
               "orthopedic_cane", "tripod_cane")
#: Finishes a device frame can take.
DEVICE_FINISH_NAMES = tuple(DEVICE_FINISHES)
#: The models every aid class has (:data:`synthua_usd.assets.devices.DEVICE_MODELS`), in the order they are drawn.
DEVICE_MODEL_NAMES = tuple(sorted(set.intersection(*(set(m) for m in DEVICE_MODELS.values()))))
#: Twin classes whose objects can get their own variant of their material ("within its class": a building
#: keeps a façade colour, a car a car paint); all of them by default.
RECOLOURED_CLASSES = tuple(RECOLOUR_PALETTES)

Range = tuple[float, float]
#: Densest randomised crowd, persons/m² of walkable area: placing a crowd anew for every view keeps people
#: apart by rejection, which stays reliable up to about this (free walking ends near 0.7/m²).
MAX_DENSITY_PER_M2 = 0.3
#: Least share of the image's height an aid user placed in view may span (0.005: about 2 pixels of a 480-pixel
#: image); below it "in view" means nothing a detector or a label could use.
MIN_VIEW_HEIGHT_SHARE = 0.005


def low_high(name: str, value, lo: float | None = None, hi: float | None = None) -> Range:
    """``value`` (two numbers, low <= high) as a tuple, within [lo, hi] when given; an :class:`InputError` naming
    ``name`` otherwise (every part's ranges are checked by it)."""
    try:
        a, b = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InputError(f"{name}: {echo(str(value))}; expected [low, high], two numbers") from None
    if not (math.isfinite(a) and math.isfinite(b) and a <= b):
        raise InputError(f"{name}: [{a:g}, {b:g}]; expected two finite numbers with low <= high")
    if (lo is not None and a < lo) or (hi is not None and b > hi):
        raise InputError(f"{name}: [{a:g}, {b:g}]; expected a range within [{lo:g}, {hi:g}]")
    return a, b


_range = low_high  # the name other modules of the package import it by


def names_among(name: str, values, known) -> tuple[str, ...]:
    """``values`` as a tuple of distinct names, each one of ``known``; an :class:`InputError` naming ``name``
    (the field) lists what is expected otherwise."""
    values = tuple(values)
    unknown = [v for v in values if v not in known]
    if unknown or not values or len(set(values)) != len(values):
        raise InputError(f"{name}: {', '.join(map(echo, unknown or values)) or 'none'}; expected one or more distinct "
                         f"of {', '.join(known)}")
    return values


@dataclass(frozen=True)
class CrowdRandomisation:
    """A new crowd per scene (who: density, aid share, which aids, bodies, clothes; manual wheelchair users
    pushed by a companion, aid users accompanied by companions) placed anew per view (where: position, heading,
    gait phase on the walkable surfaces; some aid users where the camera sees them at a projected height within
    ``view_height_share`` of the image's; companions behind or beside their aid user). Densities are persons per
    m² of walkable area."""

    enabled: bool = True
    density_per_m2: Range = (0.01, 0.05)
    aid_share: Range = (0.2, 0.5)
    aids: tuple[str, ...] = AID_CLASSES
    aid_users_in_view: Range = (1, 3)
    view_height_share: Range = (0.03, 0.6)
    seated_share: Range = (0.0, 0.1)
    group_share: Range = (0.1, 0.4)
    pushed_share: Range = (0.2, 0.5)
    accompanied_share: Range = (0.1, 0.4)
    clothing_jitter: float = 0.15

    def __post_init__(self) -> None:
        object.__setattr__(self, "density_per_m2", low_high("crowd.density_per_m2", self.density_per_m2, 0.0,
                                                                  MAX_DENSITY_PER_M2))
        if self.density_per_m2[0] <= 0:
            raise InputError(f"crowd.density_per_m2: [{self.density_per_m2[0]:g}, {self.density_per_m2[1]:g}]; "
                             f"expected a low end > 0 persons/m²")
        for name in ("aid_share", "seated_share", "group_share", "pushed_share", "accompanied_share"):
            object.__setattr__(self, name, low_high(f"crowd.{name}", getattr(self, name), 0.0, 1.0))
        users = low_high("crowd.aid_users_in_view", self.aid_users_in_view, 0, 50)
        if not all(float(v).is_integer() for v in users):
            raise InputError(f"crowd.aid_users_in_view: {list(users)}; expected two whole numbers")
        object.__setattr__(self, "aid_users_in_view", (int(users[0]), int(users[1])))
        object.__setattr__(self, "view_height_share", low_high("crowd.view_height_share", self.view_height_share, 0.0, 10.0))
        if self.view_height_share[0] < MIN_VIEW_HEIGHT_SHARE:
            # a share of 0 asks for aid users of no height in the image: placed out of view, silently
            raise InputError(f"crowd.view_height_share: [{self.view_height_share[0]:g}, {self.view_height_share[1]:g}]; "
                             f"expected a low end of at least {MIN_VIEW_HEIGHT_SHARE:g} (a share of the image's "
                             f"height an aid user in view spans)")
        aids = tuple(self.aids)
        unknown = [a for a in aids if a not in AID_CLASSES]
        if unknown or not aids:
            raise InputError(f"crowd.aids: {', '.join(map(echo, unknown)) or 'none'}; expected one or more of "
                             f"{', '.join(AID_CLASSES)}")
        object.__setattr__(self, "aids", aids)
        if not (math.isfinite(self.clothing_jitter) and 0 <= self.clothing_jitter <= 1):
            raise InputError(f"crowd.clothing_jitter: {self.clothing_jitter!r}; expected a number in [0, 1]")


@dataclass(frozen=True)
class DeviceRandomisation:
    """Each aid user's device: a model among ``models`` of those its type has (standard low-poly, detailed), a
    frame finish and colour, a seat or grip fabric colour."""

    enabled: bool = True
    finishes: tuple[str, ...] = DEVICE_FINISH_NAMES
    models: tuple[str, ...] = DEVICE_MODEL_NAMES

    def __post_init__(self) -> None:
        for name, known in (("finishes", DEVICE_FINISH_NAMES), ("models", DEVICE_MODEL_NAMES)):
            chosen = tuple(getattr(self, name))
            unknown = [f for f in chosen if f not in known]
            if unknown or not chosen:
                raise InputError(f"devices.{name}: {', '.join(map(echo, unknown)) or 'none'}; expected one or more of "
                                 f"{', '.join(known)}")
            # models in their drawing order (the order they are given in changes nothing drawn); finishes as given
            object.__setattr__(self, name, tuple(sorted(chosen)) if name == "models" else chosen)


@dataclass(frozen=True)
class HairRandomisation:
    """Each person's hair (with crowd on): a style among ``styles`` (``none`` is bald) and a colour among
    ``colours``; off, everyone is bald, as the body bank's bodies are."""

    enabled: bool = True
    styles: tuple[str, ...] = HAIR_STYLES
    colours: tuple[str, ...] = tuple(HAIR_COLOURS)

    def __post_init__(self) -> None:
        for name, known in (("styles", HAIR_STYLES), ("colours", tuple(HAIR_COLOURS))):
            values = tuple(getattr(self, name))
            unknown = [v for v in values if v not in known]
            if unknown or not values:
                raise InputError(f"hair.{name}: {', '.join(map(echo, unknown)) or 'none'}; expected one or more of "
                                 f"{', '.join(known)}")
            object.__setattr__(self, name, values)


@dataclass(frozen=True)
class LooksRandomisation:
    """How each person of the crowd (with crowd on) looks beyond colours: smooth shading (normals authored on
    the body's meshes), a fabric per garment among ``upper_fabrics`` and ``lower_fabrics`` (a pattern in a second
    colour, the weave and folds in a normal map; ``wardrobe`` upper and lower garments per scene, which its
    people pick from; upper garments in the colours of ``palette``), shoes among ``shoes`` on soles of another
    colour, a face (eyes, brows, nostrils, lips, cheeks as an image on the head) and skin with a clear coat, drawn
    from a stream of its own (switching it off or narrowing it moves no other draw); long sleeves and long legs with
    probabilities ``long_sleeves`` and ``long_legs``, one number each per person whatever they are. Off: flat-coloured garments and shoes, faceless matte
    skin, faceted bodies, long sleeves and legs with probability 0.6 each, as before."""

    enabled: bool = True
    upper_fabrics: tuple[str, ...] = UPPER_FABRICS
    lower_fabrics: tuple[str, ...] = LOWER_FABRICS
    shoes: tuple[str, ...] = SHOES
    wardrobe: int = 24
    palette: str = "bright"
    long_sleeves: float = 0.6
    long_legs: float = 0.6

    def __post_init__(self) -> None:
        if isinstance(self.wardrobe, bool) or not isinstance(self.wardrobe, int) or not 1 <= self.wardrobe <= 256:
            raise InputError(f"looks.wardrobe: {self.wardrobe!r}; expected a whole number of garments in [1, 256]")
        for name, known in (("upper_fabrics", UPPER_FABRICS), ("lower_fabrics", LOWER_FABRICS), ("shoes", SHOES)):
            values = tuple(getattr(self, name))
            unknown = [v for v in values if v not in known]
            if unknown or not values:
                raise InputError(f"looks.{name}: {', '.join(map(echo, unknown)) or 'none'}; expected one or more of "
                                 f"{', '.join(known)}")
            object.__setattr__(self, name, values)
        if not isinstance(self.palette, str) or self.palette not in UPPER_PALETTES:
            raise InputError(f"looks.palette: {echo(self.palette)}; expected one of {', '.join(UPPER_PALETTES)}")
        for name in ("long_sleeves", "long_legs"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
                raise InputError(f"looks.{name}: {value!r}; expected a probability in [0, 1]")


@dataclass(frozen=True)
class MaterialRandomisation:
    """Each twin object of ``classes`` gets its own variant of its main material: a colour from its class's
    palette (façades, car paints, canvas, ...) or, for a textured material, its texture tinted; ``value_jitter``
    scales brightness by up to ±that share."""

    enabled: bool = True
    classes: tuple[str, ...] = RECOLOURED_CLASSES
    value_jitter: float = 0.2

    def __post_init__(self) -> None:
        classes = tuple(self.classes)
        unknown = [c for c in classes if c not in RECOLOURED_CLASSES]
        if unknown:
            raise InputError(f"materials.classes: {', '.join(map(echo, unknown))}; expected among "
                             f"{', '.join(RECOLOURED_CLASSES)}")
        object.__setattr__(self, "classes", classes)
        if not (math.isfinite(self.value_jitter) and 0 <= self.value_jitter <= 0.9):
            raise InputError(f"materials.value_jitter: {self.value_jitter!r}; expected a number in [0, 0.9]")


@dataclass(frozen=True)
class LightRandomisation:
    """The light of each image within its condition: a date and a solar time at ``latitude_deg`` whose sun
    lies in the condition's elevation band, a turbidity offset, the night sky's luminance scaled, and an
    exposure compensation in EV."""

    enabled: bool = True
    latitude_deg: float = -25.43
    sun_band_deg: float = 25.0
    turbidity_offset: Range = (-1.0, 2.0)
    exposure_ev: Range = (-0.5, 0.5)
    night_sky_factor: Range = (0.5, 2.0)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.latitude_deg) and -66.0 <= self.latitude_deg <= 66.0):
            raise InputError(f"light.latitude_deg: {self.latitude_deg!r}; expected a latitude in [-66, 66] degrees "
                             f"(beyond the polar circles the sun may not rise or set)")
        if not (math.isfinite(self.sun_band_deg) and 0 <= self.sun_band_deg <= 90):
            raise InputError(f"light.sun_band_deg: {self.sun_band_deg!r}; expected degrees in [0, 90]")
        object.__setattr__(self, "turbidity_offset", low_high("light.turbidity_offset", self.turbidity_offset, -9.0, 9.0))
        object.__setattr__(self, "exposure_ev", low_high("light.exposure_ev", self.exposure_ev, -4.0, 4.0))
        object.__setattr__(self, "night_sky_factor", low_high("light.night_sky_factor", self.night_sky_factor, 0.01, 100.0))


@dataclass(frozen=True)
class CameraRandomisation:
    """Each view's camera moved within its rig type's envelope: height by up to ±``height_m`` (kept within
    the rig type's heights above the ground), yaw and pitch by up to ±degrees, focal length scaled within
    ``focal_length_factor`` (kept within the rig type's lens)."""

    enabled: bool = True
    height_m: float = 0.3
    yaw_deg: float = 5.0
    pitch_deg: float = 3.0
    focal_length_factor: Range = (0.9, 1.1)

    def __post_init__(self) -> None:
        for name, hi in (("height_m", 50.0), ("yaw_deg", 180.0), ("pitch_deg", 45.0)):
            value = getattr(self, name)
            if not (math.isfinite(value) and 0 <= value <= hi):
                raise InputError(f"camera.{name}: {value!r}; expected a number in [0, {hi:g}]")
        object.__setattr__(self, "focal_length_factor",
                           low_high("camera.focal_length_factor", self.focal_length_factor, 0.25, 4.0))


@dataclass(frozen=True)
class DistrictRandomisation:
    """Scenes drawn over procedural district seeds (``synthua create district --seed``): each scene's twin is
    the district of one of ``seeds``. Off by default; only for scenarios whose twin is the demo district."""

    enabled: bool = False
    seeds: tuple[int, ...] = (0, 1, 2, 3)

    def __post_init__(self) -> None:
        seeds = tuple(int(s) for s in self.seeds)
        if not seeds or not all(SEED.contains(s) for s in seeds) or len(set(seeds)) != len(seeds):
            raise InputError(f"district.seeds: {list(seeds)}; expected one or more distinct integers, each "
                             f"{str(SEED).removeprefix('an integer ')}")
        object.__setattr__(self, "seeds", seeds)


#: Camera effects' kinds, in the order :func:`synthua_usd.backends.camera_effects.apply_effects` applies them.
EFFECTS = ("defocus", "motion_blur", "vignetting", "exposure", "noise", "white_balance", "jpeg")


@dataclass(frozen=True)
class EffectsRandomisation:
    """Camera effects applied to each image after rendering (its labels untouched), each with the probability
    ``<effect>_probability`` per image, drawn from a stream of its own (off, or other ranges, move no scene draw):
    defocus (a thin lens focused at ``focus_m``, log-uniform, blurring a point at infinity to a disc of radius
    ``defocus_radius_width_share`` of the image width), linear motion blur (length ``motion_blur_length_width_share``
    of the width, any direction), vignetting (``vignetting_corner_loss`` of the light lost at the corners, the cos⁴
    law), exposure (``exposure_ev`` stops), sensor noise (shot noise of gain ``noise_shot_gain`` in linear units per
    photo-electron, Gaussian read noise ``noise_read_sigma``), white balance (red and blue gains within
    ``white_balance_gain``, green 1) and JPEG compression (quality within ``jpeg_quality``). Off by default: a config
    that does not ask for it renders as before."""

    enabled: bool = False
    defocus_probability: float = 0.3
    focus_m: Range = (1.5, 20.0)
    defocus_radius_width_share: Range = (0.0005, 0.003)
    motion_blur_probability: float = 0.3
    motion_blur_length_width_share: Range = (0.002, 0.008)
    vignetting_probability: float = 0.5
    vignetting_corner_loss: Range = (0.1, 0.4)
    exposure_probability: float = 1.0
    exposure_ev: Range = (-0.3, 0.3)
    noise_probability: float = 1.0
    noise_shot_gain: Range = (0.0001, 0.002)
    noise_read_sigma: Range = (0.0005, 0.004)
    white_balance_probability: float = 1.0
    white_balance_gain: Range = (0.9, 1.1)
    jpeg_probability: float = 0.5
    jpeg_quality: Range = (60, 95)

    def __post_init__(self) -> None:
        for effect in EFFECTS:
            p = getattr(self, f"{effect}_probability")
            if isinstance(p, bool) or not isinstance(p, (int, float)) or not (math.isfinite(p) and 0 <= p <= 1):
                raise InputError(f"effects.{effect}_probability: {p!r}; expected a probability in [0, 1]")
            object.__setattr__(self, f"{effect}_probability", float(p))
        for name, lo, hi in (("focus_m", 0.1, 10_000.0), ("defocus_radius_width_share", 0.0, 0.05),
                             ("motion_blur_length_width_share", 0.0, 0.1), ("vignetting_corner_loss", 0.0, 0.9),
                             ("exposure_ev", -4.0, 4.0), ("noise_shot_gain", 0.0, 0.1), ("noise_read_sigma", 0.0, 0.1),
                             ("white_balance_gain", 0.5, 2.0), ("jpeg_quality", 1.0, 100.0)):
            object.__setattr__(self, name, low_high(f"effects.{name}", getattr(self, name), lo, hi))
        if not all(float(q).is_integer() for q in self.jpeg_quality):
            raise InputError(f"effects.jpeg_quality: {[f'{q:g}' for q in self.jpeg_quality]}; expected two whole "
                             f"numbers in [1, 100]")
        object.__setattr__(self, "jpeg_quality", tuple(int(q) for q in self.jpeg_quality))


@dataclass(frozen=True)
class FramingRandomisation:
    """Views framed as photographers frame aid users, as well as the rigs' own: a share ``share`` of the views of
    cameras of ``rig_types`` is taken from ``distance_m`` of one of the aid users placed in view (on the ground),
    at an eye height (``eye_height_m``, or ``seated_height_m`` for the share ``seated_share``: a seated
    photographer, a wheelchair user's eye), aimed at the user, its focal length such that the user fills
    ``height_share`` of the frame height; from a stream of its own. Off by default: a config that does not ask for
    it renders as before."""

    enabled: bool = False
    share: float = 0.6
    rig_types: tuple[str, ...] = ("pedestrian_eye", "wheelchair_eye")
    distance_m: Range = (1.5, 8.0)
    eye_height_m: Range = (1.45, 1.75)
    seated_height_m: Range = (1.0, 1.3)
    seated_share: float = 0.3
    height_share: Range = (0.2, 0.9)

    def __post_init__(self) -> None:
        from synthua_usd.composition.rigs import RIG_TYPES

        for name in ("share", "seated_share"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
                raise InputError(f"framing.{name}: {value!r}; expected a share in [0, 1]")
        unknown = [r for r in self.rig_types if r not in RIG_TYPES]
        if unknown or not self.rig_types:
            raise InputError(f"framing.rig_types: {', '.join(map(echo, unknown)) or 'none'}; expected one or more of "
                             f"{', '.join(sorted(RIG_TYPES))}")
        for name, lo, hi in (("distance_m", 0.5, 50.0), ("eye_height_m", 0.3, 3.0), ("seated_height_m", 0.3, 3.0),
                             ("height_share", 0.02, 1.0)):
            object.__setattr__(self, name, low_high(f"framing.{name}", getattr(self, name), lo, hi))


_PARTS = {"crowd": CrowdRandomisation, "devices": DeviceRandomisation, "hair": HairRandomisation,
          "looks": LooksRandomisation, "materials": MaterialRandomisation,
          "light": LightRandomisation, "camera": CameraRandomisation, "district": DistrictRandomisation,
          "effects": EffectsRandomisation, "framing": FramingRandomisation, "settings": SettingsRandomisation,
          "distractors": DistractorRandomisation}
#: Parts that came after datasets were made: left out of a config's document while they are their default (off),
#: so that a config that does not ask for them keeps its generate.json and job key.
_LATER_PARTS = {"effects": EffectsRandomisation, "framing": FramingRandomisation, "settings": SettingsRandomisation,
                "distractors": DistractorRandomisation}
#: Fields of a part that came after datasets were made: left out of the document while they are their default.
_LATER_FIELDS = {"devices": {"models": DEVICE_MODEL_NAMES},
                 "looks": {"palette": "bright", "long_sleeves": 0.6, "long_legs": 0.6}}


@dataclass(frozen=True)
class RandomisationConfig:
    """Scene randomisation of a generation run. ``seed`` is mixed with each image's seed: images of one seed
    share a scene (crowd, looks, materials, district), and each (camera, time code) places it anew."""

    seed: int = 0
    crowd: CrowdRandomisation = field(default_factory=CrowdRandomisation)
    devices: DeviceRandomisation = field(default_factory=DeviceRandomisation)
    hair: HairRandomisation = field(default_factory=HairRandomisation)
    looks: LooksRandomisation = field(default_factory=LooksRandomisation)
    materials: MaterialRandomisation = field(default_factory=MaterialRandomisation)
    light: LightRandomisation = field(default_factory=LightRandomisation)
    camera: CameraRandomisation = field(default_factory=CameraRandomisation)
    district: DistrictRandomisation = field(default_factory=DistrictRandomisation)
    effects: EffectsRandomisation = field(default_factory=EffectsRandomisation)
    framing: FramingRandomisation = field(default_factory=FramingRandomisation)
    settings: SettingsRandomisation = field(default_factory=SettingsRandomisation)
    distractors: DistractorRandomisation = field(default_factory=DistractorRandomisation)

    def __post_init__(self) -> None:
        if self.devices.enabled and not self.crowd.enabled:
            # devices belong to the randomised crowd's aid users
            object.__setattr__(self, "devices", replace(self.devices, enabled=False))
        if self.hair.enabled and not self.crowd.enabled:  # hair belongs to the randomised crowd's people
            object.__setattr__(self, "hair", HairRandomisation(False, self.hair.styles, self.hair.colours))
        if self.looks.enabled and not self.crowd.enabled:  # so do looks
            object.__setattr__(self, "looks", replace(self.looks, enabled=False))
        if self.district.enabled and not self.crowd.enabled:
            raise InputError("randomise.district: enabled while randomise.crowd is not; expected the crowd randomised "
                             "too (the scenario's own crowd walks the routes of its own district)")
        if self.settings.enabled and not self.crowd.enabled:
            raise InputError("randomise.settings: enabled while randomise.crowd is not; expected the crowd randomised "
                             "too (a procedural setting has no crowd of its own)")

    @classmethod
    def from_document(cls, doc: dict | None, source: str = "randomise") -> "RandomisationConfig | None":
        """From a schema-valid ``randomise`` block; None (no block) is None (no randomisation)."""
        if doc is None:
            return None
        parts = {}
        for name, kind in _PARTS.items():
            values = dict(doc.get(name, {}))
            known = {f.name for f in fields(kind)}
            unknown = sorted(set(values) - known)
            if unknown:
                raise InputError(unknown_key(f"{source}.{name}", unknown[0], known))
            for key, value in values.items():
                if isinstance(value, list):
                    values[key] = tuple(value)
            try:
                parts[name] = kind(**values)
            except InputError as exc:
                raise InputError(f"{source}.{exc}") from None
        return cls(seed=int(doc.get("seed", 0)), **parts)

    def to_document(self) -> dict:
        """Every value explicit (as ``generate.json`` records it), but the parts of :data:`_LATER_PARTS` that are
        their default (off, default ranges), which are left out; ``from_document(to_document())`` is equal."""
        out: dict[str, Any] = {"seed": self.seed}
        for name in _PARTS:
            if name in _LATER_PARTS and getattr(self, name) == _LATER_PARTS[name]():
                # left out as before the part existed: a config that does not ask for it keeps its generate.json
                # and job key (and with them resumption of datasets written before)
                continue
            part = {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(getattr(self, name)).items()}
            for key, default in _LATER_FIELDS.get(name, {}).items():
                if part[key] == (list(default) if isinstance(default, tuple) else default):
                    del part[key]          # as before the field existed, for the same reason
            out[name] = part
        return out

    @property
    def enabled_parts(self) -> tuple[str, ...]:
        """Names of the parts that vary something."""
        return tuple(name for name in _PARTS if getattr(self, name).enabled)
