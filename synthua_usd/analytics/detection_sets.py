"""Object-detection sets: images with labelled boxes, as a detector is trained and scored on them.

A :class:`DetectionSet` is plain data read from any of the layouts people keep detection data in:

* **Ultralytics YOLO** (``data.yaml`` + ``images/`` + ``labels/``): ``data.yaml`` names the classes (``names``, a
  list or an index -> name mapping) and each split (``train``, ``val``, ``test``: a folder of images, a ``.txt`` list
  of image paths, or a list of either, relative to ``path`` or to the file's folder); each image's labels are the
  ``.txt`` file at the same place under ``labels/`` (Ultralytics' rule: the last ``images`` folder of the path
  becomes ``labels``), one object a line, ``k cx cy w h`` normalised by the image's size, or ``k x1 y1 x2 y2 ...``, a
  polygon (boxed by its extreme points). No label file: an image without objects. The split :data:`ALL_SPLITS`
  takes every split the file names, each image once. A folder with ``images/`` and ``labels/`` but no ``data.yaml``
  is read the same way, every image below ``images/`` (or ``images/<split>``), its classes named by a
  ``classes.txt`` (one name a line, in the folder or in ``labels/``, as labelling tools write it) or else by their
  indices (``0``, ``1``, ...).
* **COCO JSON** (``images``, ``annotations`` with ``bbox`` = [x, y, width, height] in pixels, ``categories``), the
  images in the file's folder or ``images_dir``.
* a dataset ``synthua generate`` wrote, through :mod:`synthua_usd.analytics.detection_targets` (the boxes a
  detector is trained on are derived from the records there).

Boxes are in pixels of their image, pixel edges: (x, y) the top-left corner, w and h the size. ``ignore`` marks a
box that evaluation neither requires nor penalises a detection on (COCO's ``iscrowd``).

A set is read whole or refused by name, before a detector sees it: every image of a YOLO or COCO set is decoded to
its last pixel (a truncated JPEG, a HEIC or a file that is no image is refused naming the file; the detector would
fail on it with a message that does not, or score grey rows), a COCO image's ``width`` and ``height`` must be the
file's, its ``file_name`` a path inside the images folder, every annotation's ``image_id`` an image of the file and
its box inside that image (:data:`EDGE_PX` of slack, then clipped); a YOLO label path that is not a regular file is
refused, never read as "no objects".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import MAX_DOCUMENT_BYTES, read_input_text, shown
from synthua_usd.core.schemas import read_json
from synthua_usd.model.photo_sets import ALL_SPLITS

#: File suffixes read as images (Ultralytics' own list, lower case, less the formats OpenImageIO cannot read).
IMAGE_SUFFIXES = (".bmp", ".jpeg", ".jpg", ".png", ".tif", ".tiff", ".webp")
#: Splits a set may name, in the order a test set is looked for when none is asked for.
TEST_SPLITS = ("test", "val")
#: Most images read from one set (a real benchmark holds thousands; this bounds a mistaken folder).
MAX_IMAGES = 200_000
#: Normalised coordinates may overshoot [0, 1] by this much (rounding of the tools that wrote them).
TOLERANCE = 1e-3
#: Pixels a COCO box may reach past its image's edge (rounding of the tools that wrote it); the box is clipped.
EDGE_PX = 1.0


class MissingSplit(InputError):
    """The set has no such split (a YOLO data.yaml that names none, a generated dataset without images in it): the
    one refusal ``synthua train`` answers by validating on the train split instead."""


@dataclass(frozen=True)
class Box:
    """A labelled box: ``label`` a class name of its set; x, y (top-left corner), w, h in pixels, pixel edges."""

    label: str
    x: float
    y: float
    w: float
    h: float
    ignore: bool = False

    @property
    def area(self) -> float:
        """w * h, pixels²."""
        return self.w * self.h


@dataclass(frozen=True)
class SetImage:
    """One image of a set: ``id`` from 1, its file, size in pixels and boxes; ``regions``: boxes no class is scored
    on, ignored for every class (with ``--boxes``, a composite's other group: COCO's crowd rule in each class)."""

    id: int
    path: Path
    width: int
    height: int
    boxes: tuple[Box, ...] = field(default=())
    regions: tuple[Box, ...] = field(default=())


@dataclass(frozen=True)
class DetectionSet:
    """Images and their boxes; ``names`` the set's class names (in its own index order), ``layout`` what it was
    read from (``yolo``, ``coco`` or ``synthua``), ``source`` the path read, ``split`` the split taken."""

    names: tuple[str, ...]
    images: tuple[SetImage, ...]
    layout: str
    source: str
    split: str | None = None

    def counts(self) -> dict[str, int]:
        """Boxes per class name (ignored boxes left out), every class of ``names`` present."""
        out = dict.fromkeys(self.names, 0)
        for image in self.images:
            for box in image.boxes:
                if not box.ignore:
                    out[box.label] = out.get(box.label, 0) + 1
        return out


def checked_image_size(path: Path, whole: bool = True) -> tuple[int, int]:
    """(width, height) of an image stored upright, decoded to its last pixel when ``whole`` (else from its header:
    the images of a generated dataset, which ``synthua verify`` checks). A photo whose EXIF orientation turns it
    would be read turned by the detector (OpenCV applies it) and as stored here: refused rather than scored on boxes
    that do not fit."""
    from synthua_usd.core.images import decoded_image_size, image_size

    if not path.is_file():
        found = "file not found" if not path.exists() else "not a regular file"
        raise InputError(f"{shown(path)}: {found}; expected an image of the set")
    if path.suffix.lower() not in IMAGE_SUFFIXES:
        raise InputError(f"{shown(path)}: the file name ends in '{echo(path.suffix)}'; expected an image the detector "
                         f"reads ({', '.join(IMAGE_SUFFIXES)}; convert HEIC photos to JPEG first)")
    try:
        width, height, orientation = (decoded_image_size if whole else image_size)(path)
    except OSError as exc:
        reason = str(exc).split(": ", 1)[-1].splitlines()[0]
        raise InputError(f"{shown(path)}: not an image OpenImageIO can read whole ({echo(reason, 160)}); expected an "
                         f"undamaged image of the set") from None
    if orientation != 1:
        raise InputError(f"{shown(path)}: EXIF orientation {orientation}; expected images stored upright (orientation "
                         f"1): rotate them as stored first, e.g. with ImageMagick's mogrify -auto-orient")
    return width, height


# --- Ultralytics YOLO ----------------------------------------------------------------------------------------

def read_data_yaml(path: Path) -> dict:
    text = read_input_text(path, MAX_DOCUMENT_BYTES, "an Ultralytics data.yaml")
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise InputError(f"{shown(path)}: not valid YAML{where}; expected an Ultralytics data.yaml") from None
    if not isinstance(doc, dict):
        raise InputError(f"{shown(path)}: {type(doc).__name__}; expected a mapping with names and train/val/test")
    return doc


def yolo_names(doc: dict, where: str) -> tuple[str, ...]:
    """The class names of a data.yaml document, by index: ``names`` as a list, or a mapping 0..n-1 -> name."""
    names = doc.get("names")
    if isinstance(names, dict) and names and all(isinstance(k, int) for k in names) \
            and sorted(names) == list(range(len(names))):
        names = [names[k] for k in range(len(names))]
    if not isinstance(names, list) or not names or not all(isinstance(n, (str, int)) for n in names):
        raise InputError(f"{where}: names: {str(names)[:80]}; expected a list of class names or a mapping "
                         f"0..n-1 -> name")
    out = tuple(str(n) for n in names)
    if len(set(out)) != len(out):
        raise InputError(f"{where}: names: {', '.join(out)[:80]}; expected each class name once")
    return out


def _split_images(root: Path, entry, where: str) -> list[Path]:
    """Image files of a data.yaml split entry: folders (every image below them), .txt lists or image files."""
    entries = entry if isinstance(entry, list) else [entry]
    out: list[Path] = []
    for item in entries:
        if not isinstance(item, str) or not item:
            raise InputError(f"{where}: {str(item)[:80]!r}; expected a folder, a .txt list or an image path")
        path = Path(item) if Path(item).is_absolute() else root / item
        if path.is_dir():
            found = []
            for p in path.rglob("*"):   # counted as found: a split of "/" must not walk the whole disk first
                if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file():
                    found.append(p)
                    if len(out) + len(found) > MAX_IMAGES:
                        break
            out += sorted(found)
        elif path.suffix.lower() == ".txt" and path.is_file():
            for line in read_input_text(path, MAX_DOCUMENT_BYTES, "a list of image paths").splitlines():
                line = line.strip()
                if line:  # relative to the list's folder, as Ultralytics takes "./" lines
                    p = Path(line)
                    out.append(p if p.is_absolute() else path.parent / p)
        elif path.suffix.lower() in IMAGE_SUFFIXES and path.is_file():
            out.append(path)
        else:
            raise InputError(f"{where}: {shown(path)} does not exist; expected a folder of images, a .txt list "
                             f"of images or an image")
        if len(out) > MAX_IMAGES:
            raise InputError(f"{where}: more than {MAX_IMAGES} images; expected a test set of at most that many")
    return out


def label_path(image: Path) -> Path:
    """Ultralytics' label file of an image: the last ``images`` folder of its path replaced by ``labels``,
    the suffix by ``.txt``."""
    parts = list(image.parts)
    for i in range(len(parts) - 2, -1, -1):
        if parts[i] == "images":
            parts[i] = "labels"
            break
    return Path(*parts).with_suffix(".txt")


def _finite(values: list[float]) -> bool:
    return all(math.isfinite(v) for v in values)


def parse_yolo_labels(text: str, names: tuple[str, ...], width: int, height: int, where: str) -> tuple[Box, ...]:
    """The boxes of one YOLO label file (pixels of a ``width`` x ``height`` image); bad lines raise
    :class:`InputError` naming the file and line."""
    boxes = []
    for n, line in enumerate(text.splitlines(), 1):
        fields = line.split()
        if not fields:
            continue
        try:
            k = int(fields[0])
            values = [float(v) for v in fields[1:]]
        except ValueError:
            raise InputError(f"{where}: line {n}: {line[:80]!r}; expected a class index and normalised "
                             f"coordinates") from None
        if not 0 <= k < len(names):
            raise InputError(f"{where}: line {n}: class index {k}; expected 0..{len(names) - 1} (the names of "
                             f"data.yaml)")
        if not _finite(values) or any(v < -TOLERANCE or v > 1 + TOLERANCE for v in values):
            raise InputError(f"{where}: line {n}: coordinates {' '.join(fields[1:6])}...; expected numbers "
                             f"in [0, 1] (normalised by the image's size)")
        if len(values) == 4:
            cx, cy, w, h = values
            x0, y0, x1, y1 = cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2
        elif len(values) >= 6 and len(values) % 2 == 0:
            xs, ys = values[0::2], values[1::2]
            x0, y0, x1, y1 = min(xs), min(ys), max(xs), max(ys)
        else:
            raise InputError(f"{where}: line {n}: {len(values)} coordinates; expected 4 (cx cy w h) or a polygon "
                             f"of at least 3 points")
        x0, y0 = max(0.0, x0) * width, max(0.0, y0) * height
        x1, y1 = min(1.0, x1) * width, min(1.0, y1) * height
        boxes.append(Box(names[k], x0, y0, max(0.0, x1 - x0), max(0.0, y1 - y0)))
    return tuple(boxes)


def _set_images(paths: list[Path], names: tuple[str, ...], texts: list[str] | None = None) -> tuple[SetImage, ...]:
    """The images at ``paths`` with the boxes of their label files (``texts``: those files' text, when read)."""
    images = []
    for i, path in enumerate(paths, 1):
        width, height = checked_image_size(path)
        labels = label_path(path)
        if texts is not None:
            text = texts[i - 1]
        else:
            # no label file: an image without objects; anything else at its path (a folder) is no such thing
            present = labels.exists() or labels.is_symlink()
            text = read_input_text(labels, MAX_DOCUMENT_BYTES, "a YOLO label file") if present else ""
        images.append(SetImage(i, path, width, height, parse_yolo_labels(text, names, width, height, shown(labels))))
    return tuple(images)


def read_yolo_folder(root: str | Path, split: str | None = None) -> DetectionSet:
    """The images and boxes of a YOLO folder without ``data.yaml``: every image below ``images/`` (``split``:
    below ``images/<split>``), classes from ``classes.txt`` or else their indices."""
    root = Path(root)
    folder = root / "images" if split in (None, ALL_SPLITS) else root / "images" / split
    where = shown(folder)
    if not folder.is_dir():
        raise InputError(f"{where}: not a folder; expected the images of the split below images/")
    paths = _split_images(root, folder.relative_to(root).as_posix(), where)
    if not paths:
        raise InputError(f"{where}: no images; expected images in a format OpenImageIO reads ({', '.join(IMAGE_SUFFIXES)})")
    texts = [read_input_text(label_path(p), MAX_DOCUMENT_BYTES, "a YOLO label file")
             if label_path(p).exists() or label_path(p).is_symlink() else "" for p in paths]
    listed = next((c for c in (root / "classes.txt", root / "labels" / "classes.txt") if c.is_file()), None)
    if listed is not None:
        names = tuple(n.strip() for n in read_input_text(listed, MAX_DOCUMENT_BYTES, "a list of class names")
                      .splitlines() if n.strip())
        if not names or len(set(names)) != len(names):
            raise InputError(f"{shown(listed)}: {', '.join(names)[:80] or 'empty'}; expected class names, one a line, "
                             f"each once")
    else:
        top = -1
        for path, text in zip(paths, texts):
            for n, line in enumerate(text.splitlines(), 1):
                first = line.split()[:1]
                if first:
                    try:
                        top = max(top, int(first[0]))
                    except ValueError:
                        raise InputError(f"{shown(label_path(path))}: line {n}: {line[:80]!r}; expected a class index "
                                         f"and normalised coordinates") from None
        names = tuple(str(k) for k in range(max(top + 1, 1)))
    return DetectionSet(names, _set_images(paths, names, texts), "yolo", str(root), split)


def _yolo_base(data_yaml: Path, doc: dict) -> Path:
    """The folder a data.yaml's splits are relative to: its ``path`` (relative to the file's folder), else the
    file's folder."""
    if isinstance(doc.get("path"), str) and doc["path"]:
        p = Path(doc["path"])
        return p if p.is_absolute() else data_yaml.parent / p
    return data_yaml.parent


def yolo_root(path: str | Path) -> Path:
    """The folder of the YOLO set at ``path`` (a data.yaml, or a folder with or without one) that its images'
    paths start from: a data.yaml's ``path`` where it names one."""
    path = Path(path)
    data_yaml = path / "data.yaml" if path.is_dir() else path
    return _yolo_base(data_yaml, read_data_yaml(data_yaml)) if data_yaml.is_file() else path


def read_yolo(data_yaml: str | Path, split: str | None = None) -> DetectionSet:
    """The images and boxes of one split of an Ultralytics YOLO dataset (``split`` default: ``test``, else
    ``val``; :data:`ALL_SPLITS`: every split); a folder without ``data.yaml`` is :func:`read_yolo_folder`'s."""
    data_yaml = Path(data_yaml)
    if data_yaml.is_dir() and not (data_yaml / "data.yaml").is_file() and (data_yaml / "images").is_dir():
        return read_yolo_folder(data_yaml, split)
    if data_yaml.is_dir():
        data_yaml = data_yaml / "data.yaml"
    where = shown(data_yaml)
    doc = read_data_yaml(data_yaml)
    names = yolo_names(doc, where)
    base = _yolo_base(data_yaml, doc)
    present = [s for s in ("train", "val", "test") if doc.get(s)]
    if split == ALL_SPLITS:
        wanted = present
    else:
        wanted = [split] if split else [s for s in TEST_SPLITS if doc.get(s)][:1]
    if not wanted or not all(doc.get(s) for s in wanted):
        raise MissingSplit(f"{where}: {split or 'test/val'}: not in the file (splits: {', '.join(present) or 'none'}); "
                           f"expected the split to score, e.g. --split "
                           f"{next((s for s in ('test', 'val', 'train') if doc.get(s)), 'test')}")
    paths: list[Path] = []
    for name in wanted:
        found = _split_images(base, doc[name], f"{where}: {name}")
        if not found:
            raise InputError(f"{where}: {name}: no images; expected images in a format OpenImageIO reads "
                             f"({', '.join(IMAGE_SUFFIXES)})")
        paths += found
    if len(wanted) > 1:
        paths = list(dict.fromkeys(paths))      # an image two splits list is one image
    return DetectionSet(names, _set_images(paths, names), "yolo", str(data_yaml), "+".join(wanted))


# --- COCO JSON ---------------------------------------------------------------------------------------------------

def _whole_number(value, where: str, low: int) -> int:
    """An integer JSON value of at least ``low`` (not a boolean, not 3.5), else :class:`InputError` at ``where``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not float(value).is_integer() \
            or not math.isfinite(value) or value < low:
        raise InputError(f"{where}: {echo(value)}; expected a whole number >= {low}")
    return int(value)


def _file_in(folder: Path, name, where: str) -> Path:
    """``folder / name`` for a COCO ``file_name``: a relative path that stays inside ``folder`` (``../../etc/passwd``
    and ``/etc/passwd`` are refused, as no image of the set)."""
    from pathlib import PurePosixPath, PureWindowsPath

    if not isinstance(name, str) or not name.strip():
        raise InputError(f"{where}: {echo(name)}; expected the image's file name, relative to {shown(folder)}")
    parts = PurePosixPath(name.replace("\\", "/")).parts
    if PurePosixPath(name).is_absolute() or PureWindowsPath(name).is_absolute() or ".." in parts:
        raise InputError(f"{where}: '{echo(name)}' leaves the images folder; expected a file name inside "
                         f"{shown(folder)} (or name the images' folder with --images)")
    return folder / name


def read_coco(json_path: str | Path, images_dir: str | Path | None = None) -> DetectionSet:
    """The images and boxes of a COCO instances file; images looked up by ``file_name`` in ``images_dir``
    (default: the file's folder). Read whole or refused (see the module's docstring): every image decoded and of
    the size the file states, every annotation on an image of the file and inside it."""
    json_path = Path(json_path)
    where = shown(json_path)
    doc = read_json(json_path, "COCO instances (images, annotations, categories)")
    if not isinstance(doc, dict) or not all(isinstance(doc.get(k), list) for k in ("images", "annotations",
                                                                                  "categories")):
        raise InputError(f"{where}: expected a COCO instances document with images, annotations and categories")
    folder = Path(images_dir) if images_dir is not None else json_path.parent
    try:
        categories = {int(c["id"]): str(c["name"]) for c in doc["categories"]}
        names = tuple(categories[k] for k in sorted(categories))
        sizes: dict[int, tuple[int, int, Path]] = {}
        for k, im in enumerate(doc["images"]):
            image_id = _whole_number(im["id"], f"{where}: images[{k}].id", 0)
            if image_id in sizes:
                raise InputError(f"{where}: images[{k}].id: {image_id} twice; expected each image once")
            width = _whole_number(im["width"], f"{where}: images[{k}].width", 1)
            height = _whole_number(im["height"], f"{where}: images[{k}].height", 1)
            path = _file_in(folder, im["file_name"], f"{where}: images[{k}].file_name")
            if not path.is_file():
                raise InputError(f"{where}: images[{k}]: {shown(path)}: file not found; expected the image in "
                                 f"{shown(folder)} (or name its folder with --images)")
            if checked_image_size(path) != (width, height):
                found = "x".join(map(str, checked_image_size(path, whole=False)))
                raise InputError(f"{shown(path)}: {found} pixels; expected the {width}x{height} that {where} "
                                 f"images[{k}] states")
            sizes[image_id] = (width, height, path)
        boxes: dict[int, list[Box]] = {}
        for n, a in enumerate(doc["annotations"]):
            x, y, w, h = (float(v) for v in a["bbox"])
            if not _finite([x, y, w, h]) or w < 0 or h < 0:
                raise InputError(f"{where}: annotations[{n}].bbox: {a['bbox']}; expected [x, y, width, height], "
                                 f"finite, sizes >= 0")
            if int(a["category_id"]) not in categories:
                raise InputError(f"{where}: annotations[{n}].category_id: {a['category_id']}; expected an id of "
                                 f"categories")
            image_id = _whole_number(a["image_id"], f"{where}: annotations[{n}].image_id", 0)
            if image_id not in sizes:
                raise InputError(f"{where}: annotations[{n}].image_id: {image_id}; expected the id of one of its "
                                 f"{len(sizes)} images (a box on no image would be scored as nothing)")
            width, height, path = sizes[image_id]
            if x < -EDGE_PX or y < -EDGE_PX or x + w > width + EDGE_PX or y + h > height + EDGE_PX:
                raise InputError(f"{where}: annotations[{n}].bbox: {a['bbox']}; expected a box inside its image "
                                 f"{shown(path.name)} ({width}x{height} pixels)")
            x0, y0 = min(max(x, 0.0), width), min(max(y, 0.0), height)
            x1, y1 = min(max(x + w, 0.0), width), min(max(y + h, 0.0), height)
            boxes.setdefault(image_id, []).append(
                Box(categories[int(a["category_id"])], x0, y0, x1 - x0, y1 - y0, bool(a.get("iscrowd", 0))))
        images = [SetImage(i, path, width, height, tuple(boxes.get(image_id, ())))
                  for i, (image_id, (width, height, path)) in enumerate(sorted(sizes.items()), 1)]
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"{where}: {type(exc).__name__} {str(exc)[:80]}; expected COCO images (id, file_name, "
                         f"width, height), annotations (image_id, category_id, bbox) and categories (id, name)") from None
    if not images:
        raise InputError(f"{where}: images: empty; expected the images to score")
    return DetectionSet(names, tuple(images), "coco", str(json_path))
