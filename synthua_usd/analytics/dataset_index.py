"""What analytics reads of a generated dataset: the manifest (which images, their split and QA verdict),
the dataset's class map and each image's record (``records/{name}.json``: condition, camera rig, class pixel
counts, instances with areas, occlusion and relations, panoptic segments). No image file is opened here: the
records hold every count the statistics need. Images rejected by QA are left out, as every training format
leaves them out.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.core.schemas import read_json
from synthua_usd.dataset.annotations import CROWD_ID_BASE, STUFF_ID_BASE
from synthua_usd.dataset.layout import Layout
from synthua_usd.dataset.manifest import read_manifest
from synthua_usd.dataset.qa import AidUser, aid_users
from synthua_usd.dataset.record import ImageRecord
from synthua_usd.model.taxonomy import ClassMap


@dataclass(frozen=True)
class ImageSummary:
    """One image as the statistics see it.

    ``class_pixels``: class name -> visible pixels (``unlabelled`` included); ``segments``: (class id, area in
    pixels) of each object: every visible thing instance (those too small to annotate included, which panoptic
    merges into one crowd segment per class) and each stuff class present (its panoptic segment);
    ``aid_users``: the image's mobility-aid users (:func:`synthua_usd.dataset.qa.aid_users`)."""

    id: int
    name: str
    split: str
    condition: str
    rig_type: str
    width: int
    height: int
    verdict: str
    class_pixels: dict[str, int]
    segments: tuple[tuple[int, int], ...]
    aid_users: tuple[AidUser, ...] = field(default=())
    camera_path: str = ""
    time_code: float = 0.0
    seed: int = 0
    #: Prim paths of the instances the image shows.
    visible: tuple[str, ...] = field(default=())
    #: What scene randomisation drew for the image (its record's ``randomisation``), or None.
    randomisation: dict | None = field(default=None, repr=False)

    @property
    def rgb(self) -> str:
        """Relative path of the RGB image."""
        return Layout.rgb_png(self.split, self.name)

    @property
    def class_png(self) -> str:
        """Relative path of the 8-bit class-id map."""
        return Layout.frame_file(self.name, "class")


@dataclass(frozen=True)
class DatasetIndex:
    root: Path
    class_map: ClassMap
    images: tuple[ImageSummary, ...]
    rejected: int


def image_file(root: Path, img: ImageSummary, relative: str) -> Path:
    """``root / relative``: a file of image ``img`` (its :attr:`~ImageSummary.rgb` or
    :attr:`~ImageSummary.class_png`); a missing one raises :class:`InputError`."""
    path = Path(root) / relative
    if not path.is_file():
        raise InputError(f"{shown(path)}: file not found; expected the image of record {img.name} "
                         f"(run `synthua verify {shown(root)}`)")
    return path


def load_class_map(root: Path) -> ClassMap:
    """The dataset's own class map (``class_map.json``): the ids its label maps use."""
    return ClassMap.load(Layout(root).path(Layout.CLASS_MAP))


def manifest_images(root: Path) -> list[dict]:
    """The manifest's image entries (``id``, ``name``, ``split``, ``qa``, ...); a folder without a manifest is
    refused (the manifest is written last: without it the dataset is incomplete)."""
    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{shown(root)}: not a folder; expected a dataset folder written by `synthua generate`")
    return read_manifest(root / Layout.MANIFEST)["images"]


def _objects(record: ImageRecord) -> tuple[tuple[int, int], ...]:
    """(class id, area) of the record's visible thing instances and of its stuff segments (panoptic ids from
    STUFF_ID_BASE up to CROWD_ID_BASE)."""
    things = [(int(i["category_id"]), int(i["area"])) for i in record.get("instances", ())
              if i.get("isthing") and i.get("area", 0) > 0]
    stuff = [(int(s["category_id"]), int(s["area"])) for s in record["panoptic_segments"]
             if STUFF_ID_BASE <= int(s["id"]) < CROWD_ID_BASE]
    return tuple(things + stuff)


def _summary(record: ImageRecord, verdict: str, where: str) -> ImageSummary:
    try:
        camera = record.get("camera") or {}
        condition = (record.get("condition") or {}).get("name") or "stage"
        return ImageSummary(
            id=int(record["id"]), name=str(record["name"]), split=str(record["split"]), condition=str(condition),
            rig_type=str(camera.get("rig_type") or "none"), width=int(record["width"]), height=int(record["height"]),
            verdict=verdict, class_pixels={str(k): int(v) for k, v in record["class_pixel_counts"].items()},
            segments=_objects(record),
            aid_users=tuple(aid_users(record.get("instances", ()))), camera_path=str(camera.get("prim_path", "")),
            time_code=float(record.get("time_code", 0.0)), seed=int(record.get("seed", 0)),
            visible=tuple(str(i["prim_path"]) for i in record.get("instances", ()) if i.get("area", 0) > 0),
            randomisation=record.get("randomisation") if isinstance(record.get("randomisation"), dict) else None)
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"{where}: {type(exc).__name__} {exc}; expected an image record written by "
                         f"`synthua generate`") from None


def load_index(root: str | Path) -> DatasetIndex:
    """Manifest, class map and the records of every image not rejected by QA, by image id."""
    root = Path(root)
    layout = Layout(root)
    entries = manifest_images(root)
    class_map = load_class_map(root)
    images, rejected = [], 0
    for entry in entries:
        verdict = str(entry.get("qa", "accepted"))
        if verdict == "rejected":
            rejected += 1
            continue
        path = layout.path(Layout.record(str(entry["name"])))
        images.append(_summary(read_json(path, "an image record"), verdict, shown(path)))
    images.sort(key=lambda i: i.id)
    return DatasetIndex(root=root, class_map=class_map, images=tuple(images), rejected=rejected)
