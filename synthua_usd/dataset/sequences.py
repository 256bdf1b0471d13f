"""Tracking sequences as plain data: which sequences a config asks for, their frames and their names.

A sequence is one camera under one condition with one seed, ``frames`` frames ``timeCodesPerSecond / fps`` time
codes apart from its start (:class:`synthua_usd.dataset.config.SequencesConfig`). Names are those of images, without
the id and time code: ``CCTV-Largo_clear-day_s0``. Frames are numbered from 1, as MOTChallenge numbers them.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from synthua_usd.core.errors import InputError
from synthua_usd.dataset.config import SequencesConfig
from synthua_usd.dataset.layout import safe_component
from synthua_usd.dataset.sampling import CameraInfo, select_cameras, select_conditions


@dataclass(frozen=True)
class PlannedSequence:
    """One sequence: its ``name`` (unique in the dataset), camera, condition (None: the stage's own), seed and the
    time code of every frame (``time_codes[k - 1]`` is frame ``k``)."""

    name: str
    camera_path: str
    camera_name: str
    rig_type: str | None
    condition: str | None
    seed: int
    time_codes: tuple[float, ...]

    @property
    def frames(self) -> int:
        return len(self.time_codes)

    def to_dict(self) -> dict:
        return {**asdict(self), "time_codes": list(self.time_codes)}

    @classmethod
    def from_dict(cls, document: dict) -> "PlannedSequence":
        return cls(**{**document, "time_codes": tuple(float(t) for t in document["time_codes"])})


@dataclass(frozen=True)
class PlannedFrame:
    """Frame ``frame`` (1-based) of the sequence ``sequence``, at ``time_code``."""

    sequence: PlannedSequence
    frame: int

    @property
    def time_code(self) -> float:
        return self.sequence.time_codes[self.frame - 1]


def sequence_name(camera_name: str, condition: str | None, seed: int) -> str:
    return f"{safe_component(camera_name)}_{safe_component(condition or 'stage')}_s{int(seed)}"


def plan_sequences(config: SequencesConfig, cameras: list[CameraInfo], conditions: list[str], start: float,
                   time_range: tuple[float, float] | None, time_codes_per_second: float,
                   own_crowd: bool) -> list[PlannedSequence]:
    """Every sequence of ``config`` over the stage's ``cameras`` and offered ``conditions``, in the order seed,
    condition, camera; ``start`` the stage's start time code (the default first frame), ``time_range`` the
    stage's (None: unbounded). With the scenario's own crowd (``own_crowd``) every frame must lie in the stage's
    time range (its animation covers no more); with a crowd of the sequences' own the range is extended."""
    chosen = select_cameras(config, cameras, "sequences.cameras")
    names = select_conditions(config.conditions, conditions, "sequences.conditions")
    first = config.start_time_code if config.start_time_code is not None else start
    times = config.time_codes(first, time_codes_per_second)
    if time_range is not None:
        lo, hi = time_range
        if first < lo:
            raise InputError(f"sequences.start_time_code: {first:g}; expected a time code within the stage's "
                             f"{lo:g}..{hi:g}")
        if own_crowd and times[-1] > hi + 1e-9:
            raise InputError(f"sequences: {config.duration_s:g} s at {config.fps:g} fps from time code {first:g} ends "
                             f"at time code {times[-1]:g}, beyond the stage's {lo:g}..{hi:g} (the scenario's crowd is "
                             f"animated over that range only); expected a crowd block (a crowd populated for the "
                             f"sequences) or a shorter duration")
    out, seen = [], set()
    for seed in config.seeds:
        for condition in names:
            for path, name, rig in chosen:
                base = sequence_name(name, condition, seed)
                unique, k = base, 2
                while unique in seen:  # two cameras whose names reduce to the same safe text
                    unique, k = f"{base}-{k}", k + 1
                seen.add(unique)
                out.append(PlannedSequence(unique, path, name, rig, condition, int(seed), times))
    return out
