"""The coverage report (``coverage.json``): what a generated dataset holds, and where it fell short of the
config's quotas.

Built from the final per-image records alone (plus, when the caller has them, the plan's quota targets and
the pool's counts from :mod:`sampling`), so it describes the images as written. Images rejected by QA are
counted in ``images`` but not towards the quotas or the tables: they are not part of the dataset's
annotations.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from typing import Sequence

from synthua_usd.dataset.config import NO_RIG, GenerationConfig
from synthua_usd.dataset.layout import SPLITS
from synthua_usd.dataset.qa import aid_users
from synthua_usd.dataset.record import REJECTED, DatasetRecord, is_rejected
from synthua_usd.dataset.sampling import condition_key

#: Occlusion buckets of the aid-user table: [0, 0.25), [0.25, 0.5), [0.5, 0.75), [0.75, 1].
OCCLUSION_EDGES = (0.0, 0.25, 0.5, 0.75, 1.0)
UNKNOWN_OCCLUSION = "unknown"


def occlusion_bucket(occlusion: float | None) -> str:
    """``"0.00-0.25"`` ... ``"0.75-1.00"`` (the last includes 1), or :data:`UNKNOWN_OCCLUSION`."""
    if occlusion is None:
        return UNKNOWN_OCCLUSION
    for lo, hi in zip(OCCLUSION_EDGES, OCCLUSION_EDGES[1:]):
        if occlusion < hi or hi == OCCLUSION_EDGES[-1]:
            return f"{lo:.2f}-{hi:.2f}"
    raise AssertionError("unreachable")


def _rig_key(record: DatasetRecord) -> str:
    """The rig type of a rendered image's camera; a composite's photo has none."""
    return NO_RIG if "composite" in record else record["camera"]["rig_type"] or NO_RIG


def _condition_key(record: DatasetRecord) -> str:
    """The condition of a rendered image (the stage's own light when None); a composite has none."""
    condition = None if "composite" in record else record["condition"]
    return condition_key(None if condition is None else condition["name"])


def _camera_path(record: DatasetRecord) -> str | None:
    """The prim path of a rendered image's camera; None for a composite (a photo's camera is no prim)."""
    return None if "composite" in record else record["camera"]["prim_path"]


def _quota(name: str, key: str | None, asked: int, achieved: int, pool: int | None, what: str) -> tuple[dict, str | None]:
    entry = {"quota": name, "key": key, "asked": asked, "achieved": achieved, "met": achieved >= asked}
    if pool is not None:
        entry["pool"] = pool
    if achieved >= asked:
        return entry, None
    label = name if key is None else f"{name} {key}"
    why = f" (the pool had {pool})" if pool is not None else ""
    return entry, f"{label}: asked {asked}{what}, got {achieved}{why}"


def coverage(records: Sequence[DatasetRecord], config: GenerationConfig | None, targets: dict | None = None,
             pool: dict | None = None) -> dict:
    """The coverage report as a JSON-serialisable dict.

    Parameters
    ----------
    records : the final per-image records (spec: ``camera.rig_type``, ``condition.name``, ``split``,
        ``instances`` with ``relations``, ``qa.verdict``).
    config : the generation config; None for a dataset without quotas (``synthua composite``'s): no quota is
        checked
    targets : :func:`sampling.quota_targets` of the pool (what balanced quotas asked per key); None
        takes the explicit counts and shares balanced ones over the keys the records hold.
    pool : :func:`sampling.pool_summary`; when given, shortfalls say what the pool held.

    Returns keys ``images`` (total and per verdict), ``splits`` (images, share, cameras), ``per_condition``,
    ``per_rig_type``, ``aid_users`` (images and instances), ``table`` (aid users counted by aid type × rig
    type × condition × occlusion bucket, with the images they appear in), ``quotas`` (asked, achieved,
    met per quota and key) and ``shortfalls`` (one sentence per unmet quota).
    """
    verdicts = Counter(r["qa"]["verdict"] for r in records)
    kept = [r for r in records if not is_rejected(r)]
    quota_aid = None if config is None else config.quotas.aid_users

    per_condition = Counter(_condition_key(r) for r in kept)
    per_rig = Counter(_rig_key(r) for r in kept)
    cells: dict[tuple, list] = defaultdict(lambda: [0, set()])
    with_aid = qualifying = instances = 0
    for record in kept:
        users = aid_users(record["instances"])
        instances += len(users)
        with_aid += bool(users)
        qualifying += bool(quota_aid and any(quota_aid.qualifies(u.visible_pixels, u.occlusion) for u in users))
        for user in users:
            cell = cells[(user.aid_type, _rig_key(record), _condition_key(record), occlusion_bucket(user.occlusion))]
            cell[0] += 1
            cell[1].add(record["id"])
    table = [{"aid_type": a, "rig_type": r, "condition": c, "occlusion": o, "aid_users": n, "images": len(ids)}
             for (a, r, c, o), (n, ids) in sorted(cells.items())]

    splits = {}
    for split in SPLITS:
        members = [r for r in kept if r["split"] == split]
        splits[split] = {"images": len(members), "share": round(len(members) / len(kept), 6) if kept else 0.0,
                         "cameras": len({_camera_path(r) for r in members})}

    if config is None:
        targets = {}
    elif targets is None:
        total = config.images
        targets = {
            "images": total,
            "aid_users": None if quota_aid is None else quota_aid.images(total),
            "per_condition": ({} if config.quotas.per_condition is None
                              else config.quotas.per_condition.targets(sorted(per_condition), total)),
            "per_rig_type": ({} if config.quotas.per_rig_type is None
                             else config.quotas.per_rig_type.targets(sorted(per_rig), total)),
        }
    pool = pool or {}
    quotas, shortfalls = [], []

    def add(entry_and_shortfall):
        entry, shortfall = entry_and_shortfall
        quotas.append(entry)
        if shortfall:
            shortfalls.append(shortfall)

    if config is not None:
        entry, short = _quota("images", None, config.images, len(kept), pool.get("candidates"), "")
        if short and verdicts[REJECTED]:
            short = f"images: asked {config.images}, got {len(kept)} ({verdicts[REJECTED]} rejected by QA" + (
                f"; the pool had {pool['candidates']})" if "candidates" in pool else ")")
        add((entry, short))
    if quota_aid is not None and targets.get("aid_users") is not None:
        occl = "" if quota_aid.max_occlusion is None else f", occluded at most {quota_aid.max_occlusion:g}"
        add(_quota("aid_users", None, targets["aid_users"], qualifying, pool.get("aid_users"),
                   f" images with an aid user of >= {quota_aid.min_pixels} px{occl}"))
    for name, achieved in (("per_condition", per_condition), ("per_rig_type", per_rig)):
        for key, asked in targets.get(name, {}).items():
            add(_quota(name, key, asked, achieved.get(key, 0), pool.get(name, {}).get(key, 0) if pool else None, ""))

    return {
        "images": {"total": len(records), "kept": len(kept), **{v: verdicts.get(v, 0)
                                                                for v in ("accepted", "flagged", REJECTED)}},
        "splits": splits,
        "per_condition": dict(sorted(per_condition.items())),
        "per_rig_type": dict(sorted(per_rig.items())),
        "aid_users": {"images": with_aid, "qualifying_images": qualifying, "instances": instances},
        "occlusion_buckets": [occlusion_bucket(e) for e in OCCLUSION_EDGES[:-1]] + [UNKNOWN_OCCLUSION],
        "table": table,
        "quotas": quotas,
        "shortfalls": shortfalls,
    }
