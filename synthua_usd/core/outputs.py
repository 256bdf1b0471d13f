"""The outputs of a rendered frame, in one table: which ``UsdRender.Var`` produces which files.

A scenario's render settings (``render.usda``) author one ``UsdRender.Var`` per entry of :data:`OUTPUTS`
it wants; ``synthua render`` writes the files of the vars the stage's settings name (every output when a
stage has no settings or names no vars) and always ``frame.json``, which lists the files it wrote. A dataset
image's frame folder holds the same files by the same names (:data:`FILE_NAMES`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from synthua_usd.core.errors import InputError

DEPTH_DEFINITION = ("z-depth: distance in metres from the camera centre along its optical axis "
                    "(not along the ray); 0 where the pixel-centre ray hits nothing")

#: Written with every frame, last: its presence means the frame is complete.
FRAME_DOCUMENT = "frame.json"


@dataclass(frozen=True)
class OutputFile:
    """One file of a frame: ``key`` in ``frame.json``'s ``files``, the file name, and what else frame.json
    says about it (colour space, dtype, meaning)."""

    key: str
    name: str
    about: dict = field(default_factory=dict)

    def document(self) -> dict:
        return {"path": self.name, **self.about}


@dataclass(frozen=True)
class RenderOutput:
    """A render var and the files it produces. ``source_name``, ``source_type`` and ``data_type`` are the
    ``UsdRender.Var`` attributes authored for it."""

    var: str
    source_name: str
    source_type: str
    data_type: str
    files: tuple[OutputFile, ...]


OUTPUTS: tuple[RenderOutput, ...] = (
    RenderOutput("rgb", "LdrColor", "raw", "color3f", (
        OutputFile("rgb_exr", "rgb.exr", {"colorspace": "lin_rec709_scene"}),
        OutputFile("rgb_png", "rgb.png", {"colorspace": "srgb_rec709_scene"}))),
    RenderOutput("class_id", "synthua:class_id", "primvar", "int", (
        OutputFile("class", "class.png", {"dtype": "uint8", "meaning": "class id (class_map), 0 = unlabelled"}),
        OutputFile("semantic", "semantic.png", {"colorspace": "srgb_rec709_scene", "meaning": "class colour"}))),
    RenderOutput("instance_id", "synthua:instance_id", "primvar", "int", (
        OutputFile("instance", "instance.png", {"dtype": "uint16", "meaning": "instance id (instances), 0 = none"}),
        OutputFile("instance_preview", "instance_preview.png",
                   {"colorspace": "srgb_rec709_scene", "meaning": "instance colour (a distinct colour per id, black = none)"}))),
    RenderOutput("depth", "depth", "raw", "float", (
        OutputFile("depth", "depth.exr", {"dtype": "float32", "channel": "Z", "kind": "z", "meaning": DEPTH_DEFINITION}),)),
)

OUTPUT_NAMES: tuple[str, ...] = tuple(o.var for o in OUTPUTS)

#: A dataset image's one-hot class masks (a generation config's ``outputs.onehot``; no render var makes it).
ONEHOT_FILE = OutputFile("onehot", "onehot.npz")

#: The file name of each file a frame may hold, by its key (``frame.json``'s ``files``, a dataset record's
#: ``files``): the one place the names are written.
FILE_NAMES: dict[str, str] = {f.key: f.name for o in OUTPUTS for f in o.files} | {ONEHOT_FILE.key: ONEHOT_FILE.name}


def select_outputs(var_names) -> tuple[RenderOutput, ...]:
    """The outputs for render var names (in table order); every output when ``var_names`` is empty.

    Raises :class:`InputError` for a name that is not in :data:`OUTPUTS`.
    """
    names = list(var_names)
    unknown = [n for n in names if n not in OUTPUT_NAMES]
    if unknown:
        raise InputError(f"render vars {unknown} are not outputs synthua writes; expected some of "
                         f"{', '.join(OUTPUT_NAMES)}")
    return tuple(o for o in OUTPUTS if not names or o.var in names)


def file_names(outputs: tuple[RenderOutput, ...] = OUTPUTS) -> tuple[str, ...]:
    """Every file a frame with ``outputs`` holds, ``frame.json`` last."""
    return tuple(f.name for o in outputs for f in o.files) + (FRAME_DOCUMENT,)
