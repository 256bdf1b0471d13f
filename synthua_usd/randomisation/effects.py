"""The camera effects of one image as plain data: :func:`draw_effects` draws them under an
:class:`~synthua_usd.randomisation.config.EffectsRandomisation`, and :class:`EffectsDraw` is the draw, recorded
as ``randomisation.effects`` of an image record (``schemas/record.schema.json``). The image operations that apply
a draw to an 8-bit RGB image are :mod:`synthua_usd.backends.camera_effects`; what each value means is documented
there, once.

Each effect is drawn from a child stream of its own (:meth:`numpy.random.Generator.spawn`, in the order of
:data:`~synthua_usd.randomisation.config.EFFECTS`): first whether it applies (its probability), then its values.
So another probability or range of one effect moves no other effect's draw.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

import numpy as np

from synthua_usd.core.errors import InputError, echo
from synthua_usd.randomisation.config import EFFECTS, EffectsRandomisation, RandomisationConfig
from synthua_usd.randomisation.streams import stream


@dataclass(frozen=True)
class Defocus:
    """A thin lens focused at ``focus_m`` (metres of z-depth): a point at infinity blurs to a disc of radius
    ``radius_width_share`` x the image width, in pixels."""

    focus_m: float
    radius_width_share: float


@dataclass(frozen=True)
class MotionBlur:
    """The camera moving straight during the exposure: a line ``length_width_share`` x the image width long, in
    pixels, at ``angle_deg`` from the image's +x axis towards +y (down), in [0, 180)."""

    length_width_share: float
    angle_deg: float


@dataclass(frozen=True)
class Vignetting:
    """``corner_loss``: the share of light lost at the image's corners (the cos⁴ law)."""

    corner_loss: float


@dataclass(frozen=True)
class Exposure:
    """``ev``: stops of exposure added (negative: darker)."""

    ev: float


@dataclass(frozen=True)
class Noise:
    """Shot noise of ``shot_gain`` (linear value per photo-electron) and Gaussian read noise of standard deviation
    ``read_sigma`` (linear); ``seed`` seeds the noise field."""

    shot_gain: float
    read_sigma: float
    seed: int


@dataclass(frozen=True)
class WhiteBalance:
    """Gains of the red and blue channels (linear; green 1)."""

    red_gain: float
    blue_gain: float


@dataclass(frozen=True)
class Jpeg:
    """JPEG compression at ``quality`` (Pillow's scale, 1-100)."""

    quality: int


#: Each effect's values, in :data:`EFFECTS` order (one order: the config's, the draw's and the application's).
KINDS = {"defocus": Defocus, "motion_blur": MotionBlur, "vignetting": Vignetting, "exposure": Exposure,
         "noise": Noise, "white_balance": WhiteBalance, "jpeg": Jpeg}


@dataclass(frozen=True)
class EffectsDraw:
    """The camera effects of one image: each None when not applied."""

    defocus: Defocus | None = None
    motion_blur: MotionBlur | None = None
    vignetting: Vignetting | None = None
    exposure: Exposure | None = None
    noise: Noise | None = None
    white_balance: WhiteBalance | None = None
    jpeg: Jpeg | None = None

    @property
    def applied(self) -> tuple[str, ...]:
        """Names of the effects applied, in the order they are applied."""
        return tuple(name for name in EFFECTS if getattr(self, name) is not None)

    def to_dict(self) -> dict:
        """Every effect by name: its values, or None (as an image record holds it)."""
        return {name: None if getattr(self, name) is None else asdict(getattr(self, name)) for name in EFFECTS}

    @classmethod
    def from_dict(cls, doc: dict, source: str = "effects") -> "EffectsDraw":
        """The draw of :meth:`to_dict`'s dict; unknown or missing keys and values that are not numbers raise
        :class:`InputError` naming ``source``."""
        if not isinstance(doc, dict):
            raise InputError(f"{source}: {echo(str(doc))}; expected an object with {', '.join(EFFECTS)}")
        unknown = sorted(set(doc) - set(EFFECTS))
        if unknown:
            raise InputError(f"{source}: unknown keys {unknown}; expected among {list(EFFECTS)}")
        out = {}
        for name, kind in KINDS.items():
            values = doc.get(name)
            if values is None:
                continue
            names = [f.name for f in fields(kind)]
            if not isinstance(values, dict) or sorted(values) != sorted(names):
                raise InputError(f"{source}.{name}: {echo(str(values))}; expected null or an object with "
                                 f"{', '.join(names)}")
            number = {f.name: (int if f.type == "int" else float) for f in fields(kind)}
            try:
                parsed = {k: number[k](v) for k, v in values.items() if not isinstance(v, bool)}
            except (TypeError, ValueError):
                parsed = {}
            if len(parsed) != len(names) or not all(math.isfinite(v) for v in parsed.values()):
                raise InputError(f"{source}.{name}: {echo(str(values))}; expected finite numbers")
            out[name] = kind(**parsed)
        return cls(**out)


def _uniform(rng: np.random.Generator, bounds: tuple[float, float]) -> float:
    return float(rng.uniform(*bounds))


def draw_effects(rng: np.random.Generator, config: EffectsRandomisation) -> EffectsDraw:
    """The camera effects of one image under ``config``, drawn from child streams of ``rng`` (one per effect,
    spawned whether or not the effect is on, so that ``config.enabled`` aside nothing here depends on another
    effect's settings). ``config.enabled`` is not looked at: the caller decides whether effects are drawn."""
    children = dict(zip(EFFECTS, rng.spawn(len(EFFECTS))))

    def applies(name: str) -> np.random.Generator | None:
        child = children[name]
        return child if child.random() < getattr(config, f"{name}_probability") else None

    out = {}
    if (r := applies("defocus")) is not None:
        lo, hi = config.focus_m
        out["defocus"] = Defocus(float(math.exp(r.uniform(math.log(lo), math.log(hi)))),
                                 _uniform(r, config.defocus_radius_width_share))
    if (r := applies("motion_blur")) is not None:
        out["motion_blur"] = MotionBlur(_uniform(r, config.motion_blur_length_width_share), float(r.uniform(0, 180)))
    if (r := applies("vignetting")) is not None:
        out["vignetting"] = Vignetting(_uniform(r, config.vignetting_corner_loss))
    if (r := applies("exposure")) is not None:
        out["exposure"] = Exposure(_uniform(r, config.exposure_ev))
    if (r := applies("noise")) is not None:
        out["noise"] = Noise(_uniform(r, config.noise_shot_gain), _uniform(r, config.noise_read_sigma),
                             int(r.integers(2**32)))
    if (r := applies("white_balance")) is not None:
        out["white_balance"] = WhiteBalance(_uniform(r, config.white_balance_gain),
                                            _uniform(r, config.white_balance_gain))
    if (r := applies("jpeg")) is not None:
        lo, hi = config.jpeg_quality
        out["jpeg"] = Jpeg(int(r.integers(lo, hi + 1)))
    return EffectsDraw(**out)


def draw_image_effects(config: RandomisationConfig | None, seed: int, camera_path: str, time_code: float,
                       condition: str | None) -> EffectsDraw | None:
    """The camera effects of a dataset's image (its seed, camera, time code and condition name), from the
    ``effects`` stream (:mod:`synthua_usd.randomisation.streams`); None when ``config`` draws none."""
    if config is None or not config.effects.enabled:
        return None
    keys = (camera_path, time_code) + ((condition,) if condition is not None else ())
    return draw_effects(stream(config.seed, seed, "effects", *keys), config.effects)
