"""A bank of cut-outs (``synthua cutouts --out BANK``, format ``synthua-cutouts/1``) as ``synthua composite`` reads it.

The format is fixed by the bank's specification (docs/compositing.md, "The bank"): ``BANK/bank.json`` lists the
bank's class map, its cut-outs and every other file with its size and SHA-256; each cut-out has four images of one
size under ``cutouts/``: ``rgba`` (8-bit sRGB, straight alpha = coverage), ``ids`` (8-bit instance index at each
pixel centre, 0 none), ``amodal`` (16-bit bit field, bit k-1 = instance k on the pixel centre's ray at any depth)
and ``shadow`` (8-bit, 255 x light received with the group / without). Crop pixel coordinates have (0, 0) at the
crop's top-left corner and pixel centres at integer + 0.5.

:func:`read_bank` reads and checks ``bank.json`` (plain data, no image is opened); :func:`check_bank_files` checks
every listed file's size and SHA-256. Anything that is not a bank of this format raises :class:`InputError`, one
line naming the file and the field.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import NoReturn

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import read_json
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES
from synthua_usd.model.taxonomy import ClassMap

#: The one format this version reads.
BANK_FORMAT = "synthua-cutouts/1"
BANK_FILE = "bank.json"
FILE_KEYS = ("rgba", "ids", "amodal", "shadow")
KINDS = ("aid_user", "pedestrian")
GROUPS = ("alone", "pushed", "accompanied")
ROLES = ("user", "device", "pusher", "companion", "pedestrian")
#: The amodal bit field is 16 bits: at most 16 instances a cut-out.
MAX_INSTANCES = 16
_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,63}$")


@dataclass(frozen=True)
class Light:
    """Light of a cut-out or of a photo: ``overcast`` 0 (clear sun) .. 1 (no sun); the sun's elevation and its
    azimuth relative to the camera's viewing direction (0: behind the camera, 180: against the light), degrees."""

    overcast: float
    sun_elevation_deg: float = 45.0
    sun_azimuth_deg: float = 0.0

    def distance(self, other: "Light") -> float:
        """How unalike two lights are, 0..2: the difference of overcast, plus the angle between the two suns
        (over 90 degrees) weighted by how much sun both have."""
        a, b = _sun_vector(self), _sun_vector(other)
        cross = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
        angle = math.degrees(math.atan2(math.hypot(*cross), sum(x * y for x, y in zip(a, b))))
        return abs(self.overcast - other.overcast) + (1.0 - max(self.overcast, other.overcast)) * angle / 90.0


def _sun_vector(light: Light) -> tuple[float, float, float]:
    el, az = math.radians(light.sun_elevation_deg), math.radians(light.sun_azimuth_deg)
    return math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)


@dataclass(frozen=True)
class BankInstance:
    """One instance of a cut-out: its ``index`` in ``ids.png`` (1..16), class, role, relations (name, index of the
    other instance), visible and amodal boxes and areas (crop px, [x, y, w, h]) and keypoints ((x, y, v), crop px,
    v 0 not labelled, 1 occluded, 2 visible) when its class has them."""

    index: int
    class_name: str
    role: str
    relations: tuple[tuple[str, int], ...]
    bbox: tuple[float, float, float, float]
    area: int
    amodal_bbox: tuple[float, float, float, float]
    amodal_area: int
    keypoints: tuple[tuple[float, float, int], ...] | None


@dataclass(frozen=True)
class BankCamera:
    """The camera a cut-out was rendered with: height above the ground (m), pitch (negative looks down), focal
    length (px of the full frame), ground distance to the anchor (m), elevation of the camera seen from the
    anchor (degrees)."""

    height_m: float
    pitch_deg: float
    focal_px: float
    distance_m: float
    elevation_deg: float


@dataclass(frozen=True)
class BankEntry:
    """One cut-out: ``files`` by key (:data:`FILE_KEYS`, paths relative to the bank), crop ``size`` (W, H),
    ``kind`` (:data:`KINDS`), ``group`` (:data:`GROUPS`), ``aid`` (the aid class, None for pedestrians), its
    instances, ``ground_points`` and ``anchor`` (crop px), ``subject_height_m`` (the group's highest point above the
    ground), the rendering camera, ``scale_px_per_m`` (pixels per metre of height at the anchor), its light."""

    id: str
    files: dict
    size: tuple[int, int]
    kind: str
    group: str
    aid: str | None
    instances: tuple[BankInstance, ...]
    ground_points: tuple[tuple[float, float], ...]
    anchor: tuple[float, float]
    subject_height_m: float
    camera: BankCamera
    scale_px_per_m: float
    light: Light
    seed: int

    def group_box(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1), crop px: the union of the instances' amodal boxes."""
        boxes = [i.amodal_bbox for i in self.instances]
        return (min(b[0] for b in boxes), min(b[1] for b in boxes), max(b[0] + b[2] for b in boxes),
                max(b[1] + b[3] for b in boxes))


@dataclass(frozen=True)
class Bank:
    """A bank read from ``root``: its id (SHA-256 of ``bank.json``), class map, cut-outs and file entries."""

    root: Path
    id: str
    class_map: ClassMap
    entries: tuple[BankEntry, ...]
    files: tuple[dict, ...]

    def entry(self, entry_id: str) -> BankEntry:
        for e in self.entries:
            if e.id == entry_id:
                return e
        raise InputError(f"{shown(self.root / BANK_FILE)}: no cut-out {echo(entry_id)!r}; expected one of its ids")


class _Reader:
    """Checks one ``bank.json`` document field by field; every failure names the file and the field."""

    def __init__(self, path: Path, class_map: ClassMap):
        self.where, self.class_map = shown(path), class_map

    def fail(self, field: str, found, expected: str) -> NoReturn:
        raise InputError(f"{self.where}: {field}: {echo(str(found))}; expected {expected}")

    def number(self, doc, key: str, field: str, positive: bool = False) -> float:
        value = doc.get(key) if isinstance(doc, dict) else None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                or (positive and value <= 0):
            self.fail(f"{field}.{key}", value, "a finite number" + (" > 0" if positive else ""))
        return float(value)

    def pixels(self, doc: dict, key: str, field: str) -> int:
        value = doc.get(key)
        if not isinstance(value, int) or isinstance(value, bool) or value < 0:
            self.fail(f"{field}.{key}", value, "a pixel count >= 0")
        return value

    def point(self, value, field: str) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2 or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value):
            self.fail(field, value, "[x, y], two finite numbers (crop pixels)")
        return float(value[0]), float(value[1])

    def box(self, value, field: str) -> tuple[float, float, float, float]:
        if not isinstance(value, list) or len(value) != 4 or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value) \
                or value[2] < 0 or value[3] < 0:
            self.fail(field, value, "[x, y, w, h], finite numbers with w, h >= 0 (crop pixels)")
        x, y, w, h = (float(v) for v in value)
        return x, y, w, h

    def instance(self, doc, field: str, count: int) -> BankInstance:
        if not isinstance(doc, dict):
            self.fail(field, doc, "an object")
        index = doc.get("index")
        if not isinstance(index, int) or isinstance(index, bool) or not 1 <= index <= MAX_INSTANCES:
            self.fail(f"{field}.index", index, f"an integer in 1..{MAX_INSTANCES}")
        name = doc.get("class_name")
        known = {c.name for c in self.class_map.classes if c.isthing}
        if name not in known:
            self.fail(f"{field}.class_name", name, "a thing class of the bank's class_map")
        if doc.get("role") not in ROLES:
            self.fail(f"{field}.role", doc.get("role"), f"one of {', '.join(ROLES)}")
        relations = doc.get("relations", {})
        if not isinstance(relations, dict) or not all(
                isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= count for v in relations.values()):
            self.fail(f"{field}.relations", relations, f"an object of relation -> instance index (1..{count})")
        keypoints = doc.get("keypoints")
        if keypoints is not None:
            expected = len(KEYPOINT_CLASSES[name].names) if name in KEYPOINT_CLASSES else 0
            if not isinstance(keypoints, list) or len(keypoints) != expected or not all(
                    isinstance(k, list) and len(k) == 3 and k[2] in (0, 1, 2)
                    and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in k)
                    for k in keypoints):
                self.fail(f"{field}.keypoints", f"{type(keypoints).__name__} of {len(keypoints) if isinstance(keypoints, list) else 0}",
                          f"null or {expected} keypoints [x, y, v] (v 0, 1 or 2) for class {name}")
            keypoints = tuple((float(x), float(y), int(v)) for x, y, v in keypoints)
        area, amodal_area = self.pixels(doc, "area", field), self.pixels(doc, "amodal_area", field)
        return BankInstance(index, name, doc["role"], tuple(sorted(relations.items())),
                            self.box(doc.get("bbox"), f"{field}.bbox"), area,
                            self.box(doc.get("amodal_bbox"), f"{field}.amodal_bbox"), amodal_area, keypoints)

    def entry(self, doc, field: str, listed: set[str]) -> BankEntry:
        if not isinstance(doc, dict):
            self.fail(field, doc, "a cut-out object")
        entry_id = doc.get("id")
        if not isinstance(entry_id, str) or not _ID.match(entry_id):
            self.fail(f"{field}.id", entry_id, "letters, digits, '_' and '-' (at most 64)")
        files = doc.get("files")
        if not isinstance(files, dict) or sorted(files) != sorted(FILE_KEYS):
            self.fail(f"{field}.files", files, f"an object with {', '.join(FILE_KEYS)}")
        for key in FILE_KEYS:
            if files[key] not in listed:
                self.fail(f"{field}.files.{key}", files[key], "a file listed in the bank's files")
        size = doc.get("size")
        if not isinstance(size, list) or len(size) != 2 or not all(
                isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 16384 for v in size):
            self.fail(f"{field}.size", size, "[W, H], whole numbers in 1..16384")
        if doc.get("kind") not in KINDS:
            self.fail(f"{field}.kind", doc.get("kind"), f"one of {', '.join(KINDS)}")
        if doc.get("group") not in GROUPS:
            self.fail(f"{field}.group", doc.get("group"), f"one of {', '.join(GROUPS)}")
        raw = doc.get("instances")
        if not isinstance(raw, list) or not 1 <= len(raw) <= MAX_INSTANCES:
            self.fail(f"{field}.instances", raw, f"1..{MAX_INSTANCES} instances")
        instances = tuple(self.instance(d, f"{field}.instances[{k}]", len(raw)) for k, d in enumerate(raw))
        if sorted(i.index for i in instances) != list(range(1, len(instances) + 1)):
            self.fail(f"{field}.instances", [i.index for i in instances], f"indices 1..{len(instances)}, each once")
        aid = doc.get("aid")
        if doc["kind"] == "aid_user" and aid not in {i.class_name for i in instances}:
            self.fail(f"{field}.aid", aid, "the class of one of the cut-out's instances (an aid user's aid)")
        if doc["kind"] == "pedestrian" and aid is not None:
            self.fail(f"{field}.aid", aid, "null for a pedestrian")
        ground = doc.get("ground_points")
        if not isinstance(ground, list):
            self.fail(f"{field}.ground_points", ground, "a list of [x, y]")
        camera = doc.get("camera")
        if not isinstance(camera, dict):
            self.fail(f"{field}.camera", camera, "the rendering camera's object")
        light = doc.get("light")
        if not isinstance(light, dict):
            self.fail(f"{field}.light", light, "the light's object")
        overcast = self.number(light, "overcast", f"{field}.light")
        if not 0 <= overcast <= 1:
            self.fail(f"{field}.light.overcast", overcast, "a number in [0, 1]")
        seed = doc.get("seed", 0)
        if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
            self.fail(f"{field}.seed", seed, "an integer >= 0")
        elevation = self.number(camera, "elevation_deg", f"{field}.camera")
        if not 0 < elevation < 90:
            self.fail(f"{field}.camera.elevation_deg", elevation, "an angle in (0, 90) degrees")
        return BankEntry(
            id=entry_id, files=dict(files), size=(size[0], size[1]), kind=doc["kind"], group=doc["group"], aid=aid,
            instances=instances, ground_points=tuple(self.point(p, f"{field}.ground_points[{k}]")
                                                     for k, p in enumerate(ground)),
            anchor=self.point(doc.get("anchor"), f"{field}.anchor"),
            subject_height_m=self.number(doc, "subject_height_m", field, positive=True),
            camera=BankCamera(self.number(camera, "height_m", f"{field}.camera", positive=True),
                              self.number(camera, "pitch_deg", f"{field}.camera"),
                              self.number(camera, "focal_px", f"{field}.camera", positive=True),
                              self.number(camera, "distance_m", f"{field}.camera", positive=True), elevation),
            scale_px_per_m=self.number(doc, "scale_px_per_m", field, positive=True),
            light=Light(overcast, self.number(light, "sun_elevation_deg", f"{field}.light"),
                        self.number(light, "sun_azimuth_deg", f"{field}.light")),
            seed=seed)


def read_bank(root: str | Path) -> Bank:
    """The bank at ``root`` (its ``bank.json`` read and checked; the files are checked by
    :func:`check_bank_files`)."""
    from synthua_usd.dataset.manifest import sha256_file

    root = Path(root)
    path = root / BANK_FILE
    if not root.is_dir() or not path.is_file():
        raise InputError(f"{shown(root)}: {'not a folder' if not root.is_dir() else 'no bank.json'}; expected a bank "
                         f"of cut-outs written by `synthua cutouts`")
    doc = read_json(path, "a bank's bank.json")
    where = shown(path)
    if not isinstance(doc, dict):
        raise InputError(f"{where}: {type(doc).__name__}; expected the bank's object")
    if doc.get("format") != BANK_FORMAT:
        raise InputError(f"{where}: format: {echo(str(doc.get('format')))!r}; expected {BANK_FORMAT!r} (a bank made by "
                         f"another version of synthua: make it again with `synthua cutouts`)")
    class_map = ClassMap.from_document(doc.get("class_map", {}), source=f"{where}: class_map")
    reader = _Reader(path, class_map)
    files = doc.get("files")
    if not isinstance(files, list) or not all(
            isinstance(f, dict) and isinstance(f.get("path"), str) and isinstance(f.get("bytes"), int)
            and isinstance(f.get("sha256"), str) and re.fullmatch(r"[0-9a-f]{64}", f["sha256"]) for f in files):
        reader.fail("files", str(files)[:80], "a list of {path, bytes, sha256}")
    for n, entry in enumerate(files):
        parts = Path(entry["path"]).parts
        if Path(entry["path"]).is_absolute() or ".." in parts or not parts:
            reader.fail(f"files[{n}].path", entry["path"], "a path inside the bank folder")
    raw = doc.get("cutouts")
    if not isinstance(raw, list) or not raw:
        reader.fail("cutouts", str(raw)[:80], "a list of at least one cut-out")
    listed = {f["path"] for f in files}
    entries = tuple(reader.entry(d, f"cutouts[{k}]", listed) for k, d in enumerate(raw))
    ids = [e.id for e in entries]
    if len(set(ids)) != len(ids):
        reader.fail("cutouts", "duplicate ids", "each cut-out id once")
    return Bank(root=root, id=sha256_file(path), class_map=class_map, entries=entries, files=tuple(files))


def check_bank_files(bank: Bank) -> None:
    """Every file ``bank.json`` lists is there with its size and SHA-256; the first that is not raises
    :class:`InputError` naming it."""
    from synthua_usd.dataset.manifest import sha256_file

    for entry in bank.files:
        path = bank.root / entry["path"]
        if not path.is_file():
            raise InputError(f"{shown(path)}: file not found; expected the bank file bank.json lists")
        size = path.stat().st_size
        if size != entry["bytes"]:
            raise InputError(f"{shown(path)}: {size} bytes; expected {entry['bytes']} as bank.json lists (truncated or "
                             f"replaced: make the bank again)")
        if sha256_file(path) != entry["sha256"]:
            raise InputError(f"{shown(path)}: SHA-256 differs from bank.json's; expected the file as the bank wrote "
                             f"it (altered: make the bank again)")
