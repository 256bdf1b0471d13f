"""Kernels a new scene compiles (issue 39): BSDFs alike in all but their values share their code in Dr.Jit's
path-tracing kernel, so a randomised scene (a new wardrobe of tints, weathered materials) compiles a kernel of
about the same size as any other. Before, every garment's tint was a constant of the kernel and every weathered
material recorded its own call over all shapes: 17.5 s of LLVM compilation for each new district scene, 25 s
under snow (8,508 and 358,602 operations), against about a second now."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from synthua_usd.backends.mitsuba import shape_tables, variants
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.model.render_config import RenderConfig
from synthua_usd.usd.cameras import read_camera
from synthua_usd.usd.conditions import read_condition
from synthua_usd.usd.reader import StageReader
from synthua_usd.usd.stage_io import open_stage

pytestmark = pytest.mark.usefixtures("llvm")


@pytest.fixture(scope="module")
def llvm():
    from conftest import activate_variant

    activate_variant("llvm_ad_rgb")  # skips, with the reason, where libLLVM 19 is missing


def path_kernel_operations(render) -> int:
    """Operations of the largest kernel ``render()`` launches (the path tracer's megakernel)."""
    import drjit as dr

    dr.set_flag(dr.JitFlag.KernelHistory, True)
    try:
        dr.kernel_history()
        render()
        return max(k["operation_count"] for k in dr.kernel_history() if "operation_count" in k)
    finally:
        dr.set_flag(dr.JitFlag.KernelHistory, False)


def test_tints_of_one_image_share_one_kernel():
    """The ``affine`` texture's scale and bias are opaque: five tints of one bitmap compile what one does."""
    import drjit as dr

    from synthua_usd.backends.mitsuba import affine_texture

    mi = variants.activate("llvm_ad_rgb")
    affine_texture.register(mi)

    def scene(tints: int):
        image = mi.load_dict({"type": "bitmap", "data": mi.TensorXf(np.full((4, 4, 3), 0.5, np.float32)), "raw": True})
        document = {"type": "scene", "integrator": {"type": "path", "max_depth": 3}, "light": {"type": "constant"},
                    "sensor": {"type": "perspective", "film": {"type": "hdrfilm", "width": 8, "height": 8},
                               "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0],
                                                                          up=[0, 1, 0])}}
        for k in range(tints):
            tint = mi.load_dict({"type": "affine", "texture": image, "scale": mi.ScalarColor3f(0.2 + 0.1 * k, 1, 1),
                                 "bias": mi.ScalarColor3f(0, 0.01 * k, 0)})
            document[f"ball_{k}"] = {"type": "sphere", "center": [k - 2.0, 0, 0], "radius": 0.4,
                                     "bsdf": {"type": "principled", "base_color": tint}}
        return mi.load_dict(document)

    one = path_kernel_operations(lambda: dr.eval(mi.render(scene(1))))
    five = path_kernel_operations(lambda: dr.eval(mi.render(scene(5))))
    assert five <= one * 1.01, (one, five)  # literal tints: 2,006 and 5,408 operations


@pytest.fixture(scope="module")
def street(lamps_scenario, class_map):
    """The lamp street's snapshot, camera and snowy and wet conditions; and the same snapshot with five copies of
    every mesh (100 m aside each), each copy with a material of its own, another colour."""
    stage = open_stage(lamps_scenario)
    snapshot = StageReader(stage, class_map).snapshot(1)
    rng = np.random.default_rng(0)
    materials, meshes = dict(snapshot.materials), list(snapshot.meshes)
    for copy in range(1, 6):
        for k, mesh in enumerate(snapshot.meshes):
            key = f"own_{copy}_{k}"
            materials[key] = dataclasses.replace(snapshot.materials[mesh.material_key], key=key,
                                                 base_color=tuple(float(v) for v in rng.uniform(0.1, 0.9, 3)))
            meshes.append(dataclasses.replace(mesh, material_key=key, points=mesh.points + [100.0 * copy, 0, 0]))
    own = dataclasses.replace(snapshot, meshes=tuple(meshes), materials=materials)
    camera = read_camera(stage, "/World/Cam", 1)
    conditions = {name: read_condition(stage, name) for name in ("snow", "day_rain_fog")}
    return snapshot, own, camera, conditions


def render(snapshot, camera, condition, spp: int = 4):
    session = RenderSession(RenderConfig(width=48, height=36, spp=spp, denoise=False, variant="llvm_ad_rgb"))
    return session.render(snapshot, camera, condition=condition, seed=3)


@pytest.mark.parametrize("name", ["snow", "day_rain_fog"])
def test_weathered_materials_alike_share_one_kernel(street, name):
    snapshot, own, camera, conditions = street
    shared = path_kernel_operations(lambda: render(snapshot, camera, conditions[name]))
    separate = path_kernel_operations(lambda: render(own, camera, conditions[name]))
    assert len({m.material_key for m in own.meshes}) >= 5 * len({m.material_key for m in snapshot.meshes})
    assert separate <= shared * 1.05, (shared, separate)


@pytest.mark.parametrize("name", ["snow", "day_rain_fog"])
def test_face_weights_from_the_table_render_what_mesh_attributes_render(street, name, monkeypatch):
    """The table holds the same float32 weights Mitsuba's ``mesh_attribute`` reads: the same image, bit for bit."""
    snapshot, own, camera, conditions = street
    table = render(own, camera, conditions[name])
    monkeypatch.setattr(shape_tables, "enabled", lambda mi: False)
    attributes = render(own, camera, conditions[name])
    weathered = table.rgb[table.class_ids > 0]
    assert np.array_equal(table.rgb, attributes.rgb) and weathered.std() > 0
