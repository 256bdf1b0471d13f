"""Where the cut-outs of one composite go: the photo's camera model drawn, then each paste's cut-out, anchor,
scale, order, blend mode and shadow, as plain data (no pixel is touched here; :mod:`synthua_usd.backends.compositing`
paints what this plans).

A paste is planned on the ground plane of the photo's camera (:class:`synthua_usd.model.photo_camera.PhotoCamera`):

1. its kind (aid user or pedestrian) and its share of the frame height, drawn from the config's range;
2. the anchor row that shows a group of the kind's median height that tall (at most the image's last row: a
   camera that cannot show the group that large takes the largest share it can, recorded as ``share``);
3. the elevation the camera is seen from there; the cut-outs are ranked by how far their own camera elevation
   is (over ``elevation_tolerance_deg``), plus how unalike their light is when the config gives the photo's;
   one of the best ``choose_among`` is drawn;
4. the anchor row again for the chosen cut-out's own height (the share kept), its scale
   ``(y_a - y_h) / (H scale_px_per_m)``, and a column where its box lies in the frame (up to ``edge_cut`` of its
   width beyond the left edge, and as much beyond the right one), tried ``placement_tries`` times for one where,
   of it and each earlier paste, the nearer (drawn later) covers at most ``max_overlap`` of the farther one's box
   in view (the part within the frame; with ``visible_overlap`` False, as jobs without ``job_key.visible_overlap``
   did, its whole box, though the frame may cut it; with ``overlap_by_depth`` False, as jobs without
   ``job_key.overlap_by_depth`` did, always the share of the earlier one's box the new paste covers, though a
   farther new paste is drawn behind it), and that covers at most ``max_background_cover`` (default
   ``drop_covered_share``) of each labelled background box; where no column does, the least overlapping one
   (``when_no_room``: ``least_overlap``) or no paste at all (``skip``: the photo's own labelled people stay in
   view);
5. a blend mode by the config's weights (Poisson at most once a composite) and a shadow strength;
6. where ``sharpen.share`` > 0, whether it is sharpened and by what amount and sigma, from a generator spawned
   for it (the handed one's draws stay as they are: the pastes are those of the same config without sharpening).

Pastes are drawn far to near (by anchor row): ``order`` 0 is drawn first, and a nearer paste covers a farther one.
Every draw comes from the generator handed in (or one spawned from it), in a fixed order, so a composite's plan
depends on its seed only.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from statistics import median
from typing import Sequence

import numpy as np

from synthua_usd.dataset.composite_config import BLEND_MODES, PEOPLE_HEIGHTS, CameraSettings, CompositeConfig
from synthua_usd.dataset.cutout_bank import BankEntry, Light
from synthua_usd.dataset.record import PhotoCameraEntry
from synthua_usd.model.photo_camera import PhotoCamera, focal_px_from_35mm, horizon_from_people

#: Least drop, in pixels, from the horizon to an anchor (a paste right at the horizon would be infinitely far).
MIN_DROP_PX = 1.0


@dataclass(frozen=True)
class DrawnCamera:
    """A composite's camera model and where each of its values came from (``config``, ``folder:<name>``,
    ``exif``, ``pitch_deg:<one of those>`` or ``people:<boxes used>:<those of the heights set, joined by +>``);
    ``light`` the photo's light when the config gives it."""

    camera: PhotoCamera
    sources: dict
    light: Light | None
    exif_focal_35mm: float | None

    def to_dict(self) -> PhotoCameraEntry:
        c = self.camera
        return PhotoCameraEntry(width_px=c.width_px, height_px=c.height_px, horizon_row_px=c.horizon_row_px,
                                height_m=c.height_m, focal_px=c.focal_px, pitch_deg=c.pitch_deg,
                                K=c.intrinsics().tolist(), sources=dict(self.sources),
                                exif_focal_35mm=self.exif_focal_35mm,
                                light=None if self.light is None else asdict(self.light))


def draw_camera(settings: CameraSettings, sources: dict, size: tuple[int, int], exif_focal_35mm: float | None,
                source_size: tuple[int, int], scale: float, rng: np.random.Generator,
                people: Sequence[tuple[str, tuple[float, float, float, float]]] = (),
                photo_rows: tuple[float, float] | None = None) -> DrawnCamera:
    """The camera model of one composite of ``size`` (W, H), written from a photo of ``source_size`` at ``scale``
    (written px per photo px); ``people`` the photo's boxes as (class name, (x0, y0, x1, y1) in written px, not
    clipped to the frame), which place the horizon where :meth:`CameraSettings.people_heights` gives their class a
    height and one is whole in the photo, whose top and bottom edges are the written rows ``photo_rows`` (None: the
    frame's). Its three ranges are always drawn, in one order, used or not."""
    width, height = size
    horizon_share = float(rng.uniform(*settings.horizon_row_share))
    height_m = float(rng.uniform(*settings.height_m))
    focal_share = float(rng.uniform(*settings.focal_width_share))
    if settings.use_exif and exif_focal_35mm:
        focal = focal_px_from_35mm(exif_focal_35mm, *source_size) * scale
        focal_source = "exif"
    else:
        focal, focal_source = focal_share * max(width, height), sources["focal_width_share"]
    if settings.pitch_deg is not None:
        camera = PhotoCamera.from_pitch(width, height, settings.pitch_deg, height_m, focal)
        horizon_source = f"pitch_deg:{sources['pitch_deg']}"
    else:
        camera = PhotoCamera(width, height, horizon_share * height, height_m, focal)
        horizon_source = sources["horizon_row_share"]
    heights = settings.people_heights()     # none where a known pitch wins: a measured camera over an estimate
    found = horizon_from_people([(box, heights[name]) for name, box in people if name in heights],
                                photo_rows or (0.0, float(height)), height_m) if heights else None
    if found is not None:
        camera = PhotoCamera(width, height, found[0], height_m, focal)
        said = dict.fromkeys(sources[n] for n in PEOPLE_HEIGHTS if getattr(settings, n) is not None)
        horizon_source = f"people:{found[1]}:{'+'.join(said)}"
    return DrawnCamera(camera, {"horizon_row_px": horizon_source, "height_m": sources["height_m"],
                                "focal_px": focal_source}, settings.light,
                       None if not exif_focal_35mm else float(exif_focal_35mm))


@dataclass(frozen=True)
class Placement:
    """One planned paste. ``anchor_px`` (x, y) is where the cut-out's anchor lands (written px, continuous:
    pixel centres at + 0.5); a cut-out point (u, v) lands at ``anchor_px + scale * ((u, v) - entry.anchor)``.
    ``box`` (x0, y0, x1, y1) is its group's amodal box in the frame. ``share`` the group's height over the
    frame's as placed, ``share_drawn`` as drawn; ``distance_m`` and ``elevation_deg`` of the anchor on the photo's
    ground plane, ``cutout_elevation_deg`` the cut-out's own; ``blend`` the mode and its parameter
    (``feather_px`` or ``sigma_px``); ``order`` 0 is drawn first (the farthest); ``sharpen`` the unsharp mask's
    ``amount`` and ``sigma_px``, None where the paste is not sharpened."""

    entry_id: str
    kind: str
    anchor_px: tuple[float, float]
    scale: float
    share: float
    share_drawn: float
    distance_m: float
    elevation_deg: float
    cutout_elevation_deg: float
    light_distance: float | None
    box: tuple[float, float, float, float]
    overlap: float
    blend: dict
    shadow_strength: float
    order: int
    sharpen: dict | None = None

    def to_dict(self) -> dict:
        out = asdict(self)
        out["anchor_px"], out["box"] = list(self.anchor_px), list(self.box)
        return out


def _box_in_frame(entry: BankEntry, anchor: tuple[float, float], scale: float) -> tuple[float, float, float, float]:
    x0, y0, x1, y1 = entry.group_box()
    ax, ay = entry.anchor
    return (anchor[0] + scale * (x0 - ax), anchor[1] + scale * (y0 - ay),
            anchor[0] + scale * (x1 - ax), anchor[1] + scale * (y1 - ay))


def covered_share(box, by) -> float:
    """The share of ``box``'s area (x0, y0, x1, y1) that ``by`` covers (0 for an empty box)."""
    area = max(0.0, box[2] - box[0]) * max(0.0, box[3] - box[1])
    w = max(0.0, min(box[2], by[2]) - max(box[0], by[0]))
    h = max(0.0, min(box[3], by[3]) - max(box[1], by[1]))
    return w * h / area if area > 0 else 0.0


def _draw_order(planned: dict) -> tuple[float, int]:
    """A planned paste's place in drawing order: far to near by anchor row, then in the order planned."""
    return planned["anchor_px"][1], planned["k"]


def _drawn_first(key: tuple[float, int], planned: dict) -> bool:
    """Whether a paste of drawing-order ``key`` is drawn before (behind) the ``planned`` one."""
    return key < _draw_order(planned)


def _hidden(box, box_seen, earlier) -> list[float]:
    """Of a paste's ``box`` (``box_seen``: as overlap measures it) and each earlier paste's (box as measured,
    whether the new one stands behind it), the share of the farther box that the nearer one covers."""
    return [covered_share(box_seen, e) if behind else covered_share(e, box) for e, behind in earlier]


def _rank(candidates: Sequence[BankEntry], elevation: float, light: Light | None, tolerance: float):
    """(score, entry id, entry) of each candidate, best first (ties by id: the order never depends on the bank's
    listing)."""
    def score(e: BankEntry) -> float:
        s = abs(e.camera.elevation_deg - elevation) / tolerance
        return s + (light.distance(e.light) if light is not None else 0.0)
    return sorted(((score(e), e.id, e) for e in candidates), key=lambda t: t[:2])


def _blend(config: CompositeConfig, poisson_used: bool, rng: np.random.Generator) -> dict:
    weights = config.blend.weights
    if poisson_used:
        weights = dict(weights, poisson=0.0)
    total = sum(weights.values())
    mode = "hard" if total <= 0 else BLEND_MODES[int(np.searchsorted(
        np.cumsum([weights[m] / total for m in BLEND_MODES]), rng.random(), side="right").clip(0, 3))]
    value = float(rng.uniform(*(config.blend.feather_px if mode == "feather" else config.blend.blur_sigma_px)))
    return {"mode": mode, **({"feather_px": value} if mode == "feather" else {"sigma_px": value} if mode == "blur"
                             else {})}


def _sharpen(config: CompositeConfig, rng: np.random.Generator | None) -> dict | None:
    """The unsharp mask of one paste (``amount``, ``sigma_px``), or None (always None without ``rng``)."""
    settings = config.sharpen
    if rng is None:
        return None
    u, amount, sigma = rng.random(), float(rng.uniform(*settings.amount)), float(rng.uniform(*settings.sigma_px))
    return {"amount": amount, "sigma_px": sigma} if u < settings.share else None


def eligible(entries: Sequence[BankEntry], config: CompositeConfig) -> dict[str, list[BankEntry]]:
    """The bank's cut-outs the config lets a composite paste, by kind (``aid_user``, ``pedestrian``)."""
    out: dict[str, list[BankEntry]] = {"aid_user": [], "pedestrian": []}
    for e in entries:
        if e.kind == "aid_user" and ((config.pastes.aids is not None and e.aid not in config.pastes.aids)
                                     or (config.pastes.groups is not None and e.group not in config.pastes.groups)):
            continue
        out[e.kind].append(e)
    return out


def plan_pastes(drawn: DrawnCamera, pools: dict[str, list[BankEntry]], config: CompositeConfig,
                background_boxes: Sequence[tuple[float, float, float, float]],
                rng: np.random.Generator, visible_overlap: bool = True,
                overlap_by_depth: bool = True) -> list[Placement]:
    """The pastes of one composite (see the module docstring), sorted far to near with their ``order``.
    ``background_boxes`` (x0, y0, x1, y1, written px) are the labelled boxes a paste should not cover.
    ``visible_overlap`` and ``overlap_by_depth`` False give the overlap measures of earlier jobs (step 4)."""
    camera, settings = drawn.camera, config.pastes
    frame_w, frame_h = camera.width_px, camera.height_px

    def seen(box):      # an earlier paste's box as overlap measures it
        if not visible_overlap:
            return box
        return (max(box[0], 0.0), max(box[1], 0.0), min(box[2], float(frame_w)), min(box[3], float(frame_h)))

    cover = (config.background_labels.drop_covered_share if settings.max_background_cover is None
             else settings.max_background_cover)
    count = int(rng.integers(settings.per_image[0], settings.per_image[1] + 1))
    planned: list[dict] = []
    poisson_used = False
    sharpen_rng = rng.spawn(1)[0] if config.sharpen.on else None
    for k in range(count):
        kinds = [kind for kind in ("aid_user", "pedestrian") if pools.get(kind)]
        draw_kind, share_drawn = rng.random(), float(rng.uniform(*settings.height_share))
        if not kinds:
            break
        if len(kinds) == 1:
            kind = kinds[0]
        elif k == 0 and settings.at_least_one_aid_user:
            kind = "aid_user"
        else:
            kind = "aid_user" if draw_kind < settings.aid_user_share else "pedestrian"
        pool = pools[kind]
        nominal = median(e.subject_height_m for e in pool)
        lowest = camera.lowest_anchor_row()
        if lowest - camera.horizon_row_px < MIN_DROP_PX:
            break  # the horizon lies below the image: no ground to stand on
        largest = camera.pixel_height(nominal, lowest) / frame_h
        share = min(share_drawn, largest)
        anchor_row = max(camera.anchor_row(nominal, share * frame_h), camera.horizon_row_px + MIN_DROP_PX)
        elevation = camera.elevation_deg(anchor_row)
        ranked = _rank(pool, elevation, drawn.light, settings.elevation_tolerance_deg)
        _, _, entry = ranked[int(rng.integers(min(settings.choose_among, len(ranked))))]
        anchor_row = min(lowest, max(camera.anchor_row(entry.subject_height_m, share * frame_h),
                                     camera.horizon_row_px + MIN_DROP_PX))
        scale = (anchor_row - camera.horizon_row_px) / (camera.height_m * entry.scale_px_per_m)
        x0, _, x1, _ = entry.group_box()
        beyond = settings.edge_cut * scale * (x1 - x0)
        lo = -scale * (x0 - entry.anchor[0]) - beyond
        hi = frame_w - scale * (x1 - entry.anchor[0]) + beyond
        columns = rng.uniform(0.0, 1.0, settings.placement_tries)
        blend = _blend(config, poisson_used, rng)
        shadow = float(rng.uniform(*config.shadow_strength))
        sharpen = _sharpen(config, sharpen_rng)
        if lo > hi:
            continue  # wider than the frame (and edge_cut) allows at this size
        best: tuple[float, tuple[float, float], tuple[float, float, float, float]] | None = None
        # each earlier paste's box in view, and whether this paste stands behind it (drawn first, by the key the
        # plan is sorted by below)
        earlier = [(seen(p["box"]), overlap_by_depth and _drawn_first((anchor_row, k), p)) for p in planned]
        for c in columns:
            anchor = (float(lo + c * (hi - lo)), float(anchor_row))
            box = _box_in_frame(entry, anchor, scale)
            excess = max([hidden - settings.max_overlap for hidden in _hidden(box, seen(box), earlier)]
                         + [covered_share(b, box) - cover for b in background_boxes] + [0.0])
            if best is None or excess < best[0]:
                best = (excess, anchor, box)
            if excess <= 0:
                break
        assert best is not None  # placement_tries >= 1 (the schema)
        excess, anchor, box = best
        if excess > 0 and settings.when_no_room == "skip":
            continue
        poisson_used |= blend["mode"] == "poisson"
        overlap = max(_hidden(box, seen(box), earlier) + [0.0])
        planned.append(dict(
            entry_id=entry.id, kind=kind, anchor_px=anchor, scale=float(scale),
            share=float(camera.pixel_height(entry.subject_height_m, anchor_row) / frame_h), share_drawn=share_drawn,
            distance_m=camera.distance_m(anchor_row), elevation_deg=camera.elevation_deg(anchor_row),
            cutout_elevation_deg=entry.camera.elevation_deg,
            light_distance=None if drawn.light is None else drawn.light.distance(entry.light),
            box=tuple(float(v) for v in box), overlap=float(overlap), blend=blend, shadow_strength=shadow,
            sharpen=sharpen, k=k))
    planned.sort(key=_draw_order)
    return [Placement(**{key: v for key, v in p.items() if key != "k"}, order=n) for n, p in enumerate(planned)]

