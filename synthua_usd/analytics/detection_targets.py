"""The boxes a detector is trained on, derived from a generated dataset's records (a composite's too: its pasted
instances', and the boxes of its labelled photo that the pastes left visible).

A real photo's ``wheelchair`` box is drawn around what a person sees as "a wheelchair" in the street: the chair
*with the person sitting in it* (the Mobility Aids dataset of Vasquez et al., 2017, and the public "wheelchair"
sets label the user and the aid as one object), not the frame alone, which our COCO instances annotate (the device
is its own instance, linked to its user by ``uses``). So by default (:attr:`DetectionTargets.aid_box` =
``with_user``) a mobility aid's box is the union of the device's visible box and its user's; ``device`` keeps the
device's own box. A person is a person whatever they use (COCO's convention, and what a pedestrian detector must
find): every visible person gets a ``person`` box, a wheelchair user too, unless ``aid_users_as_person`` is off
(for test sets that label a wheelchair user only as ``wheelchair``).

Named conventions (:mod:`synthua_usd.model.box_conventions`, which says what each means) set both choices and the
classes trained at once (:func:`targets_for`): ``synthua``, the default above, and ``wheelchair-sets``, the public
wheelchair photo sets' (a wheelchair box covers the chair and its seated user, who has no ``person`` box).

Boxes are the records' visible, pixel-edge boxes. A box lower than ``min_height_px`` (a person of 3 pixels far
down the street) is kept as ``ignore``: never a training target, and neither required nor penalised when the
split is scored (COCO's crowd rule).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from synthua_usd.analytics.dataset_index import dataset_manifest, load_class_map
from synthua_usd.analytics.detection_sets import Box, DetectionSet, MissingSplit, SetImage, checked_image_size
from synthua_usd.assets.devices import DEVICES
from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown
from synthua_usd.dataset.layout import SPLITS, Layout
from synthua_usd.dataset.manifest import kept_images
from synthua_usd.dataset.record import DatasetRecord, InstanceEntry, read_record
from synthua_usd.model.box_conventions import CONVENTIONS, DEFAULT_CONVENTION
from synthua_usd.model.detection_limits import DEFAULT_MIN_HEIGHT_PX, MIN_HEIGHT_PX, SCORED_BOXES

PERSON = "person"
#: The classes trained by default: person and the eight mobility aids.
DEFAULT_CLASSES = (PERSON,) + tuple(DEVICES)
AID_BOXES = ("with_user", "device")
_DEFAULT = CONVENTIONS[DEFAULT_CONVENTION]


@dataclass(frozen=True)
class DetectionTargets:
    """What a detector is trained to find in a generated dataset.

    ``classes``: class names of the dataset's class map, things; ``aid_box``: ``with_user`` (a mobility aid's box
    covers its user too) or ``device``; ``aid_users_as_person``: whether an aid user also gets a person box (only
    users of an aid among ``classes`` lose theirs); ``min_height_px``: boxes lower than this, pixels of the written
    image, are ``ignore``. The defaults are those of :data:`DEFAULT_CONVENTION`."""

    classes: tuple[str, ...] = _DEFAULT.classes or DEFAULT_CLASSES
    aid_box: str = _DEFAULT.aid_box
    aid_users_as_person: bool = _DEFAULT.aid_users_as_person
    min_height_px: float = DEFAULT_MIN_HEIGHT_PX

    def __post_init__(self):
        if not self.classes or len(set(self.classes)) != len(self.classes):
            raise InputError(f"--classes: {','.join(self.classes)}; expected class names, each once")
        if self.aid_box not in AID_BOXES:
            raise InputError(f"--aid-box: {self.aid_box!r}; expected one of {', '.join(AID_BOXES)}")
        MIN_HEIGHT_PX.check(self.min_height_px, "--min-height-px")

    def document(self) -> dict:
        return {"classes": list(self.classes), "aid_box": self.aid_box,
                "aid_users_as_person": self.aid_users_as_person, "min_height_px": self.min_height_px}

    @classmethod
    def from_document(cls, doc: dict) -> "DetectionTargets":
        return cls(tuple(doc["classes"]), doc["aid_box"], bool(doc["aid_users_as_person"]), float(doc["min_height_px"]))

    @property
    def convention(self) -> str | None:
        """The name of the convention whose aid boxes and classes these are, or None."""
        return next((name for name, c in CONVENTIONS.items() if (c.aid_box, c.aid_users_as_person,
                                                                  c.classes or DEFAULT_CLASSES) ==
                     (self.aid_box, self.aid_users_as_person, self.classes)), None)


def targets_for(convention: str | None = None, classes: tuple[str, ...] | None = None, aid_box: str | None = None,
                aid_users_as_person: bool | None = None,
                min_height_px: float = DEFAULT_MIN_HEIGHT_PX) -> DetectionTargets:
    """The targets of ``convention`` (None: :data:`DEFAULT_CONVENTION`, whose choices the options may change) with
    the options given (None: the convention's). A named convention fixes ``aid_box`` and ``aid_users_as_person``:
    another value for either raises :class:`InputError`; ``classes`` may narrow or widen what is trained."""
    name = DEFAULT_CONVENTION if convention is None else convention
    if name not in CONVENTIONS:
        raise InputError(f"--convention: {name!r}; expected one of {', '.join(CONVENTIONS)}")
    chosen = CONVENTIONS[name]
    if convention is not None:
        for option, given, fixed in (("--aid-box", aid_box, chosen.aid_box),
                                     ("--aid-users-as-person", aid_users_as_person, chosen.aid_users_as_person)):
            if given is not None and given != fixed:
                shown_given = given if isinstance(given, str) else ("on" if given else "off")
                shown_fixed = fixed if isinstance(fixed, str) else ("on" if fixed else "off")
                raise InputError(f"{option} {shown_given}: --convention {name} sets it {shown_fixed}; expected the "
                                 f"convention or the option, not both")
    return DetectionTargets((chosen.classes or DEFAULT_CLASSES) if classes is None else tuple(classes),
                            chosen.aid_box if aid_box is None else aid_box,
                            chosen.aid_users_as_person if aid_users_as_person is None else aid_users_as_person,
                            min_height_px)


def _union(a: list, b: list) -> list:
    x0, y0 = min(a[0], b[0]), min(a[1], b[1])
    return [x0, y0, max(a[0] + a[2], b[0] + b[2]) - x0, max(a[1] + a[3], b[1] + b[3]) - y0]


def image_boxes(instances: list[InstanceEntry], targets: DetectionTargets) -> tuple[Box, ...]:
    """The target boxes of one record's ``instances`` (``class_name``, ``prim_path``, ``area``, ``bbox`` [x, y, w, h]
    and ``relations`` of each), in instance order."""
    visible = [i for i in instances if i["area"] > 0]
    user_of = {i["relations"]["uses"]: i for i in visible if i["class_name"] == PERSON and i["relations"].get("uses")}
    wanted = set(targets.classes)
    out = []
    for inst in visible:
        name = inst["class_name"]
        if name not in wanted:
            continue
        bbox = [float(v) for v in inst["bbox"]]
        if name == PERSON:
            device = inst["relations"].get("uses_class")
            if not targets.aid_users_as_person and device in wanted:
                continue
        elif name in DEVICES and targets.aid_box == "with_user" and inst["prim_path"] in user_of:
            bbox = _union(bbox, [float(v) for v in user_of[inst["prim_path"]]["bbox"]])
        x, y, w, h = bbox
        out.append(Box(name, x, y, w, h, ignore=h < targets.min_height_px))
    return tuple(out)


def background_boxes(record: DatasetRecord, targets: DetectionTargets) -> tuple[Box, ...]:
    """The kept boxes of a composite's labelled photo (its record's ``composite.background_boxes``) whose class is
    trained, as labelled there (in the photo set's own box convention); none for a rendered image."""
    if "composite" not in record:
        return ()
    wanted, out = set(targets.classes), []
    for box in record["composite"]["background_boxes"]:
        if box["kept"] and box["class_name"] in wanted:
            x, y, w, h = (float(v) for v in box["bbox"])
            out.append(Box(box["class_name"], x, y, w, h, ignore=h < targets.min_height_px))
    return tuple(out)


#: Why a photo's box was dropped from a composite's labels while it still shows (part of) a labelled object.
_STILL_SHOWN = ("covered", "cropped", "crowd")


def record_boxes(record: DatasetRecord, targets: DetectionTargets) -> tuple[Box, ...]:
    """Every target box of one image record: its instances' (:func:`image_boxes`), then a composite's photo's own
    (:func:`background_boxes`)."""
    return image_boxes(record["instances"], targets) + background_boxes(record, targets)


def _photo_regions(record: DatasetRecord) -> tuple[Box, ...]:
    """Every box of a composite's photo that still shows something labelled, whatever its class: the kept ones and
    those dropped as covered, cropped or a crowd region (``label`` the photo set's own)."""
    if "composite" not in record:
        return ()
    out = []
    for box in record["composite"]["background_boxes"]:
        x, y, w, h = (float(v) for v in box["bbox"])
        if (box["kept"] or box["reason"] in _STILL_SHOWN) and w > 0 and h > 0:
            out.append(Box(box["label"], x, y, w, h, ignore=True))
    return tuple(out)


def scored_boxes(record: DatasetRecord, targets: DetectionTargets,
                 scored: str = "all") -> tuple[tuple[Box, ...], tuple[Box, ...]]:
    """The boxes of one record that are scored, and the regions ignored for every class: with ``scored`` ``all``
    every target box (:func:`record_boxes`) and none; ``pasted``, the pasted instances' boxes, the photo's
    (:func:`_photo_regions`) as regions; ``photo``, the photo's kept boxes, the pasted instances' (every class) and
    the photo's dropped ones as regions (:data:`~synthua_usd.model.detection_limits.SCORED_BOXES`)."""
    if scored == "all":
        return record_boxes(record, targets), ()
    pasted, photo = image_boxes(record["instances"], targets), background_boxes(record, targets)
    if scored == "pasted":
        return pasted, _photo_regions(record)
    every_class = tuple(dict.fromkeys(i["class_name"] for i in record["instances"])) or targets.classes
    every_target = replace(targets, classes=every_class)
    pastes = tuple(replace(b, ignore=True) for b in image_boxes(record["instances"], every_target))
    scored_here = {(b.x, b.y, b.w, b.h) for b in photo}
    return photo, pastes + tuple(b for b in _photo_regions(record) if (b.x, b.y, b.w, b.h) not in scored_here)


def read_generated(root, split: str | None, targets: DetectionTargets, scored: str = "all") -> DetectionSet:
    """The target boxes of the images of ``split`` (every split when None) of a dataset ``synthua generate`` or
    ``synthua composite`` wrote; images QA rejected are left out, as every training format leaves them out.
    ``scored`` (:data:`~synthua_usd.model.detection_limits.SCORED_BOXES`) other than ``all`` asks for a composite
    dataset and keeps the other group's boxes as regions ignored for every class (:func:`scored_boxes`)."""
    layout = Layout(Path(root))
    if split is not None and split not in SPLITS:
        raise InputError(f"--split: {split!r}; expected one of {', '.join(SPLITS)}")
    if scored not in SCORED_BOXES:
        raise InputError(f"--boxes: {scored!r}; expected one of {', '.join(SCORED_BOXES)}")
    class_map = load_class_map(layout.root)
    things = {c.name for c in class_map.classes if c.isthing}
    unknown = [c for c in targets.classes if c not in things]
    if unknown:
        raise InputError(f"--classes: {', '.join(unknown)}: not thing classes of {shown(layout.path(Layout.CLASS_MAP))}"
                         f"; expected some of {', '.join(sorted(things))}")
    entries = kept_images(dataset_manifest(layout.root), split)
    if not entries:
        raise MissingSplit(f"{shown(layout.root)}: no images{f' in split {split}' if split else ''}; expected a "
                         f"dataset with images in the split (see its manifest.json)")
    images = []
    for n, entry in enumerate(entries, 1):
        name, image_split = entry["name"], entry["split"]
        path = layout.path(Layout.record(name))
        record = read_record(path)
        if scored != "all" and "composite" not in record:
            raise InputError(f"--boxes {scored}: {shown(path)} is a rendered image's record (no composite part); "
                             f"expected a dataset `synthua composite` wrote, or --boxes all")
        (boxes, regions), width, height = scored_boxes(record, targets, scored), record["width"], record["height"]
        image = layout.path(Layout.rgb_png(image_split, name))
        if checked_image_size(image, whole=False) != (width, height):  # its header: `synthua verify` checks the rest
            raise InputError(f"{shown(image)}: {'x'.join(map(str, checked_image_size(image, whole=False)))} pixels; "
                             f"expected the {width}x{height} of its record {shown(path)}")
        images.append(SetImage(n, image, width, height, boxes, regions))
    return DetectionSet(tuple(targets.classes), tuple(images), "synthua", str(layout.root), split)
