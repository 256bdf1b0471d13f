"""Tiny banks of cut-outs drawn by hand, in the bank format ``synthua-cutouts/1`` (what ``synthua cutouts`` writes;
docs/compositing.md, "The bank"), and tiny photos to paste them on: what the composite tests run on.

An aid user is a person (instance 1: a head and a torso) seated behind a manual wheelchair (instance 2: a seat and a
wheel in front of the person's legs, so the person's amodal mask holds pixels the wheel hides), with a one-pixel
half-transparent rim outside both (alpha without an id, as a rendered edge has), an elliptic shadow under the wheel,
17 person keypoints (those behind the wheel flagged 1, one unlabelled) and the wheelchair's 3 contact points. A
pedestrian is a person alone. Every number (boxes, areas, keypoints, anchor, scale) is computed from the drawn
masks, as a bank writer must.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
from PIL import Image
from scipy import ndimage

from synthua_usd.model.taxonomy import ClassMap

FORMAT = "synthua-cutouts/1"


def _disc(h: int, w: int, cx: float, cy: float, r: float) -> np.ndarray:
    yy, xx = np.mgrid[0:h, 0:w] + 0.5
    return (xx - cx) ** 2 + (yy - cy) ** 2 <= r * r


def _rect(h: int, w: int, x0: int, y0: int, x1: int, y1: int) -> np.ndarray:
    m = np.zeros((h, w), bool)
    m[y0:y1, x0:x1] = True
    return m


def _box(mask: np.ndarray) -> list[int]:
    ys, xs = np.nonzero(mask)
    return [int(xs.min()), int(ys.min()), int(xs.max() - xs.min() + 1), int(ys.max() - ys.min() + 1)]


def _person_keypoints(ids: np.ndarray, cx: float, top: float, index: int) -> list[list[float]]:
    """17 COCO keypoints down the figure's middle: head ones, shoulders, elbows, wrists, hips, knees, ankles; v = 2
    where the figure is visible there, 1 where another instance hides it; the left ear unlabelled."""
    rows = [top + 4, top + 3, top + 3, top + 4, top + 4, top + 13, top + 13, top + 20, top + 20, top + 26, top + 26,
            top + 31, top + 31, top + 40, top + 40, top + 48, top + 48]
    out = []
    for k, y in enumerate(rows):
        x = cx + (-3 if k % 2 else 3) * (k >= 5)
        if k == 3:
            out.append([0.0, 0.0, 0])
            continue
        col, row = int(x), int(y)
        v = 2 if 0 <= row < ids.shape[0] and ids[row, col] == index else 1
        out.append([float(x), float(y), v])
    return out


def aid_user(entry_id: str, elevation_deg: float = 15.0, subject_height_m: float = 1.3, overcast: float = 0.0,
             sun_azimuth_deg: float = 0.0, colour=(200, 40, 40), group: str = "alone") -> dict:
    """An aid user's cut-out: its arrays and its bank entry (without files)."""
    h, w = 66, 48
    person = _disc(h, w, 24, 8, 5) | _rect(h, w, 17, 13, 31, 52)
    chair = _rect(h, w, 12, 38, 36, 43) | (_disc(h, w, 24, 52, 10) & ~_disc(h, w, 24, 52, 6))
    ids = np.zeros((h, w), np.uint8)
    ids[person] = 1
    ids[chair] = 2
    amodal = person.astype(np.uint16) | (chair.astype(np.uint16) << 1)
    group_mask = person | chair
    rim = np.zeros_like(group_mask)
    rim[1:, :] |= group_mask[:-1, :]
    rim[:-1, :] |= group_mask[1:, :]
    rim[:, 1:] |= group_mask[:, :-1]
    rim[:, :-1] |= group_mask[:, 1:]
    rim &= ~group_mask
    rgba = np.zeros((h, w, 4), np.uint8)
    rgba[person] = (*colour, 255)
    rgba[chair] = (40, 40, 60, 255)
    rgba[rim] = (90, 90, 90, 128)
    shadow = np.full((h, w), 255, np.uint8)
    yy, xx = np.mgrid[0:h, 0:w] + 0.5
    shadow[((xx - 24) / 20) ** 2 + ((yy - 62) / 3.5) ** 2 <= 1] = 110
    top, bottom = 3, 62
    anchor = [24.0, 62.0]
    instances = [
        {"index": 1, "class_name": "person", "role": "user", "relations": {"uses": 2},
         "keypoints": _person_keypoints(ids, 24.0, top, 1)},
        {"index": 2, "class_name": "manual_wheelchair", "role": "device", "relations": {},
         "keypoints": [[14.0, 45.0, 2], [34.0, 45.0, 2], [24.0, 40.0, 2]]},
    ]
    return _entry(entry_id, "aid_user", group, "manual_wheelchair", rgba, ids, amodal, shadow, instances,
                  [[24.0, 62.0]], anchor, subject_height_m, (bottom - top) / subject_height_m, elevation_deg,
                  overcast, sun_azimuth_deg)


def pedestrian(entry_id: str, elevation_deg: float = 15.0, subject_height_m: float = 1.7,
               colour=(40, 160, 60)) -> dict:
    """A pedestrian's cut-out."""
    h, w = 66, 24
    person = _disc(h, w, 12, 7, 5) | _rect(h, w, 7, 12, 17, 62)
    ids = person.astype(np.uint8)
    rgba = np.zeros((h, w, 4), np.uint8)
    rgba[person] = (*colour, 255)
    shadow = np.full((h, w), 255, np.uint8)
    shadow[60:64, 2:22] = 150
    instances = [{"index": 1, "class_name": "person", "role": "pedestrian", "relations": {},
                  "keypoints": _person_keypoints(ids, 12.0, 2, 1)}]
    return _entry(entry_id, "pedestrian", "alone", None, rgba, ids, person.astype(np.uint16), shadow, instances,
                  [[9.0, 62.0], [15.0, 62.0]], [12.0, 62.0], subject_height_m, 60 / subject_height_m, elevation_deg,
                  0.5, 0.0)


def _entry(entry_id, kind, group, aid, rgba, ids, amodal, shadow, instances, ground, anchor, subject_height_m,
           scale_px_per_m, elevation_deg, overcast, sun_azimuth_deg) -> dict:
    for inst in instances:
        visible = ids == inst["index"]
        full = (amodal & (1 << (inst["index"] - 1))) > 0
        inst.update({"bbox": _box(visible), "area": int(visible.sum()), "amodal_bbox": _box(full),
                     "amodal_area": int(full.sum())})
    distance = 1.6 / np.tan(np.radians(elevation_deg))
    entry = {"id": entry_id, "size": [int(ids.shape[1]), int(ids.shape[0])], "kind": kind, "group": group, "aid": aid,
             "instances": instances, "ground_points": ground, "anchor": anchor, "subject_height_m": subject_height_m,
             "camera": {"height_m": 1.6, "pitch_deg": -8.0, "focal_px": 900.0, "distance_m": float(distance),
                        "elevation_deg": elevation_deg, "frame": [1280, 960], "crop_origin": [600, 400]},
             "scale_px_per_m": float(scale_px_per_m),
             "light": {"sun_elevation_deg": 35.0, "sun_azimuth_deg": sun_azimuth_deg, "overcast": overcast,
                       "condition": "clear_day"}, "seed": 0}
    return {"entry": entry, "rgba": rgba, "ids": ids, "amodal": amodal.astype(np.uint16), "shadow": shadow}


def bands(height: int, width: int, period: int, low: float, high: float, sigma: float = 0.0) -> np.ndarray:
    """Horizontal grey bands (half a period each), sRGB values in [0, 1] (h, w), blurred by a Gaussian of
    ``sigma`` px."""
    rows = (np.arange(height) // (period // 2)) % 2
    grey = np.where(rows[:, None] == 1, high, low) * np.ones((1, width))
    return ndimage.gaussian_filter(grey, sigma) if sigma else grey


def banded_aid_user(entry_id: str, sigma: float = 0.0) -> dict:
    """:func:`aid_user` whose person is drawn in grey bands 12 px high (0.35 and 0.7; blurred by ``sigma`` within
    the drawing): a cut-out with edges inside it, for sharpness matching."""
    cutout = aid_user(entry_id, 15.0)
    person = cutout["ids"] == 1
    grey = np.round(bands(66, 48, 12, 0.35, 0.7, sigma) * 255).astype(np.uint8)
    cutout["rgba"][person, :3] = grey[person][:, None]
    return cutout


def write_band_photos(folder: Path, count: int, size, sigma: float) -> list[Path]:
    """``count`` photos (W, H) ``size`` of grey bands 18 px high blurred by ``sigma`` px: a soft photo."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for k in range(count):
        grey = np.round(bands(size[1], size[0], 36, 0.3 + 0.05 * k, 0.75, sigma) * 255).astype(np.uint8)
        out.append(folder / f"bands_{k:02d}.png")
        Image.fromarray(np.repeat(grey[..., None], 3, axis=2)).save(out[-1])
    return out


def default_cutouts() -> list[dict]:
    """Three aid users seen from 8, 15 and 30 degrees (one pushed) and two pedestrians."""
    return [aid_user("c000000", 8.0), aid_user("c000001", 15.0, colour=(30, 90, 200), group="pushed"),
            aid_user("c000002", 30.0, colour=(220, 180, 40), overcast=1.0),
            pedestrian("c000003", 10.0), pedestrian("c000004", 25.0, colour=(150, 60, 150))]


def write_bank(root: Path, cutouts: list[dict] | None = None, fmt: str = FORMAT) -> Path:
    """Write a bank of ``cutouts`` (default :func:`default_cutouts`) into ``root``; bank.json last."""
    root = Path(root)
    (root / "cutouts").mkdir(parents=True, exist_ok=True)
    cutouts = default_cutouts() if cutouts is None else cutouts
    files, entries = [], []
    for c in cutouts:
        entry = dict(c["entry"])
        names = {key: f"cutouts/{entry['id']}.{key}.png" for key in ("rgba", "ids", "amodal", "shadow")}
        Image.fromarray(c["rgba"]).save(root / names["rgba"])
        Image.fromarray(c["ids"]).save(root / names["ids"])
        Image.fromarray(c["amodal"]).save(root / names["amodal"])
        Image.fromarray(c["shadow"]).save(root / names["shadow"])
        entry["files"] = names
        entries.append(entry)
        for rel in names.values():
            data = (root / rel).read_bytes()
            files.append({"path": rel, "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()})
    doc = {"format": fmt, "synthua": "0.1.0", "config": {}, "class_map": ClassMap.default().document(),
           "cutouts": entries, "files": files}
    (root / "bank.json").write_text(json.dumps(doc, indent=1), encoding="utf-8")
    return root


def write_photos(folder: Path, count: int = 3, size=(96, 72), suffix: str = ".png", seed: int = 0) -> list[Path]:
    """``count`` photos of a street-like gradient with noise (sky above, ground below), ``size`` (W, H)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        w, h = size
        rows = np.linspace(0, 1, h)[:, None, None]
        base = np.where(rows < 0.4, [150, 180, 230], [110 + 10 * k, 105, 100]) * (0.8 + 0.2 * rows)
        pixels = np.clip(base + rng.normal(0, 8, (h, w, 3)), 0, 255).astype(np.uint8)
        path = folder / f"photo_{k:02d}{suffix}"
        Image.fromarray(pixels).save(path, quality=95) if suffix == ".jpg" else Image.fromarray(pixels).save(path)
        out.append(path)
    return out
