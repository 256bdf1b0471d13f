"""Which images a generation run renders: the sweep of candidates, the quota-driven plan, and the split.

* :func:`candidates` expands a config's sweep over the stage's cameras, time codes and conditions (and the
  config's seeds) into :class:`Candidate` views, checking the config's names against the stage.
* :func:`plan` chooses ``config.images`` of them, deterministically, to meet the quotas as well as the pool
  allows, from :class:`ViewScore` s (visible aid users per camera and time code, measured by the caller on a
  cheap label pass: a view's geometry does not depend on its condition, nor on its seed unless the config
  randomises scenes, when each seed is a scene of its own and is scored per seed).
* :func:`split_of` assigns whole cameras to train/val/test: the frames of one camera at other time codes,
  conditions and seeds are near duplicates, so they never straddle splits.

Plain data only: cameras arrive as ``(prim path, name, rig type or None)`` tuples.
"""

from __future__ import annotations

import hashlib
import math
from collections import Counter, deque
from dataclasses import asdict, dataclass
from fnmatch import fnmatchcase
from typing import Iterable, Mapping, Sequence

import numpy as np

from synthua_usd.core.errors import InputError, echo
from synthua_usd.dataset.config import NO_RIG, GenerationConfig, SplitRatios
from synthua_usd.dataset.layout import SPLITS

#: Condition key of images rendered with the stage's own condition (config ``conditions`` empty).
STAGE_CONDITION = "(stage)"
#: Most candidates a sweep may hold.
MAX_POOL = 5_000_000

CameraInfo = tuple  # (prim_path: str, name: str, rig_type: str | None)


@dataclass(frozen=True)
class Candidate:
    """One view the sweep can render. ``condition`` None: the stage's own; ``rig_type`` None: no rig."""

    camera_path: str
    camera_name: str
    rig_type: str | None
    time_code: float
    condition: str | None
    seed: int

    @property
    def rig_key(self) -> str:
        return self.rig_type or NO_RIG

    @property
    def condition_key(self) -> str:
        return condition_key(self.condition)


def condition_key(name: str | None) -> str:
    """The key of a condition in quotas and reports (:data:`STAGE_CONDITION` for None)."""
    return STAGE_CONDITION if name is None else name


@dataclass(frozen=True)
class AidUserView:
    """One aid user in a view: the device's class name, visible pixels of the person and of the device,
    and the pair's occlusion 0..1 (None when unknown)."""

    aid_type: str
    person_pixels: int
    device_pixels: int
    occlusion: float | None = None

    @property
    def visible_pixels(self) -> int:
        return int(self.person_pixels) + int(self.device_pixels)


@dataclass(frozen=True)
class ViewScore:
    """The aid users visible from one camera at one time code; with scene randomisation, of one seed's scene
    (``seed``; None: the scenario as composed, whatever the seed)."""

    camera_path: str
    time_code: float
    aid_users: tuple[AidUserView, ...] = ()
    seed: int | None = None

    @classmethod
    def from_rows(cls, camera_path: str, time_code: float, rows: Iterable[Sequence],
                  seed: int | None = None) -> "ViewScore":
        """From ``(aid_type, person_pixels, device_pixels, occlusion or None)`` rows."""
        return cls(camera_path, float(time_code), tuple(AidUserView(*row) for row in rows), seed)

    def to_dict(self) -> dict:
        out = asdict(self)
        if self.seed is None:
            del out["seed"]
        return out


@dataclass(frozen=True)
class PlannedImage(Candidate):
    """One image to render: a candidate with its ``id`` (1-based in plan order), its ``split``, whether the
    plan counted it for the aid-user quota (``aid_user``), and the ``round`` that planned it (0: the plan,
    k: the k-th round of replacing images QA rejected)."""

    id: int = 0
    split: str = "train"
    aid_user: bool = False
    round: int = 0

    def to_dict(self) -> dict:
        return asdict(self)


def select_cameras(config, cameras: Sequence[CameraInfo], where: str = "cameras") -> list[CameraInfo]:
    """The stage's ``cameras`` that the ``cameras`` selectors of ``config`` (a generation config, or its
    sequences) pick, in stage order (all when it lists none). A selector that picks nothing raises
    :class:`InputError`."""
    cameras = [(str(p), str(n), r) for p, n, r in cameras]
    if not config.cameras:
        return cameras
    chosen: set[str] = set()
    for k, selector in enumerate(config.cameras):
        if selector.pattern is not None:
            hits = {p for p, _, _ in cameras if fnmatchcase(p, selector.pattern)}
            what = f"{echo(selector.pattern)!r} matches no camera"
        else:
            hits = {p for p, _, r in cameras if (r or NO_RIG) in selector.rig_types}
            what = f"rig types {', '.join(selector.rig_types)} match no camera"
        if not hits:
            stage = ", ".join(f"{p} ({r or NO_RIG})" for p, _, r in cameras) or "none"
            raise InputError(f"{where}[{k}]: {what}; expected a camera of the stage: {echo(stage, 600)}")
        chosen |= hits
    return [c for c in cameras if c[0] in chosen]


def select_conditions(asked, offered: Sequence[str], where: str = "conditions") -> list[str | None]:
    """The conditions a config's ``asked`` (``"all"``, names, or empty: the stage as composed, None) picks among
    those the stage ``offered``; a name the stage lacks raises :class:`InputError`."""
    offered = list(offered)
    if asked == "all":
        if not offered:
            raise InputError(f'{where}: "all" but the stage offers no conditions; expected a stage with a condition '
                             "variant set, or conditions empty")
        return offered
    if asked:
        unknown = [c for c in asked if c not in offered]
        if unknown:
            raise InputError(f"{where}: {', '.join(map(echo, unknown))} not offered by the stage; expected among "
                             f"{', '.join(offered) or 'none (leave conditions empty)'}")
        return list(asked)
    return [None]


def candidates(config: GenerationConfig, cameras: Sequence[CameraInfo], time_codes: Sequence[float],
               conditions: Sequence[str]) -> list[Candidate]:
    """Every view of the sweep, ordered condition, camera (stage order), time code, seed.

    Parameters
    ----------
    cameras : the stage's cameras as (prim path, name, rig type or None).
    time_codes : the stage's time codes (its whole time codes, start to end); the config's time codes must
        lie within their range, and an empty config list takes them all.
    conditions : names of the conditions the stage offers (its condition variants); the config's must be
        among them, ``"all"`` takes them all, an empty config list renders the stage as composed (None).
    """
    chosen = select_cameras(config, cameras)
    stage_times = [float(t) for t in time_codes]
    times = list(config.time_codes) or stage_times
    if not times:
        raise InputError("time_codes: the stage has no time codes and the config lists none; expected time codes")
    if stage_times:
        lo, hi = min(stage_times), max(stage_times)
        outside = [t for t in times if not lo <= t <= hi]
        if outside:
            raise InputError(f"time_codes: {', '.join(f'{t:g}' for t in outside[:5])} outside the stage's time range; "
                             f"expected time codes within {lo:g}..{hi:g}")
    names = select_conditions(config.conditions, conditions)
    size = len(names) * len(chosen) * len(times) * len(config.seeds)
    if size > MAX_POOL:
        raise InputError(f"the sweep holds {size} candidates; expected at most {MAX_POOL} (fewer time codes, "
                         "conditions or seeds)")
    return [Candidate(path, name, rig, t, condition, seed)
            for condition in names for path, name, rig in chosen for t in times for seed in config.seeds]


def _scores_by_view(scores) -> dict[tuple[str, float, int | None], ViewScore]:
    if isinstance(scores, Mapping):
        scores = scores.values()
    return {(s.camera_path, float(s.time_code), s.seed): s for s in scores}


def _qualifying(pool: Sequence[Candidate], scores, config: GenerationConfig) -> list[bool]:
    """Per candidate: whether its view shows an aid user that counts for the aid-user quota (a view without a
    score shows none). A randomised candidate takes its seed's score."""
    quota = config.quotas.aid_users
    by_view = _scores_by_view(scores)
    scene = config.randomise is not None
    out = []
    for c in pool:
        score = by_view.get((c.camera_path, float(c.time_code), c.seed if scene else None))
        out.append(bool(quota and score and any(quota.qualifies(a.visible_pixels, a.occlusion)
                                                for a in score.aid_users)))
    return out


def _condition_keys(pool: Sequence[Candidate]) -> list[str]:
    return list(dict.fromkeys(c.condition_key for c in pool))


def _rig_keys(pool: Sequence[Candidate]) -> list[str]:
    return list(dict.fromkeys(c.rig_key for c in pool))


def quota_targets(pool: Sequence[Candidate], config: GenerationConfig) -> dict:
    """What each quota asks of a plan over ``pool``: ``{"images": n, "aid_users": n or None,
    "per_condition": {key: n}, "per_rig_type": {key: n}}`` (balanced quotas shared over the keys the pool
    holds)."""
    quotas = config.quotas
    total = min(config.images, len(pool))
    return {
        "images": total,
        "aid_users": None if quotas.aid_users is None else quotas.aid_users.images(total),
        "per_condition": {} if quotas.per_condition is None else quotas.per_condition.targets(_condition_keys(pool), total),
        "per_rig_type": {} if quotas.per_rig_type is None else quotas.per_rig_type.targets(_rig_keys(pool), total),
    }


def pool_summary(pool: Sequence[Candidate], scores, config: GenerationConfig) -> dict:
    """How many candidates the pool holds in all, with a qualifying aid user, per condition and per rig type
    (what :mod:`coverage` quotes when a quota falls short)."""
    qualifying = _qualifying(pool, scores, config)
    return {"candidates": len(pool), "aid_users": sum(qualifying),
            "per_condition": dict(Counter(c.condition_key for c in pool)),
            "per_rig_type": dict(Counter(c.rig_key for c in pool))}


def plan(pool: Sequence[Candidate], scores, config: GenerationConfig) -> list[PlannedImage]:
    """Choose ``config.images`` candidates (all of them when the pool is smaller) to meet the quotas.

    Deterministic: the pool is shuffled by ``config.sampling_seed``; candidates are grouped by (condition,
    rig type, has a qualifying aid user); each pick takes, from the group that helps the most quotas still
    short, its next candidate in shuffled order (ties: the group whose next candidate comes first). Once every
    quota is met the rest follows the shuffled order. Greedy, so quotas are met as well as the pool allows
    in the common cases, not provably optimally; :mod:`coverage` reports what was achieved.

    ``scores`` are :class:`ViewScore` s (an iterable, or a mapping whose values are them). The chosen images
    are returned in pool order, ids from 1, each with its split (:func:`split_of` over the chosen cameras).
    """
    pool = list(pool)
    qualifying = _qualifying(pool, scores, config)
    targets = quota_targets(pool, config)
    rank = np.empty(len(pool), dtype=np.int64)
    rank[np.random.default_rng(config.sampling_seed).permutation(len(pool))] = np.arange(len(pool))
    groups = _groups(pool, qualifying, rank, range(len(pool)))

    chosen = _pick(groups, rank, targets["images"], dict(targets["per_condition"]), dict(targets["per_rig_type"]),
                   targets["aid_users"] or 0)
    chosen.sort()
    splits = split_of([pool[i].camera_path for i in chosen], config.split)
    return [PlannedImage(**asdict(pool[i]), id=k, split=splits[pool[i].camera_path], aid_user=qualifying[i])
            for k, i in enumerate(chosen, start=1)]


def _groups(pool: Sequence[Candidate], qualifying: list[bool], rank: np.ndarray, indices) -> dict[tuple, deque]:
    """Indices of ``pool`` grouped by (condition, rig type, qualifying aid user), each group in rank order."""
    groups: dict[tuple, deque] = {}
    for index in sorted(indices, key=lambda i: rank[i]):
        c = pool[index]
        groups.setdefault((c.condition_key, c.rig_key, qualifying[index]), deque()).append(index)
    return groups


def _pick(groups: dict[tuple, deque], rank: np.ndarray, count: int, need_condition: dict, need_rig: dict,
          need_aid: int) -> list[int]:
    """Take ``count`` candidates from ``groups``: each pick from the group that helps the most quotas still
    short (ties: the group whose next candidate ranks first)."""
    chosen: list[int] = []
    for _ in range(count):
        best, best_key = None, None
        for key, queue in groups.items():
            if not queue:
                continue
            condition, rig, aid = key
            gain = ((need_condition.get(condition, 0) > 0) + (need_rig.get(rig, 0) > 0) + (aid and need_aid > 0))
            order = (-gain, rank[queue[0]])
            if best_key is None or order < best_key:
                best, best_key = key, order
        if best is None:
            break
        chosen.append(groups[best].popleft())
        condition, rig, aid = best
        need_condition[condition] = need_condition.get(condition, 0) - 1
        need_rig[rig] = need_rig.get(rig, 0) - 1
        need_aid -= int(aid)
    return chosen


def replacements(pool: Sequence[Candidate], scores, config: GenerationConfig, planned: Sequence[PlannedImage],
                 rejected: set[int], round: int = 1) -> list[PlannedImage]:
    """Images to render in place of the ``rejected`` ids of ``planned``, chosen like :func:`plan` from the
    candidates not planned yet, counting what the kept images already give the quotas. Only cameras of
    the plan are used, so each replacement inherits its camera's split; ids continue after the plan's."""
    pool = list(pool)
    qualifying = _qualifying(pool, scores, config)
    targets = quota_targets(pool, config)
    rank = np.empty(len(pool), dtype=np.int64)
    rank[np.random.default_rng(config.sampling_seed).permutation(len(pool))] = np.arange(len(pool))
    key = lambda c: (c.camera_path, float(c.time_code), c.condition, c.seed)  # noqa: E731
    taken = {key(p) for p in planned}
    split_of_camera = {p.camera_path: p.split for p in planned}
    kept = [p for p in planned if p.id not in rejected]
    need_condition = dict(targets["per_condition"])
    need_rig = dict(targets["per_rig_type"])
    need_aid = targets["aid_users"] or 0
    for p in kept:
        need_condition[condition_key(p.condition)] = need_condition.get(condition_key(p.condition), 0) - 1
        need_rig[p.rig_type or NO_RIG] = need_rig.get(p.rig_type or NO_RIG, 0) - 1
        need_aid -= int(p.aid_user)
    free = [i for i, c in enumerate(pool) if key(c) not in taken and c.camera_path in split_of_camera]
    chosen = sorted(_pick(_groups(pool, qualifying, rank, free), rank, targets["images"] - len(kept), need_condition,
                          need_rig, need_aid))
    first = max((p.id for p in planned), default=0) + 1
    return [PlannedImage(**asdict(pool[i]), id=first + k, split=split_of_camera[pool[i].camera_path],
                         aid_user=qualifying[i], round=round)
            for k, i in enumerate(chosen)]


def _stable_hash(seed: int, key: str) -> str:
    return hashlib.sha256(f"{seed}\0{key}".encode("utf-8", "surrogatepass")).hexdigest()


def split_counts(groups: int, ratios: SplitRatios) -> dict[str, int]:
    """Groups per split: largest remainder of ratio × ``groups`` (ties in train, val, test order); then each
    split with a positive ratio gets at least one group when there are enough groups, taken from the split
    with the most."""
    shares = ratios.ratios
    exact = {s: shares[s] * groups for s in SPLITS}
    counts = {s: math.floor(exact[s] + 1e-9) for s in SPLITS}
    by_remainder = sorted(SPLITS, key=lambda s: (-(exact[s] - counts[s]), SPLITS.index(s)))
    for s in by_remainder[:groups - sum(counts.values())]:
        counts[s] += 1
    positive = [s for s in SPLITS if shares[s] > 0]
    if groups >= len(positive):
        for s in positive:
            if counts[s] == 0:
                donor = max(SPLITS, key=lambda d: (counts[d], -SPLITS.index(d)))
                counts[donor] -= 1
                counts[s] += 1
    return counts


def split_of(groups: Iterable[str], ratios: SplitRatios) -> dict[str, str]:
    """The split of each group (a camera prim path): the distinct groups ordered by a SHA-256 hash of
    (``ratios.seed``, group), then dealt out train, val, test by :func:`split_counts`. A group's split
    depends only on the seed and the set of groups, never on the order they come in."""
    distinct = sorted(set(groups), key=lambda g: (_stable_hash(ratios.seed, g), g))
    counts = split_counts(len(distinct), ratios)
    out, start = {}, 0
    for split in SPLITS:
        for group in distinct[start:start + counts[split]]:
            out[group] = split
        start += counts[split]
    return out
