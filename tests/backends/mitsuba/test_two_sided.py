"""Open shells of imports render lit from both sides: the importer authors ``doubleSided``, the reader keeps it,
the translator wraps the BSDF in Mitsuba's ``twosided``."""

import dataclasses

import numpy as np
import pytest
from pxr import UsdGeom

from synthua_usd.backends.mitsuba import variants
from synthua_usd.backends.mitsuba.translate import translate
from synthua_usd.composition.scenario import StageMetadata
from synthua_usd.importers.mesh import import_mesh
from synthua_usd.model.cameras import PinholeCamera
from synthua_usd.model.class_assignment import AssignmentRules
from synthua_usd.model.meshes import look_at
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.model.scene import Light
from synthua_usd.usd.reader import read_snapshot
from synthua_usd.usd.scenario_writer import write_twin_layers
from synthua_usd.usd.stage_io import open_stage

#: A 4 x 4 m quad at z = 0 wound clockwise seen from above: its front faces down, an open shell.
OBJ = """o Sheet
v -2 -2 0
v -2 2 0
v 2 2 0
v 2 -2 0
f 1 2 3
f 1 3 4
"""


def _render(mi, snapshot, eye_z: float) -> float:
    """Mean radiance of a 16 x 16 view from ``eye_z`` above (or below) the quad's centre, sun from above."""
    sun = Light("/Sun", "distant", (1.0, 1.0, 1.0), direction=(0.0, 0.0, -1.0), irradiance=3.0)
    snap = dataclasses.replace(snapshot, lights=(sun,))
    camera = PinholeCamera("/Cam", 50.0, 36.0, 36.0, 0.05, 100.0,
                           look_at((0.3, 0.2, eye_z), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0)))
    scene = translate(mi, snap, camera, RenderConfig(width=16, height=16, spp=8)).load(mi)
    return float(np.asarray(mi.render(scene, seed=0)).mean())


@pytest.fixture(scope="module")
def sheets(tmp_path_factory, class_map):
    folder = tmp_path_factory.mktemp("sheet")
    (folder / "sheet.obj").write_text(OBJ)
    rules = AssignmentRules.from_document({"rules": [{"field": "object", "pattern": ".", "class": "building"}]},
                                          class_map)
    model = import_mesh(folder / "sheet.obj", rules, up_axis="Z")
    assert model.double_sided
    out = {}
    for name, m in (("two", model), ("one", dataclasses.replace(model, double_sided=False))):
        write_twin_layers(m, folder / name, class_map, StageMetadata(start_time_code=1, end_time_code=1))
        stage = open_stage(folder / name / "twin.usdc")
        gprim = next(p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh))
        assert bool(UsdGeom.Mesh(gprim).GetDoubleSidedAttr().Get()) is (name == "two")
        out[name] = read_snapshot(stage, 1.0, class_map)
    return out


def test_an_open_shell_renders_lit_from_both_sides(sheets, variant):
    mi = variants.activate(variant)
    two, one = sheets["two"], sheets["one"]
    assert two.meshes[0].double_sided and not one.meshes[0].double_sided
    # Seen from above, lit from above: the quad's back face. One-sided it is black, two-sided it is lit.
    back_one, back_two = _render(mi, one, 5.0), _render(mi, two, 5.0)
    assert back_one < 1e-3 < back_two
    # Two-sided, the back seen lit equals the front seen lit (the same scene mirrored through z = 0).
    flipped = dataclasses.replace(two, meshes=(dataclasses.replace(two.meshes[0],
                                                                   triangles=two.meshes[0].triangles[:, ::-1]),))
    assert back_two == pytest.approx(_render(mi, flipped, 5.0), rel=0.02)
