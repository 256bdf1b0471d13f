"""Camera rigs as plain data: the kinds of viewpoint the paper varies, their physical ranges and lenses,
and one rig request (:class:`RigSpec`) as a user writes it: ``cctv:aim=aid_user,height_m=6``.

Heights are metres above the ground under the camera (for a rig riding with an agent: above the agent's
feet). Lens values are millimetres; a rig's focal length left unset is chosen by placement within its
lens's range (the zoom a varifocal CCTV, a UAV camera or a person's camera has), so that the target fills
the frame without leaving it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from synthua_usd.core.errors import InputError, echo
from synthua_usd.model.distortion import COEFFICIENTS, BrownConrady


@dataclass(frozen=True)
class Lens:
    """A camera body and lens: filmback (mm) and the focal lengths (mm) it can take."""

    horizontal_aperture_mm: float
    vertical_aperture_mm: float
    focal_range_mm: tuple[float, float]
    default_focal_mm: float
    doc: str


@dataclass(frozen=True)
class RigType:
    """One kind of rig. ``options`` are the :class:`RigSpec` fields that apply to it beyond the common ones."""

    name: str
    prefix: str
    height_range_m: tuple[float, float]
    default_height_m: float
    lens: Lens
    default_aim: str
    options: frozenset[str]
    doc: str


CCTV_LENS = Lens(4.8, 3.6, (2.8, 12.0), 2.8, '1/3" sensor (4.8 x 3.6 mm), 2.8-12 mm varifocal lens')
DASHCAM_LENS = Lens(5.6, 3.15, (2.8, 4.0), 3.0, '1/2.8" 16:9 sensor (5.6 x 3.15 mm), 3 mm wide-angle lens')
UAV_LENS = Lens(13.2, 8.8, (8.8, 26.0), 8.8, '1" sensor (13.2 x 8.8 mm), 8.8 mm (84 degrees across the diagonal, '
                                             'the survey camera) zooming to 26 mm')
EYE_LENS = Lens(36.0, 24.0, (24.0, 50.0), 24.0, "full-frame 36 x 24 mm, 24-50 mm")

RIG_TYPES: dict[str, RigType] = {t.name: t for t in (
    RigType("cctv", "CCTV", (3.0, 8.0), 6.0, CCTV_LENS, "aid_user", frozenset({"mount", "distance_m"}),
            "CCTV on a pole or a façade, 3-8 m up, looking down at a sidewalk, crossing or square"),
    RigType("dashcam", "Dashcam", (1.2, 1.5), 1.35, DASHCAM_LENS, "none", frozenset({"speed_kmh", "pitch_deg"}),
            "vehicle dashcam, 1.2-1.5 m up, driving along the centre of the road graph over the animation"),
    RigType("uav_nadir", "UAVNadir", (20.0, 120.0), 40.0, UAV_LENS, "aid_user", frozenset(),
            "UAV 20-120 m above the ground, looking straight down (image top = +Y)"),
    RigType("uav_oblique", "UAVOblique", (20.0, 120.0), 40.0, UAV_LENS, "aid_user", frozenset({"tilt_deg"}),
            "UAV 20-120 m above the ground, looking down at tilt_deg off nadir"),
    RigType("pedestrian_eye", "PedestrianEye", (1.45, 1.75), 1.6, EYE_LENS, "aid_user",
            frozenset({"ride", "distance_m", "pitch_deg"}),
            "a standing pedestrian's eye level (about 1.6 m), standing or riding with a walking agent"),
    RigType("wheelchair_eye", "WheelchairEye", (1.05, 1.35), 1.2, EYE_LENS, "aid_user",
            frozenset({"ride", "distance_m", "pitch_deg"}),
            "a seated wheelchair user's eye level (about 1.2 m), standing still or riding with a wheelchair user"),
)}

#: What a rig may aim at besides a prim path: every aid user, the users of one device class, crossings,
#: curb ramps, or nothing in particular.
AIM_KINDS = ("aid_user", "crossing", "curb_ramp", "none")
CCTV_MOUNTS = ("any", "pole", "facade")
MAX_COUNT = 20

_COMMON = frozenset({"type", "name", "height_m", "aim", "count", "focal_length_mm", "horizontal_aperture_mm",
                     "vertical_aperture_mm", *COEFFICIENTS})
_RANGES = {"speed_kmh": (1.0, 130.0), "tilt_deg": (15.0, 75.0), "pitch_deg": (-45.0, 20.0), "distance_m": (2.0, 200.0),
           "focal_length_mm": (1.0, 2000.0), "horizontal_aperture_mm": (1.0, 100.0), "vertical_aperture_mm": (1.0, 100.0)}


@dataclass(frozen=True)
class RigSpec:
    """One rig request; ``count`` cameras are placed from it, each on a different target.

    Attributes
    ----------
    type : str
        A key of :data:`RIG_TYPES`.
    name : str or None
        Camera prim name (``_<n>`` is appended when ``count`` > 1); default ``<Prefix>_<Aim>_<n>``.
    height_m : float or None
        Above the ground under the camera, within the type's range; default the type's.
    aim : str or None
        ``aid_user``, a mobility-aid class (``electric_wheelchair``, ``walker``, ...), ``crossing``,
        ``curb_ramp``, ``none`` or a prim path (an agent or a labelled prim); default the type's.
    ride : str or None
        Eye-level rigs: ``auto`` (the agent of the right kind that sees the target best) or an agent's prim
        path to ride with; unset stands still.
    focal_length_mm, horizontal_aperture_mm, vertical_aperture_mm : float or None
        Lens; unset aperture is the type's, unset focal length is chosen by placement (a fixed default for
        dashcams and riding cameras).
    k1, k2, k3, p1, p2 : float
        Brown–Conrady distortion (OpenCV's convention); all zero is an ideal pinhole.
    mount : str
        CCTV: ``pole`` (on a sidewalk or grass), ``facade`` (beside a building) or ``any``.
    distance_m : float or None
        CCTV and standing eye level: the farthest horizontal distance from the target to try.
    speed_kmh, pitch_deg, tilt_deg : float
        Dashcam speed; dashcam and riding pitch (negative looks down); UAV oblique angle off nadir.
    """

    type: str
    name: str | None = None
    height_m: float | None = None
    aim: str | None = None
    count: int = 1
    ride: str | None = None
    focal_length_mm: float | None = None
    horizontal_aperture_mm: float | None = None
    vertical_aperture_mm: float | None = None
    k1: float = 0.0
    k2: float = 0.0
    k3: float = 0.0
    p1: float = 0.0
    p2: float = 0.0
    mount: str = "any"
    distance_m: float | None = None
    speed_kmh: float = 30.0
    pitch_deg: float | None = None
    tilt_deg: float = 45.0

    def __post_init__(self) -> None:
        where = f"rig '{self.type}'"
        if self.type not in RIG_TYPES:
            raise InputError(f"rig type {echo(self.type)!r} is unknown; expected one of {', '.join(RIG_TYPES)}")
        kind = RIG_TYPES[self.type]
        lo, hi = kind.height_range_m
        height = kind.default_height_m if self.height_m is None else self.height_m
        if not (_finite(height) and lo <= height <= hi):
            raise InputError(f"{where}: height_m = {height!r}; expected {lo:g}-{hi:g} m for a {kind.doc}")
        object.__setattr__(self, "height_m", float(height))
        object.__setattr__(self, "aim", self.aim if self.aim is not None else kind.default_aim)
        if self.aim not in AIM_KINDS and not self.aim.startswith("/") and self.aim not in _device_classes():
            raise InputError(f"{where}: aim = {echo(self.aim)!r}; expected {', '.join(AIM_KINDS)}, a mobility-aid "
                             f"class ({', '.join(_device_classes())}) or a prim path")
        if isinstance(self.count, bool) or not isinstance(self.count, int) or not 1 <= self.count <= MAX_COUNT:
            raise InputError(f"{where}: count = {self.count!r}; expected an integer 1-{MAX_COUNT}")
        if self.count > 1 and self.aim.startswith("/"):
            raise InputError(f"{where}: count = {self.count} with one target prim {echo(self.aim)}; expected count=1")
        if self.name is not None and not (self.name.isidentifier() and self.name.isascii()):
            raise InputError(f"{where}: name = {echo(self.name)!r}; expected a USD prim name (letters, digits, _)")
        for name, (low, high) in _RANGES.items():
            value = getattr(self, name)
            if value is not None and not (_finite(value) and low <= value <= high):
                raise InputError(f"{where}: {name} = {value!r}; expected {low:g}-{high:g}")
        if self.mount not in CCTV_MOUNTS:
            raise InputError(f"{where}: mount = {echo(self.mount)!r}; expected one of {', '.join(CCTV_MOUNTS)}")
        if self.ride is not None and self.ride != "auto" and not self.ride.startswith("/"):
            raise InputError(f"{where}: ride = {echo(self.ride)!r}; expected 'auto' or an agent's prim path")
        self.distortion  # checks the coefficients

    @property
    def kind(self) -> RigType:
        return RIG_TYPES[self.type]

    @property
    def distortion(self) -> BrownConrady:
        return BrownConrady(**{c: getattr(self, c) for c in COEFFICIENTS})

    @property
    def moving(self) -> bool:
        return self.type == "dashcam" or self.ride is not None

    @property
    def apertures_mm(self) -> tuple[float, float]:
        lens = self.kind.lens
        return (self.horizontal_aperture_mm or lens.horizontal_aperture_mm,
                self.vertical_aperture_mm or lens.vertical_aperture_mm)

    def check_lens(self, width: int, height: int, where: str) -> None:
        """Refuse distortion coefficients that cannot be inverted over a W×H image at the widest field the
        rig may get (its focal length, else the shortest of its lens's range)."""
        if self.distortion.is_zero:
            return
        from synthua_usd.model.cameras import PinholeCamera

        focal = self.focal_length_mm or self.kind.lens.focal_range_mm[0]
        h_ap, v_ap = self.apertures_mm
        probe = PinholeCamera(where, focal, h_ap, v_ap, 0.1, 10.0, np.eye(4), self.distortion)
        probe.check_distortion(width, height)

    def aim_label(self) -> str:
        """``AidUser``, ``ElectricWheelchair``, ``Crossing``, the last name of a prim path, or '' for none."""
        if self.aim == "none":
            return ""
        if self.aim.startswith("/"):
            return self.aim.rstrip("/").rsplit("/", 1)[-1]
        return "".join(part.title() for part in self.aim.split("_"))

    @classmethod
    def from_dict(cls, data: dict, source: str = "rig") -> "RigSpec":
        """From ``{"type": ..., key: value}``; keys that are not fields, or do not apply to the type, are
        refused with the ones that do."""
        kind = RIG_TYPES.get(data.get("type"))
        if kind is None:
            raise InputError(f"{source}: rig type {echo(data.get('type'))!r} is unknown; expected one of "
                             f"{', '.join(RIG_TYPES)}")
        allowed = _COMMON | kind.options
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise InputError(f"{source}: {', '.join(map(echo, unknown))} do(es) not apply to a {kind.name} rig; "
                             f"expected keys among {', '.join(sorted(allowed - {'type'}))}")
        return cls(**data)

    @classmethod
    def parse(cls, text: str) -> "RigSpec":
        """``TYPE`` or ``TYPE:key=value,key=value`` (e.g. ``cctv:aim=electric_wheelchair,height_m=5``)."""
        source = f"--rig {echo(text)!r}"
        kind, _, rest = text.partition(":")
        data: dict = {"type": kind.strip()}
        types = {f.name: f.type for f in fields(cls)}
        for item in filter(None, (part.strip() for part in rest.split(","))):
            key, eq, value = item.partition("=")
            key, value = key.strip(), value.strip()
            if not eq or not key or not value:
                raise InputError(f"{source}: {echo(item)!r} is not key=value; expected e.g. cctv:aim=aid_user,height_m=6")
            if key in data:
                raise InputError(f"{source}: {echo(key)} is given twice; expected each key once")
            data[key] = _convert(source, key, value, types.get(key, "str"))
        return cls.from_dict(data, source)


@dataclass(frozen=True)
class AimedRigs:
    """Rigs to place in a scenario when it is written (the demo district's aimed views), the minimum target
    size they must meet, the time codes their report covers, and the rig camera the render settings should
    use when it is placed."""

    rigs: tuple[RigSpec, ...]
    min_target_px: int
    time_codes: tuple[float, ...] = ()
    render_camera: str | None = None


def _convert(source: str, key: str, value: str, type_name: str):
    try:
        if type_name == "int":
            return int(value)
        if "float" in type_name:
            return float(value)
    except ValueError:
        expected = "an integer" if type_name == "int" else "a number"
        raise InputError(f"{source}: {key} = {echo(value)!r}; expected {expected}") from None
    return value


def _finite(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _device_classes() -> tuple[str, ...]:
    from synthua_usd.agents.profiles import PROFILES

    return tuple(sorted({p.device for p in PROFILES.values() if p.device}))


def describe_types() -> str:
    """A table of the rig types, their heights, lenses and options (for ``synthua cameras types``)."""
    lines = []
    for kind in RIG_TYPES.values():
        lo, hi = kind.height_range_m
        lines.append(f"{kind.name:15s} {lo:g}-{hi:g} m (default {kind.default_height_m:g}): {kind.doc}")
        lines.append(f"{'':15s} lens: {kind.lens.doc}; default aim: {kind.default_aim}"
                     + (f"; options: {', '.join(sorted(kind.options))}" if kind.options else ""))
    return "\n".join(lines)
