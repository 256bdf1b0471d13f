"""``synthua cutouts``: a bank of cut-outs of aid users (every aid; alone, pushed, accompanied) and pedestrians,
rendered from USD layers like everything else, for ``synthua composite`` to paste into photos.

Each group (:mod:`synthua_usd.randomisation.cutouts`) is authored into a :class:`~synthua_usd.usd.studio.Studio`
once and seen from ``views_per_group`` cameras and lights; per view one label pass gives the exact instance ids of
every pixel centre and the amodal masks (as a dataset image's), the path tracer the group's colour and coverage
(:func:`~synthua_usd.backends.mitsuba.cutout_passes.render_rgba`), shadow rays the shadow it casts on the ground
(:func:`~synthua_usd.backends.mitsuba.cutout_passes.ground_shadow`) over the frame and the ground around it (a low
sun's shadow goes on beyond the frame; one longer still fades out). The crop holding the group and its shadow (it
may reach beyond the frame: the colour, ids and masks are empty there) is written as four PNGs and an entry of
``bank.json`` (the format: docs/cutouts.md, read by :mod:`synthua_usd.dataset.cutout_bank`): instances with visible
and amodal boxes, keypoints, the ground points, the camera, the light. Groups run on worker processes
(:func:`synthua_usd.pipeline.executors.run_shards`); the bank is written as a set (a staging folder renamed into
place when complete) with a manifest of checksums. The same config gives the same bytes.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from synthua_usd import __version__
from synthua_usd.core.atomic import output_set, write_json_atomic
from synthua_usd.dataset.cutout_bank import BANK_FILE, BANK_FORMAT, FILE_KEYS, MAX_INSTANCES
from synthua_usd.dataset.manifest import file_entry
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.randomisation.cutouts import CutoutsConfig, GroupDraw, draw_group, draw_view

FOLDER = "cutouts"
#: The four images of a cut-out (:data:`~synthua_usd.dataset.cutout_bank.FILE_KEYS`): their file suffixes.
FILES = {key: f"{key}.png" for key in FILE_KEYS}
#: Pixels around the group and its shadow in a crop.
MARGIN_PX = 4
#: A vertex this close to the ground (metres) touches it.
GROUND_TOUCH_M = 0.02
#: Ground farther than this many group heights from the group's box has the whole sky (its occlusion there is a few
#: per cent at most).
SKY_REACH = 1.5
#: The shadow factor below which the ground counts as shadowed (for the crop).
SHADOWED = 0.98
#: The ground around the frame the shadow layer covers, a share of the frame's longer side on each side: a low sun's
#: shadow goes on beyond the frame (cut at the frame's edge, it ended in a straight line where it was pasted).
SHADOW_PAD_SHARE = 0.25
#: A shadow that reaches beyond that fades out over this share of the pad, outermost (no straight edge either).
SHADOW_FADE_SHARE = 0.5


@dataclass(frozen=True)
class CutoutJob:
    """What a worker needs, as plain picklable data: the config, the class map, and the staging folder the
    cut-outs' images are written into."""

    config: CutoutsConfig
    class_map_document: dict
    folder: str


@dataclass
class CutoutSummary:
    """What a run made: the bank folder, its cut-outs (by kind, by aid), seconds."""

    out_dir: Path
    cutouts: int = 0
    groups: int = 0
    by_aid: dict | None = None
    wall_seconds: float = 0.0


class CutoutWorker:
    """One worker's studio, reader and render session (:func:`init_worker`); :meth:`group` renders one group's
    views."""

    def __init__(self, job: CutoutJob) -> None:
        from synthua_usd.assets.postures import shared_body_parts
        from synthua_usd.backends.mitsuba.session import RenderSession
        from synthua_usd.model.render_config import RenderConfig
        from synthua_usd.usd.reader import StageReader
        from synthua_usd.usd.studio import Studio

        self.job = job
        frame = job.config.frame
        self.class_map = ClassMap.from_document(job.class_map_document, source="class map")
        self.studio = Studio(shared_body_parts(), self.class_map.taxonomy, frame.width, frame.height)
        self.reader = StageReader(self.studio.stage, self.class_map)
        self.session = RenderSession(RenderConfig(width=frame.width, height=frame.height, spp=1, denoise=False,
                                                  max_depth=frame.max_depth))

    def group(self, index: int) -> list[dict]:
        """The bank entries of group ``index`` (its files written)."""
        drawn, placements = self.set_group(index)
        config = self.job.config
        views = min(config.views_per_group, config.count - index * config.views_per_group)
        entries = []
        for v in range(views):
            view, light, snapshot, camera, condition = self.set_view(drawn, placements, v)
            seed = (config.seed * 1_000_003 + drawn.index * 101 + v) % (2 ** 31)
            entry = render_cutout(self.session, snapshot, camera, condition, self.studio.cast, drawn, config, seed,
                                  f"g{drawn.index:06d}v{v:02d}", Path(self.job.folder))
            entry["draw"] = {"light": light.to_dict(), "view": asdict(view)}
            entries.append(entry)
        return entries

    def set_group(self, index: int) -> tuple[GroupDraw, tuple]:
        """Author group ``index`` into the studio; its draw and its members' placements."""
        from synthua_usd.randomisation.scene import SceneDraw, draw_unit

        config = self.job.config
        drawn, rng = draw_group(config, index)
        cast, wardrobe = draw_unit(rng, config.randomise, drawn.aid, drawn.group)
        self.studio.set_group(SceneDraw(scene_seed=index, district_seed=None, density_per_m2=None, aid_share=None,
                                        cast=cast, recolours=(), wardrobe=wardrobe))
        return drawn, _placements(rng, cast, drawn)

    def set_view(self, drawn: GroupDraw, placements: tuple, index: int):
        """Author view ``index`` of the studio's group ``drawn``; (view, light draw, snapshot, camera, condition)."""
        from synthua_usd.randomisation.light import draw_light
        from synthua_usd.usd.cameras import read_camera
        from synthua_usd.usd.conditions import read_condition
        from synthua_usd.usd.studio import CAMERA_PATH, TIME_CODE

        config = self.job.config
        view, rng = draw_view(config, drawn.index, index)
        base = read_condition(self.studio.base, view.condition)
        light = draw_light(rng, base, config.randomise.light)
        condition = light.condition(base)
        # first the group where it stands (the camera anywhere) to measure it, then the camera fitted to it
        self.studio.set_view(placements, np.eye(4), 50.0, condition)
        bounds = _bounds(self.reader.snapshot(TIME_CODE))
        camera_to_world, focal_mm = _aim(bounds, drawn.heading_deg, view, config.frame)
        self.studio.set_view(placements, camera_to_world, focal_mm, condition)
        snapshot = self.reader.snapshot(TIME_CODE)
        camera = read_camera(self.studio.stage, CAMERA_PATH, TIME_CODE)
        return view, light, snapshot, camera, read_condition(self.studio.stage, view.condition)


def _placements(rng: np.random.Generator, cast, drawn: GroupDraw) -> tuple:
    """Where each member of the group stands: its aid user (or pedestrian) on the origin facing
    ``drawn.heading_deg``, companions behind or beside it (:func:`~synthua_usd.randomisation.view.companion_offsets`),
    all at one stride phase and pace, standing with :data:`~synthua_usd.randomisation.view.STANDING_SHARE`."""
    from synthua_usd.agents.profiles import PROFILES
    from synthua_usd.randomisation.view import STANDING_SHARE, Placement, companion_offsets

    h = math.radians(drawn.heading_deg)
    ahead, left = np.array([math.cos(h), math.sin(h)]), np.array([-math.sin(h), math.cos(h)])
    phase = float(rng.uniform(0.0, 2 * math.pi))
    amplitude = 0.0 if rng.random() < STANDING_SHARE else 1.0
    speed = PROFILES[cast[0].profile].speed_mps
    placements: list[Placement | None] = [None] * len(cast)
    for k, a, b in companion_offsets(cast, 0):
        xy = a * ahead + b * left
        own = phase if k == 0 else float(rng.uniform(0.0, 2 * math.pi))
        placements[k] = Placement((float(xy[0]), float(xy[1]), 0.0), drawn.heading_deg, own, amplitude, speed, True)
    return tuple(placements)


def _bounds(snapshot) -> np.ndarray:
    """(2, 3) lowest and highest corner of every mesh of ``snapshot`` (world metres)."""
    points = np.concatenate([m.points for m in snapshot.meshes])
    return np.stack([points.min(axis=0), points.max(axis=0)])


def _aim(bounds: np.ndarray, heading_deg: float, view, frame) -> tuple[np.ndarray, float]:
    """The camera of ``view``: ``view.distance_m`` from the group's middle on the ground at ``view.azimuth_deg``
    from its heading, ``view.height_m`` above the ground, aimed at the group's middle; its focal length (mm on the
    studio's 36 mm film) such that the group's box fills ``view.fill`` of the frame's height or width."""
    from synthua_usd.model.cameras import PinholeCamera
    from synthua_usd.model.meshes import look_at
    from synthua_usd.usd.studio import APERTURE_MM

    centre = bounds.mean(axis=0)
    angle = math.radians(heading_deg + view.azimuth_deg)
    eye = np.array([centre[0] + view.distance_m * math.cos(angle), centre[1] + view.distance_m * math.sin(angle),
                    view.height_m])
    camera_to_world = look_at(eye, centre)
    unit = PinholeCamera("/fit", 1.0, APERTURE_MM, APERTURE_MM * frame.height / frame.width, 0.01, 1000.0,
                         camera_to_world)
    corners = np.array([[bounds[i][0], bounds[j][1], bounds[k][2]] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    uv, _ = unit.project(corners, frame.width, frame.height)
    half = np.abs(uv - [frame.width / 2, frame.height / 2]).max(axis=0) / [frame.width / 2, frame.height / 2]
    # the projection scales with the focal length: fill = half-extent x focal / 1 mm
    return camera_to_world, float(view.fill / max(half.max(), 1e-9))


def render_cutout(session, snapshot, camera, condition, cast_prims, drawn: GroupDraw, config: CutoutsConfig,
                  seed: int, entry_id: str, folder: Path) -> dict:
    """Render one view of the studio's group, write its four images into ``folder`` and return its bank entry."""
    from synthua_usd.core import images
    from synthua_usd.backends.exposure import choose_exposure
    from synthua_usd.backends.mitsuba.cutout_passes import ground_light, ground_shadow, render_rgba
    from synthua_usd.dataset import annotations, keypoints

    frame = config.frame
    rendered = session.render(snapshot, camera, rgb=False, condition=condition)
    instance_ids, class_ids, depth = rendered.instance_ids, rendered.class_ids, rendered.hits.z_m
    members = _members(cast_prims, snapshot)
    amodal = session.amodal(snapshot, camera, [m["id"] for m in members])
    entries = {e["id"]: e for e in annotations.annotate(class_ids, instance_ids, snapshot.instances, amodal, {})}
    keypoints.annotate_keypoints(list(entries.values()), snapshot.keypoints, camera, (frame.width, frame.height),
                                 instance_ids, depth)
    rgba = render_rgba(session, camera, frame.spp, seed, frame.denoise)
    light = ground_light(session)
    bounds = _bounds(snapshot)
    # the sky's occlusion matters within about one and a half heights of the group
    reach = float(np.hypot(*(bounds[1, :2] - bounds[0, :2])) / 2 + SKY_REACH * bounds[1, 2])
    pad = shadow_pad(frame.width, frame.height)
    shadow = _faded(ground_shadow(session, camera, light, (*((bounds[0, :2] + bounds[1, :2]) / 2), reach), pad,
                                  bounds), max(1, int(round(SHADOW_FADE_SHARE * pad))))
    exposure = choose_exposure(light.grey_card())
    alpha = rgba[..., 3]
    colour = rgba[..., :3] / np.maximum(alpha, 1e-6)[..., None]
    display = images.linear_to_display(colour * np.float32(exposure.scale))
    alpha8 = np.round(np.clip(alpha, 0.0, 1.0) * 255).astype(np.uint8)
    display[alpha8 == 0] = 0

    index = {m["id"]: k + 1 for k, m in enumerate(members)}
    lut = np.zeros(int(instance_ids.max()) + 1, np.uint8)
    for instance, k in index.items():
        if instance < len(lut):
            lut[instance] = k
    ids = lut[instance_ids]
    bits = np.zeros(instance_ids.shape, np.uint16)
    for instance, k in index.items():
        pixels = np.union1d(amodal.get(instance, np.zeros(0, np.int64)), np.flatnonzero(instance_ids.ravel() == instance))
        bits.reshape(-1)[pixels] |= np.uint16(1 << (k - 1))

    group_box = _box(alpha8 > 0)
    if group_box is None:
        raise RuntimeError(f"cut-out {entry_id}: the group is not in its frame (a bug in aiming the camera)")
    shadow_box = _box(shadow < SHADOWED)      # in the padded grid: frame pixels + pad
    x0, y0, x1, y1 = group_box if shadow_box is None else (
        min(group_box[0], shadow_box[0] - pad), min(group_box[1], shadow_box[1] - pad),
        max(group_box[2], shadow_box[2] - pad), max(group_box[3], shadow_box[3] - pad))
    # frame pixels: the crop may reach beyond the frame (by the shadow alone: the group is inside it)
    x0, y0 = max(-pad, x0 - MARGIN_PX), max(-pad, y0 - MARGIN_PX)
    x1, y1 = min(frame.width + pad, x1 + MARGIN_PX), min(frame.height + pad, y1 + MARGIN_PX)
    files = {key: f"{FOLDER}/{entry_id}.{suffix}" for key, suffix in FILES.items()}
    images.write_rgba_png(folder / files["rgba"], _cut(np.dstack([display, alpha8]), x0, y0, x1, y1))
    images.write_id_png(folder / files["ids"], _cut(ids, x0, y0, x1, y1))
    images.write_id_png(folder / files["amodal"], _cut(bits, x0, y0, x1, y1))
    images.write_id_png(folder / files["shadow"], np.round(np.clip(shadow[y0 + pad:y1 + pad, x0 + pad:x1 + pad], 0, 1)
                                                           * 255).astype(np.uint8))

    instances = []
    for member in members:
        entry = entries.get(member["id"])
        box = _shifted(entry["bbox"], x0, y0) if entry else None
        amodal_box = _box(((bits >> (index[member["id"]] - 1)) & 1).astype(bool))
        found = entry.get("keypoints") if entry else None
        points = None
        if found:
            flat = np.array(found["keypoints"], float).reshape(-1, 3)
            flat[:, 0] -= x0
            flat[:, 1] -= y0
            flat[flat[:, 2] == 0, :2] = 0.0
            points = [[round(float(x), 3), round(float(y), 3), int(v)] for x, y, v in flat]
        instances.append({
            "index": index[member["id"]], "class_name": member["class_name"], "role": member["role"],
            "prim_path": member["prim_path"],
            "relations": {name: index[target] for name, target in member["relations"].items() if target in index},
            "bbox": box or [0.0, 0.0, 0.0, 0.0], "area": int(entry["area"]) if entry else 0,
            "amodal_bbox": [] if amodal_box is None else [float(amodal_box[0] - x0), float(amodal_box[1] - y0),
                                                         float(amodal_box[2] - amodal_box[0]),
                                                         float(amodal_box[3] - amodal_box[1])],
            "amodal_area": int(((bits >> (index[member["id"]] - 1)) & 1).sum()),
            "keypoints": points})

    ground, anchor_world = _ground_points(snapshot, members)
    uv, depths = camera.project(np.vstack([ground, anchor_world[None]]), frame.width, frame.height)
    focal_px = float(camera.intrinsics(frame.width, frame.height)[0, 0])
    eye = camera.origin
    distance = float(np.hypot(*(eye[:2] - anchor_world[:2])))
    forward = camera.axes()[2]
    lighting = session.lighting
    sun_elevation = sun_azimuth = 0.0
    if lighting is not None and lighting.sun_direction is not None:
        sun = np.asarray(lighting.sun_direction, float)
        sun_elevation = math.degrees(math.asin(float(np.clip(sun[2], -1.0, 1.0))))
        # 0: the sun behind the camera (the group lit from the front), 180: against the light
        sun_azimuth = (math.degrees(math.atan2(sun[1], sun[0]) - math.atan2(-forward[1], -forward[0])) + 180) % 360 - 180
    return {
        "id": entry_id, "files": files, "size": [x1 - x0, y1 - y0],
        "kind": "pedestrian" if drawn.aid is None else "aid_user", "group": drawn.group, "aid": drawn.aid,
        "instances": instances,
        "ground_points": [[round(float(u - x0), 3), round(float(v - y0), 3)] for u, v in uv[:-1]],
        "anchor": [round(float(uv[-1][0] - x0), 3), round(float(uv[-1][1] - y0), 3)],
        "subject_height_m": round(float(bounds[1][2]), 4),
        "camera": {"height_m": round(float(eye[2]), 4),
                   "pitch_deg": round(math.degrees(math.asin(float(np.clip(forward[2], -1, 1)))), 3),
                   "focal_px": round(focal_px, 3), "distance_m": round(distance, 4),
                   "elevation_deg": round(math.degrees(math.atan2(float(eye[2]), distance)), 3),
                   "frame": [frame.width, frame.height], "crop_origin": [x0, y0]},
        "scale_px_per_m": round(focal_px / float(depths[-1]), 4),
        "light": {"sun_elevation_deg": round(sun_elevation, 3), "sun_azimuth_deg": round(sun_azimuth, 3),
                  "overcast": round(1.0 - light.sun_lux / max(light.sun_lux + light.sky_lux, 1e-12), 4),
                  "condition": condition.name},
        "exposure": exposure.to_dict(),
        "seed": seed,
    }


def shadow_pad(width: int, height: int) -> int:
    """Pixels of ground on each side of a frame the shadow layer covers: :data:`SHADOW_PAD_SHARE` of its longer
    side, a multiple of 4."""
    return 4 * int(round(SHADOW_PAD_SHARE * max(width, height) / 4))


def _faded(shadow: np.ndarray, fade_px: int) -> np.ndarray:
    """``shadow`` (1: unshadowed) with its darkening faded out linearly over the outermost ``fade_px`` pixels: a
    shadow longer than the layer ends softly, not in a straight line."""
    h, w = shadow.shape
    rows, cols = np.arange(h), np.arange(w)
    to_edge = np.minimum.outer(np.minimum(rows, h - 1 - rows), np.minimum(cols, w - 1 - cols))
    ramp = np.clip((to_edge + 0.5) / fade_px, 0.0, 1.0).astype(np.float32)
    return 1.0 - (1.0 - shadow) * ramp


def _cut(array: np.ndarray, x0: int, y0: int, x1: int, y1: int) -> np.ndarray:
    """``array`` (H, W, ...) of the frame cut to x0..x1, y0..y1 (frame pixels, beyond the frame: zeros)."""
    h, w = array.shape[:2]
    out = np.zeros((y1 - y0, x1 - x0) + array.shape[2:], array.dtype)
    out[max(0, -y0):min(h, y1) - y0, max(0, -x0):min(w, x1) - x0] = array[max(0, y0):min(h, y1), max(0, x0):min(w, x1)]
    return out


def _members(cast_prims, snapshot) -> list[dict]:
    """The group's labelled instances in cast order (person, then its device): id, class, role, relations by
    prim path."""
    by_path = {inst.prim_path: inst for inst in snapshot.instances}
    out = []
    for k, (member, person, device) in enumerate(zip(cast_prims.members, cast_prims.persons, cast_prims.devices)):
        role = ("user" if member.aid is not None else "pusher" if member.pushes is not None
                else "companion" if member.accompanies is not None else "pedestrian")
        for path, kind in ((person, role), (device, "device")):
            inst = by_path.get(path) if path else None
            if inst is not None:
                out.append({"id": inst.id, "class_name": inst.class_name, "role": kind, "prim_path": inst.prim_path,
                            "relations": {name: by_path[target].id for name, target in inst.relations
                                          if target in by_path}})
    if len(out) > MAX_INSTANCES:
        raise ValueError(f"a group of {len(out)} people and devices; a cut-out holds at most {MAX_INSTANCES}")
    return out


def _ground_points(snapshot, members) -> tuple[np.ndarray, np.ndarray]:
    """(k, 3) the lowest point of every mesh of the group that touches the ground (feet, wheels, tips), on the
    ground; and the anchor, the ground point under the middle of the aid user (or pedestrian) and its device."""
    ids = {m["id"] for m in members}
    points = []
    for mesh in snapshot.meshes:
        if mesh.instance_id in ids and len(mesh.points):
            low = mesh.points[int(np.argmin(mesh.points[:, 2]))]
            if low[2] <= GROUND_TOUCH_M:
                points.append([low[0], low[1], 0.0])
    lead = {m["id"] for m in members if m["role"] in ("user", "device", "pedestrian")}
    lead_points = np.concatenate([m.points for m in snapshot.meshes if m.instance_id in lead])
    middle = (lead_points.min(axis=0) + lead_points.max(axis=0)) / 2
    ground = np.array(points, float).reshape(-1, 3)
    return ground, np.array([middle[0], middle[1], 0.0])


def _box(mask: np.ndarray) -> tuple[int, int, int, int] | None:
    """(x0, y0, x1, y1) exclusive bounds of ``mask``'s true pixels, or None."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if not len(rows):
        return None
    return int(cols[0]), int(rows[0]), int(cols[-1]) + 1, int(rows[-1]) + 1


def _shifted(bbox, x0: int, y0: int) -> list[float]:
    return [float(bbox[0] - x0), float(bbox[1] - y0), float(bbox[2]), float(bbox[3])]


def init_worker(job: CutoutJob) -> CutoutWorker:
    return CutoutWorker(job)


def work(worker: CutoutWorker, index: int) -> list[dict]:
    return worker.group(int(index))


def make_bank(config_path: Path, out: Path, workers: int | None = None, class_map_path: Path | None = None,
              show_progress: bool = False) -> CutoutSummary:
    """Render the bank of ``config_path`` into ``out`` (a folder that does not exist, or an empty one): its
    images, then ``bank.json``, as one set."""
    from tqdm import tqdm

    from synthua_usd.core.errors import OutputError
    from synthua_usd.pipeline.executors import cut_shards, run_shards
    from synthua_usd.pipeline.worker_protocol import ExecutorConfig

    started = time.perf_counter()
    config = CutoutsConfig.load(config_path)
    class_map = ClassMap.load_or_bundled(class_map_path)
    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise OutputError(f"{out}: exists and is not an empty folder; expected a new folder for the bank")
    count = workers or config.workers or default_workers()
    entries: list[dict] = []
    with output_set(out) as staging:
        (staging / FOLDER).mkdir()
        job = CutoutJob(config=config, class_map_document=class_map.document(), folder=str(staging))
        groups = list(range(config.groups))
        bar = tqdm(total=config.count, desc="cutouts", unit="cut-out", disable=not show_progress)

        def collect(result) -> None:
            entries.extend(result.value)
            bar.update(len(result.value))

        run_shards(cut_shards(groups, lambda g: g, count, most=4), functools.partial(init_worker, job), work,
                   collect, ExecutorConfig(kind="local", workers=count))
        bar.close()
        entries.sort(key=lambda e: e["id"])
        files = sorted((file_entry(staging, e["files"][key]) for e in entries for key in FILES),
                       key=lambda f: f["path"])
        write_json_atomic(staging / BANK_FILE, {"format": BANK_FORMAT, "synthua": __version__,
                                                "config": config.to_document(), "class_map": class_map.document(),
                                                "cutouts": entries, "files": files}, indent=1)
    by_aid: dict = {}
    for e in entries:
        by_aid[e["aid"] or "pedestrian"] = by_aid.get(e["aid"] or "pedestrian", 0) + 1
    return CutoutSummary(out_dir=out, cutouts=len(entries), groups=config.groups, by_aid=by_aid,
                         wall_seconds=time.perf_counter() - started)


def default_workers() -> int:
    """One worker per two CPUs, at least one: a studio scene is small, so much of a view's time is spent in
    Python (authoring, reading, writing) that a second process overlaps."""
    import os

    return max(1, (os.cpu_count() or 1) // 2)
