"""The background photos of ``synthua composite``: which files, with which labels, checked before anything is written.

BACKGROUNDS is one of:

* a folder of photos without labels (every JPEG, PNG, TIFF, BMP, WebP and HEIC file below it, in path order;
  linked folders followed, hidden files and folders and the datasets synthua wrote there left out);
* a labelled Ultralytics YOLO set (a ``data.yaml``, or a folder holding one or ``images/`` + ``labels/``): its
  ``train`` split where it has one (a set's val and test photos are what a detector trained on its composites is
  scored on: pasting into them would leak), another split or all of them when asked, read by
  :func:`synthua_usd.analytics.detection_sets.read_yolo`;
* a COCO instances ``.json`` (its images in the file's folder, or in ``images``):
  :func:`synthua_usd.analytics.detection_sets.read_coco`; crowd regions (``iscrowd``) are kept as boxes to ignore.

Photos are read in place, never copied: a background is named by its path relative to the set's folder (the
folder itself, a ``data.yaml``'s ``path`` or folder, a ``.json``'s images folder), which must be UTF-8. Checked
here, each failure one :class:`InputError`: a
folder without photos, a photo Pillow cannot open (a HEIC without its decoder included) or smaller than the output
size, a YOLO label file whose image is missing, a box outside its image (the YOLO reader refuses coordinates outside
[0, 1]; COCO boxes are checked here against the image's size), a labelled photo not stored upright. A truncated
photo's pixels fail when its composite decodes them (the run then stops and writes nothing).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import os
from pathlib import Path

from synthua_usd.analytics.detection_sets import IMAGE_SUFFIXES, MAX_IMAGES, TOLERANCE, Box, label_path, read_coco, \
    read_data_yaml, read_yolo, yolo_root
from synthua_usd.analytics.detection_sources import detect_format, is_synthua_dataset
from synthua_usd.backends.photos import HEIC_SUFFIXES, cover_region, photo_header
from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.model.photo_sets import ALL_SPLITS, DEFAULT_SPLIT

LAYOUTS = ("folder", "yolo", "coco")


@dataclass(frozen=True)
class Background:
    """One photo: ``relative`` its POSIX path below the set's folder; ``width`` x ``height`` upright pixels; its
    labelled ``boxes`` (photo pixels, the set's class names); ``focal_35mm`` its EXIF 35 mm equivalent focal
    length (None when absent)."""

    relative: str
    width: int
    height: int
    boxes: tuple[Box, ...] = ()
    focal_35mm: float | None = None


@dataclass(frozen=True)
class BackgroundSet:
    """The photos of BACKGROUNDS: ``folder`` (absolute) that ``relative`` paths start from, ``layout`` (one of
    :data:`LAYOUTS`), ``labelled`` (whether its photos' people are labelled), ``names`` the set's class names;
    ``skipped`` the datasets synthua wrote below a folder of photos, left out (paths relative to ``folder``)."""

    source: str
    folder: Path
    layout: str
    labelled: bool
    names: tuple[str, ...]
    images: tuple[Background, ...]
    skipped: tuple[str, ...] = ()

    def path(self, background: Background) -> Path:
        return self.folder / background.relative


def _absolute(path: Path) -> Path:
    """``path`` made absolute with ``..`` taken out as written, links not followed: a photo listed below a set's
    folder is inside it even where it is a link to a file elsewhere (a nested subset of links to the photos)."""
    return Path(os.path.abspath(path))


def _photos_below(folder: Path) -> tuple[list[Path], list[Path]]:
    """The photos below ``folder`` in path order, and the datasets synthua wrote there (left out: their images
    and label maps are no photos). Hidden files and folders are left out; a linked folder is followed where it
    leads out of ``folder`` (one leading into it is walked under its own name), each real folder once."""
    suffixes = IMAGE_SUFFIXES + HEIC_SUFFIXES
    root = os.path.realpath(folder)
    found: list[Path] = []
    skipped: list[Path] = []
    seen: set[str] = set()
    for top, dirs, files in os.walk(folder, followlinks=True):
        real = os.path.realpath(top)
        if real in seen:        # two links to one folder outside, or a link back up
            dirs[:] = []
            continue
        seen.add(real)
        kept: list[Path] = []
        for name in sorted(dirs):
            path = Path(top, name)
            if name.startswith(".") or (path.is_symlink() and Path(os.path.realpath(path)).is_relative_to(root)):
                continue
            (skipped if is_synthua_dataset(path) else kept).append(path)
        dirs[:] = [p.name for p in kept]
        for name in files:
            path = Path(top, name)
            if not name.startswith(".") and path.suffix.lower() in suffixes and path.is_file():
                found.append(path)
                if len(found) > MAX_IMAGES:
                    raise InputError(f"{shown(folder)}: more than {MAX_IMAGES} photos; expected at most that many")
    return sorted(found), sorted(skipped)


def listed_backgrounds(backgrounds: BackgroundSet, listed: list) -> BackgroundSet:
    """``backgrounds`` as a job listed them (``job_key.backgrounds``: ``[relative, width, height]`` each; a
    composite's names count photos in that list): for replay, when the folder is walked otherwise now (a photo
    left out today, e.g. in a dataset synthua wrote there, is read by its recorded name)."""
    found = {b.relative: b for b in backgrounds.images}
    images = []
    for item in listed:
        relative = item[0] if isinstance(item, list) and item and isinstance(item[0], str) else None
        if relative is None or Path(relative).is_absolute() or ".." in Path(relative).parts:
            raise InputError(f"generate.json: job_key.backgrounds: {str(item)[:80]!r}; expected [path below "
                             f"BACKGROUNDS, width, height]")
        if relative not in found:
            if backgrounds.labelled:
                raise InputError(f"{shown(backgrounds.folder / relative)}: not among the photos of "
                                 f"{shown(backgrounds.source)}; expected the photos the dataset was made from")
            header = photo_header(backgrounds.folder / relative)
            found[relative] = Background(relative, header.width, header.height, (), header.focal_35mm)
        images.append(found[relative])
    return replace(backgrounds, images=tuple(images))


def _check_yolo_labels(root: Path, images: list[Path], whole: bool = True) -> None:
    """Every label file of a YOLO folder names an image of the set (``labels/.../x.txt`` needs ``images/.../x.*``):
    of its whole ``labels/`` folder when ``whole`` (every split read), else of the read images' label folders."""
    expected = {label_path(p).resolve() for p in images}
    for labels in sorted({label_path(p).parent for p in images} | ({root / "labels"} if whole and (root / "labels")
                                                                   .is_dir() else set())):
        if not labels.is_dir():
            continue
        for label in sorted(labels.rglob("*.txt")):
            if label.name != "classes.txt" and label.resolve() not in expected:
                raise InputError(f"{shown(label)}: a label file naming image {label.stem!r}, which the set does not "
                                 f"have; expected its image beside the others under images/ (or remove the label)")


def _check_boxes(image: Path, boxes: tuple[Box, ...], width: int, height: int) -> None:
    for n, b in enumerate(boxes):
        if b.x < -TOLERANCE * width or b.y < -TOLERANCE * height or b.x + b.w > width * (1 + TOLERANCE) \
                or b.y + b.h > height * (1 + TOLERANCE):
            raise InputError(f"{shown(image)}: box {n} ({b.label}) at [{b.x:g}, {b.y:g}, {b.w:g}, {b.h:g}]; expected "
                             f"a box inside the {width}x{height} image")


def _yolo_split(path: Path, split: str) -> str:
    """The split of the YOLO set at ``path`` that ``split`` (one of
    :data:`synthua_usd.model.photo_sets.SPLIT_CHOICES`) reads."""
    if split != DEFAULT_SPLIT:
        return split
    yaml = path if path.is_file() else path / "data.yaml"
    if yaml.is_file():
        return "train" if read_data_yaml(yaml).get("train") else ALL_SPLITS
    return "train" if (path / "images" / "train").is_dir() else ALL_SPLITS


def read_backgrounds(path: str | Path, output: tuple[int, int] | None, split: str = DEFAULT_SPLIT,
                     images_dir: str | Path | None = None) -> BackgroundSet:
    """The background set at ``path`` (see the module docstring), every photo's header checked against
    ``output`` (W, H; None: any size); of a labelled YOLO set, the photos of ``split`` (one of
    :data:`synthua_usd.model.photo_sets.SPLIT_CHOICES`; the default: its train split where it names one, else all);
    of a COCO .json, the photos in ``images_dir`` (default: the file's folder)."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{shown(path)}: not found; expected a folder of photos, a YOLO set or a COCO .json")
    layout: str | None
    try:
        layout = detect_format(path)
    except InputError:
        layout = "folder" if path.is_dir() else None
    if images_dir is not None and layout != "coco":
        raise InputError(f"--images: {shown(images_dir)}; expected only with a COCO .json (a folder or YOLO set "
                         f"names its own photos)")
    if layout is None or layout not in LAYOUTS:
        raise InputError(f"{shown(path)}: {'a dataset written by synthua' if layout else 'not a folder'}; expected a "
                         f"folder of photos, a labelled YOLO set (data.yaml or images/ + labels/) or a COCO .json")
    #: (photo, its boxes, the size its labels give; None for an unlabelled photo)
    images: list[tuple[Path, tuple[Box, ...], tuple[int, int] | None]]
    names: tuple[str, ...]
    skipped: list[Path] = []
    if layout == "folder":
        folder = _absolute(path)
        paths, skipped = _photos_below(folder)
        if not paths:
            raise InputError(f"{shown(path)}: no photos; expected JPEG, PNG, TIFF, BMP, WebP or HEIC files below it")
        images, names = [(p, (), None) for p in paths], ()
    elif layout == "yolo":
        chosen = _yolo_split(path, split)
        found = read_yolo(path, chosen)
        folder = _absolute(yolo_root(path))
        _check_yolo_labels(folder, [Path(i.path) for i in found.images], whole=chosen == ALL_SPLITS)
        images, names = [(Path(i.path), i.boxes, (i.width, i.height)) for i in found.images], found.names
    else:
        found = read_coco(path, images_dir)
        folder = _absolute(Path(images_dir) if images_dir is not None else path.parent)
        images, names = [(Path(i.path), i.boxes, (i.width, i.height)) for i in found.images], found.names
    out = []
    for image, boxes, size in images:
        header = photo_header(image)
        if size is not None:  # a labelled photo
            if header.orientation != 1:
                raise InputError(f"{shown(image)}: EXIF orientation {header.orientation}; expected labelled photos "
                                 f"stored upright (orientation 1), their boxes drawn on them as stored")
            if size != (header.width, header.height):
                raise InputError(f"{shown(image)}: {header.width}x{header.height} pixels; its labels say "
                                 f"{size[0]}x{size[1]}")
            _check_boxes(image, boxes, header.width, header.height)
        cover_region((header.width, header.height), output, image)
        try:
            relative = _absolute(image).relative_to(folder).as_posix()
        except ValueError:
            raise InputError(f"{shown(image)}: outside {shown(folder)}; expected the set's photos below its "
                             f"folder") from None
        try:
            relative.encode("utf-8")
        except UnicodeEncodeError:
            raise InputError(f"{shown(image)}: a file name that is not UTF-8; expected UTF-8 names (rename it, "
                             f"e.g. with convmv)") from None
        out.append(Background(relative, header.width, header.height, tuple(boxes), header.focal_35mm))
    if len({b.relative for b in out}) != len(out):
        raise InputError(f"{shown(path)}: a photo listed twice; expected each photo once")
    return BackgroundSet(str(path), folder, layout, layout != "folder", tuple(names), tuple(out),
                         tuple(p.relative_to(folder).as_posix() for p in skipped))
