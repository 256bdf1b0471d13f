"""What analytics reads of a generated dataset: the manifest (which images, their split and QA verdict),
the dataset's class map and each image's record (``records/{name}.json``, read and validated by
:func:`synthua_usd.dataset.record.read_record`: condition, camera rig, class pixel counts, instances with areas,
occlusion and relations, panoptic segments). No image file is opened here: the records hold every count the
statistics need. Images rejected by QA are left out (:func:`synthua_usd.dataset.manifest.kept_images`), as every
training format leaves them out.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.dataset.annotations import CROWD_ID_BASE, STUFF_ID_BASE
from synthua_usd.dataset.layout import Layout
from synthua_usd.dataset.manifest import Manifest, kept_images, read_manifest
from synthua_usd.dataset.qa import AidUser, aid_users
from synthua_usd.dataset.record import DatasetRecord, read_record
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


def dataset_manifest(root: Path) -> Manifest:
    """The manifest of the dataset at ``root`` (:func:`synthua_usd.dataset.manifest.read_manifest`); a folder without
    one is refused (the manifest is written last: without it the dataset is incomplete)."""
    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{shown(root)}: not a folder; expected a dataset folder written by `synthua generate`")
    return read_manifest(root / Layout.MANIFEST)


def _objects(record: DatasetRecord) -> tuple[tuple[int, int], ...]:
    """(class id, area) of the record's visible thing instances and of its stuff segments (panoptic ids from
    STUFF_ID_BASE up to CROWD_ID_BASE)."""
    things = [(i["category_id"], i["area"]) for i in record["instances"] if i["isthing"] and i["area"] > 0]
    stuff = [(s["category_id"], s["area"]) for s in record["panoptic_segments"]
             if STUFF_ID_BASE <= s["id"] < CROWD_ID_BASE]
    return tuple(things + stuff)


def _summary(record: DatasetRecord) -> ImageSummary:
    """What the statistics see of one record; a composite has no condition, rig, camera prim or time code (its
    photo's), and counts as ``stage`` and ``none``."""
    if "composite" in record:
        condition, rig_type, camera_path, time_code, randomisation = "stage", "none", "", 0.0, None
    else:
        condition = record["condition"]["name"] if record["condition"] else "stage"
        rig_type, camera_path = record["camera"]["rig_type"] or "none", record["camera"]["prim_path"]
        time_code, randomisation = float(record["time_code"]), record.get("randomisation")
    return ImageSummary(
        id=record["id"], name=record["name"], split=record["split"], condition=condition, rig_type=rig_type,
        width=record["width"], height=record["height"], verdict=record["qa"]["verdict"],
        class_pixels=dict(record["class_pixel_counts"]), segments=_objects(record),
        aid_users=tuple(aid_users(record["instances"])), camera_path=camera_path, time_code=time_code,
        seed=record["seed"], visible=tuple(i["prim_path"] for i in record["instances"] if i["area"] > 0),
        randomisation=randomisation)


def load_index(root: str | Path) -> DatasetIndex:
    """Manifest, class map and the records of every image not rejected by QA, by image id."""
    root = Path(root)
    layout = Layout(root)
    manifest = dataset_manifest(root)
    class_map = load_class_map(root)
    kept = kept_images(manifest)
    images = tuple(_summary(read_record(layout.path(Layout.record(entry["name"])))) for entry in kept)
    return DatasetIndex(root=root, class_map=class_map, images=images, rejected=len(manifest["images"]) - len(kept))
