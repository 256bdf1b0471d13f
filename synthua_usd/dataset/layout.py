"""Where every file of a generated dataset lives: the one owner of the dataset's folder layout.

One layout serves every format at once, so that the RGB image is written once::

    DIR/
      images/{split}/{name}.png                  RGB, 8-bit sRGB (COCO images and YOLO images/)
      labels/{split}/{name}.txt                  YOLO segmentation labels (Ultralytics convention)
      data.yaml                                  YOLO dataset file
      annotations/instances_{split}.json         COCO instances, RLE masks
      annotations/person_keypoints_{split}.json  COCO person keypoints (the person category only)
      annotations/panoptic_{split}.json          COCO panoptic
      annotations/panoptic_{split}/{name}.png    COCO panoptic PNGs (id = R + 256 G + 256² B)
      gtFine/{split}/{city}/{city}_{seq}_{frame}_gtFine_{labelIds,instanceIds,color}.png   Cityscapes
      leftImg8bit/{split}/{city}/{city}_{seq}_{frame}_leftImg8bit.png                       (link to images/)
      frames/{name}/...                          everything else of one image (class, semantic, instance
                                                 ids and preview, depth, optional EXR and one-hot tensor)
      records/{name}.json                        the image's record, written last: the image is complete
      sequences/{seq}/img1/{frame:06d}.jpg       a tracking sequence in the MOTChallenge layout (seqinfo.ini,
      sequences/{seq}/gt/gt.txt                  gt/gt.txt), with tracks.csv, instances/{frame:06d}.png (16-bit
                                                 instance ids), records/{frame:06d}.json (written last) and
                                                 preview.mp4; sequences/crowds/seed_{s}.usdc its crowd;
                                                 annotations/sequences.json every sequence as COCO video
      metadata.csv, metadata.parquet, coverage.json, rejected.csv, class_map.json, manifest.json,
      generate.json (the configuration of the run)

Names come from the scene (camera prim names, condition names) and so from untrusted input: every path
component made here is reduced to ``[A-Za-z0-9-]`` by :func:`safe_component`, and :func:`inside` refuses
any path that would leave the dataset folder.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from synthua_usd.core import dataset_folders
from synthua_usd.core.errors import echo as escape
from synthua_usd.core.errors import OutputError
from synthua_usd.core.outputs import FILE_NAMES

SPLITS = ("train", "val", "test")

_UNSAFE = re.compile(r"[^A-Za-z0-9-]+")


def safe_component(text: str, limit: int = 48) -> str:
    """``text`` reduced to letters, digits and hyphens (runs of anything else become one hyphen), at most
    ``limit`` characters, never empty: safe as one path component on every file system."""
    out = _UNSAFE.sub("-", str(text)).strip("-")[:limit].strip("-")
    return out or "x"


def image_name(image_id: int, camera_name: str, time_code: float, condition: str | None, seed: int) -> str:
    """File stem of an image: ``000017_CCTV-Largo_t0024_clear-day_s0``. The id prefix keeps names unique
    when two cameras' names reduce to the same safe text."""
    tc = f"{int(time_code):04d}" if float(time_code).is_integer() else f"{time_code:08.3f}".replace(".", "p")
    return (f"{image_id:06d}_{safe_component(camera_name)}_t{tc}_{safe_component(condition or 'stage')}"
            f"_s{int(seed)}")


def composite_name(image_id: int, background: str, number: int) -> str:
    """File stem of a composite of ``synthua composite``: ``000017_street-04_c1`` (id, the background photo's file
    stem, which composite of that photo it is)."""
    return f"{image_id:06d}_{safe_component(PurePosixPath(background).stem)}_c{int(number)}"


@dataclass(frozen=True)
class CityscapesName:
    """Cityscapes' ``{city}_{seq:06d}_{frame:06d}`` naming: city from the scenario's name (letters and digits
    only: cityscapesScripts splits names at underscores), seq from the camera's index, frame from the image
    id."""

    city: str
    seq: int
    frame: int

    @property
    def stem(self) -> str:
        return f"{self.city}_{self.seq:06d}_{self.frame:06d}"


def cityscapes_city(scenario_name: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "", scenario_name).lower()[:32] or "synthua"


@dataclass(frozen=True)
class Layout:
    """Relative POSIX paths (as they appear in documents) of one dataset's files."""

    root: Path

    def path(self, relative: str) -> Path:
        """The absolute path of a relative one, refused if it would leave the dataset folder."""
        return inside(self.root, relative)

    # per image
    @staticmethod
    def rgb_png(split: str, name: str) -> str:
        return f"images/{split}/{name}.png"

    @staticmethod
    def yolo_label(split: str, name: str) -> str:
        return f"labels/{split}/{name}.txt"

    @staticmethod
    def panoptic_png(split: str, name: str) -> str:
        return f"annotations/panoptic_{split}/{name}.png"

    @staticmethod
    def cityscapes(split: str, cs: CityscapesName, kind: str) -> str:
        """``kind``: ``labelIds``, ``instanceIds``, ``color`` (gtFine) or ``leftImg8bit``."""
        if kind == "leftImg8bit":
            return f"leftImg8bit/{split}/{cs.city}/{cs.stem}_leftImg8bit.png"
        return f"gtFine/{split}/{cs.city}/{cs.stem}_gtFine_{kind}.png"

    @staticmethod
    def frame_file(name: str, key: str) -> str:
        """The file ``key`` of image ``name``'s frame folder (its name from :data:`FILE_NAMES`: ``class`` is
        ``class.png``)."""
        return f"frames/{name}/{FILE_NAMES[key]}"

    @staticmethod
    def record(name: str) -> str:
        return f"{dataset_folders.RECORDS}/{name}.json"

    # per sequence
    SEQUENCES = "sequences"

    @staticmethod
    def sequence_file(sequence: str, file_name: str) -> str:
        """A file of one sequence: ``seqinfo.ini``, ``tracks.csv``, ``preview.mp4``, ``gt/gt.txt``."""
        return f"sequences/{sequence}/{file_name}"

    @staticmethod
    def sequence_frame(sequence: str, frame: int, kind: str = "img1") -> str:
        """Frame ``frame`` (1-based) of a sequence: ``img1`` (JPEG), ``instances`` (PNG) or ``records`` (JSON)."""
        suffix = {"img1": "jpg", "instances": "png", "records": "json"}[kind]
        return f"sequences/{sequence}/{kind}/{frame:06d}.{suffix}"

    @staticmethod
    def sequence_crowd(seed: int) -> str:
        return f"sequences/crowds/seed_{int(seed)}.usdc"

    SEQUENCES_COCO = "annotations/sequences.json"

    # per dataset
    @staticmethod
    def coco_instances(split: str) -> str:
        return f"annotations/instances_{split}.json"

    @staticmethod
    def coco_person_keypoints(split: str) -> str:
        return f"annotations/person_keypoints_{split}.json"

    @staticmethod
    def coco_panoptic(split: str) -> str:
        return f"annotations/panoptic_{split}.json"

    DATA_YAML = "data.yaml"
    METADATA_CSV = "metadata.csv"
    METADATA_PARQUET = "metadata.parquet"
    COVERAGE = "coverage.json"
    REJECTED = "rejected.csv"
    CLASS_MAP = "class_map.json"
    MANIFEST = dataset_folders.MANIFEST
    CONFIG = dataset_folders.CONFIG


def inside(root: Path, relative: str) -> Path:
    """``root / relative`` for a relative POSIX path with no ``..``, no absolute part and no empty or hidden
    component; anything else raises :class:`OutputError` (a scene name must never write outside DIR)."""
    parts = PurePosixPath(relative).parts
    if (not parts or PurePosixPath(relative).is_absolute() or "\\" in relative
            or any(p in ("", ".", "..") or p.startswith(".") or "\n" in p or "\0" in p for p in parts)):
        raise OutputError(f"{escape(relative)!r}: a path that leaves the dataset folder or hides in it; expected a "
                          f"plain relative path inside the dataset folder")
    return Path(root).joinpath(*parts)
