"""What distractors can be (``randomise.distractors``): primitive shapes, everyday objects of the asset library and
hard negatives, each with the class it honestly is.

- **primitives** (``box``, ``ball``, ``cylinder``, ``cone``, ``torus``, ``capsule``), in the manner of the
  domain-randomisation papers (Tobin et al. 2017, Tremblay et al. 2018): no class of the map fits a floating shape,
  so they are ``unlabelled`` (void: ignored by segmentation, background to a detector);
- **objects** of the library, labelled as the district labels them: ``chair``, ``table``, ``bench``
  (``furniture``), ``sign`` (``signage``), ``bicycle``, ``dog`` (``animal``), ``plant`` (``vegetation``);
- **hard negatives**, wheeled things a detector must not take for a wheelchair user: a ``stroller`` and a
  ``shopping_trolley`` (no class in the map: ``unlabelled``), and empty wheelchairs (``empty_manual_wheelchair``,
  ``empty_electric_wheelchair``), which *are* wheelchairs and are labelled so, with no user.

No distractor is ever labelled ``person``; only the empty wheelchairs carry a mobility-aid class. A builder gives
the object's parts in its own frame (footprint centre at the origin on z = 0, front +X): a primitive fills the box
``size_m`` (x, y, z), an object keeps its own size.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from synthua_usd.assets import carts, devices, interior, market, nature, street, vehicles
from synthua_usd.model import meshes as geo
from synthua_usd.model.twin import TwinPart


def _unit(mesh: geo.Mesh) -> geo.Mesh:
    """``mesh`` moved and scaled into the unit box [-0.5, 0.5]² x [0, 1]."""
    pts, tris = mesh
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = (lo + hi) / 2
    return (pts - [centre[0], centre[1], lo[2]]) / np.maximum(hi - lo, 1e-9), tris


_SHAPES: dict[str, geo.Mesh] = {
    "box": geo.box((-0.5, -0.5, 0.0), (0.5, 0.5, 1.0)),
    "ball": _unit(geo.sphere((0.0, 0.0, 0.0), 0.5, subdivisions=2)),
    "cylinder": _unit(geo.cylinder((0.0, 0.0, 0.5), 0.5, 1.0, sections=20)),
    "cone": _unit(geo.cone(0.5, 1.0, sections=20)),
    "torus": _unit(geo.torus((0.0, 0.0, 0.0), 0.36, 0.14, major_sections=24, minor_sections=10)),
    "capsule": _unit(geo.capsule(0.5, 1.0, sections=12)),
}


def _primitive(name: str) -> Callable[[tuple[float, float, float]], list[TwinPart]]:
    def build(size_m: tuple[float, float, float]) -> list[TwinPart]:
        pts, tris = _SHAPES[name]
        return [TwinPart.of("Shape", (pts * np.asarray(size_m, float), tris), "Neutral")]
    return build


def _fixed(builder: Callable[[], list[TwinPart]]) -> Callable[[tuple[float, float, float]], list[TwinPart]]:
    return lambda size_m: builder()


@dataclass(frozen=True)
class DistractorObject:
    """One kind of distractor: its class (``unlabelled`` for void), its group (``primitive``, ``object``,
    ``hard_negative``) and its builder of parts from a size (x, y, z) metres (objects ignore the size)."""

    label: str
    group: str
    build: Callable[[tuple[float, float, float]], list[TwinPart]]


CATALOGUE: dict[str, DistractorObject] = {
    **{name: DistractorObject("unlabelled", "primitive", _primitive(name)) for name in _SHAPES},
    "chair": DistractorObject("chair", "object", _fixed(market.chair)),
    "table": DistractorObject("table", "object", _fixed(market.table)),
    "bench": DistractorObject("furniture", "object", _fixed(lambda: street.bench(1.4))),
    "sign": DistractorObject("signage", "object", _fixed(lambda: street.sign(2.2))),
    "bicycle": DistractorObject("bicycle", "object", _fixed(vehicles.bicycle)),
    "dog": DistractorObject("animal", "object", _fixed(nature.dog)),
    "plant": DistractorObject("vegetation", "object", _fixed(interior.potted_plant)),
    "stroller": DistractorObject("unlabelled", "hard_negative", _fixed(carts.stroller)),
    "shopping_trolley": DistractorObject("unlabelled", "hard_negative", _fixed(carts.shopping_trolley)),
    "empty_manual_wheelchair": DistractorObject("manual_wheelchair", "hard_negative",
                                                _fixed(devices.DEVICES["manual_wheelchair"])),
    "empty_electric_wheelchair": DistractorObject("electric_wheelchair", "hard_negative",
                                                  _fixed(devices.DEVICES["electric_wheelchair"])),
}
DISTRACTOR_OBJECTS = tuple(CATALOGUE)
PRIMITIVES = tuple(_SHAPES)
#: Parts that keep their own material whatever colours a distractor draws (tyres stay rubber).
KEPT_MATERIALS = ("Tyre",)
