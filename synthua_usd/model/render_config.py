"""Render settings as a checked, frozen dataclass (plain data; backends read it), and the one rule that settles
them from their sources (:func:`resolve_render`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

from synthua_usd.core.errors import InputError
from synthua_usd.model.ranges import SEED

PIXEL_FILTERS = ("gaussian", "box")
MAX_SIDE = 16384
MAX_SPP = 65536
#: The odd multiplier that spreads a render seed over Mitsuba's 32-bit sampler seeds (one per RGB pass).
_PASS_STRIDE = 100_003


def sampler_seed(seed: int, render_pass: int) -> int:
    """Mitsuba's sampler seed of RGB pass ``render_pass`` of a render seeded ``seed`` (any seed of
    :data:`synthua_usd.model.ranges.SEED`): ``seed * 100003 + render_pass`` modulo 2^32, as Mitsuba takes 32-bit
    seeds. Below 42,949 the modulo changes nothing (the seeds every earlier dataset was rendered with); the odd
    multiplier maps distinct seeds to distinct first passes."""
    return (int(seed) * _PASS_STRIDE + int(render_pass)) % 2**32


@dataclass(frozen=True)
class RenderConfig:
    """How to render one frame.

    Attributes
    ----------
    width, height : int
        Image size in pixels.
    spp : int
        Path-tracing samples per pixel for RGB. Labels always use one ray through each pixel centre.
    max_depth : int
        Mitsuba path length (``max_depth = 4`` matches Cycles ``max_bounces = 2``).
    pixel_filter : str
        RGB reconstruction filter, ``box`` (each sample lands in its own pixel: independent per-pixel noise, what
        the denoiser needs, and bit-identical reruns) or ``gaussian`` (Mitsuba's default; correlates the noise of
        neighbouring pixels, so the denoiser gains little from it).
    denoise : bool
        Denoise the RGB pass (firefly filter, then Intel Open Image Denoise guided by albedo and normal from the
        same samples; :mod:`synthua_usd.backends.denoise`) before image-space weather and exposure.
    seed : int
        Seed of the RGB sampler; the same seed gives the same image on the same variant.
    variant : str | None
        Mitsuba variant; None picks cuda → llvm → scalar at run time.
    """

    width: int = 1280
    height: int = 960
    # The default quality, chosen by measurement (tools/bench_denoise.py, docs/rendering.md, "Denoising"): 32 multi-jittered
    # box-filtered samples, denoised: 38.0-42.8 dB on the district's four views at 1280x960 against 256-spp
    # references whose own noise caps the score at 39.9-46.2 dB (8 spp: 34.5-40.9 dB in 36 % of the time).
    # Dataset configs choose their own (configs/*.json: 8).
    spp: int = 32
    max_depth: int = 8
    pixel_filter: str = "box"
    denoise: bool = True
    seed: int = 0
    variant: str | None = None

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            value = getattr(self, name)
            if not isinstance(value, int) or not 0 < value <= MAX_SIDE:
                raise InputError(f"{name} should be an integer in 1..{MAX_SIDE}, but was {value!r}")
        if not isinstance(self.spp, int) or not 1 <= self.spp <= MAX_SPP:
            raise InputError(f"spp should be an integer in 1..{MAX_SPP}, but was {self.spp!r}")
        if not isinstance(self.max_depth, int) or self.max_depth < 1:
            raise InputError(f"max_depth should be an integer >= 1, but was {self.max_depth!r}")
        if self.pixel_filter not in PIXEL_FILTERS:
            raise InputError(f"pixel_filter should be one of {', '.join(PIXEL_FILTERS)}, but was {self.pixel_filter!r}")
        if not isinstance(self.denoise, bool):
            raise InputError(f"denoise should be true or false, but was {self.denoise!r}")
        if not isinstance(self.seed, int) or not SEED.contains(self.seed):
            raise InputError(f"seed: {self.seed!r}; expected {SEED}")

    @classmethod
    def from_dict(cls, data: dict) -> "RenderConfig":
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise InputError(f"render config: unknown keys {unknown}; known keys: {sorted(known)}")
        return cls(**data)

    def to_dict(self) -> dict:
        return asdict(self)


def resolve_render(stage: Mapping[str, Any] | None = None, config: Mapping[str, Any] | None = None,
                   options: Mapping[str, Any] | None = None) -> RenderConfig:
    """The render settings of a frame, each field from the strongest source that sets it, in this order
    (weakest first): :class:`RenderConfig`'s defaults < ``stage``, the stage's UsdRender settings (resolution
    and ``synthua:spp``, as :func:`synthua_usd.usd.render_settings.render_defaults` reads them) < ``config``,
    a dataset config's ``render`` block < ``options``, the command line's. Every source maps field names to
    values; None (or a key left out) leaves the field to the weaker sources. ``synthua render``, ``synthua
    generate`` and ``synthua randomise`` all settle their settings here (docs/rendering.md, "Where the render
    settings come from"). An unknown field or a value out of range raises :class:`InputError`."""
    values = RenderConfig().to_dict()
    for source in (stage, config, options):
        values.update({key: value for key, value in (source or {}).items() if value is not None})
    return RenderConfig.from_dict(values)


def takes_exactly(spp: int) -> bool:
    """Whether Mitsuba's multi-jittered sampler (every RGB pass's) draws exactly ``spp`` samples (it draws an
    r x c grid, ``r = isqrt(spp)``, ``c = ceil(spp / r)``): 1, 2, 3, 4, 6, 8, 9, 12, 15, 16, 20, ..."""
    import math

    r = math.isqrt(spp)
    return r * -(-spp // r) == spp
