"""Independent checks of textured renders for tests, and the textured-quad stage edits they share.

The reference casts pixel-centre rays with Embree (trimesh), interpolates the reader's texture coordinates
(``MeshItem.uvs``) with the hit's barycentric coordinates, and looks the texel up in numpy (bilinear, texel
centres at (i + 0.5) / N, t measured from the image's bottom row as USD says), decoding 8-bit values with
colour-science's sRGB transfer function. Mitsuba's side is the BSDF's diffuse reflectance (its albedo) at the
first hit of each ray, which for ``principled`` is the base colour: no light transport, exact values.
"""

from __future__ import annotations

import shutil

import numpy as np
import trimesh
from conftest import DATA
from pxr import Sdf, UsdGeom, UsdLux, UsdShade

from synthua_usd.backends.mitsuba.translate import translate
from synthua_usd.core.images import write_color_png
from synthua_usd.model.render_config import RenderConfig


#: 8 wide, 6 tall, every texel different: a transposed, mirrored or flipped lookup cannot pass.
TEXELS = np.random.default_rng(7).integers(0, 256, (6, 8, 3), dtype=np.uint8)


def textured_quads(folder, texels: np.ndarray = TEXELS):
    """A copy of tests/data/valid/textured_quads.usda in ``folder`` with ``texels`` as its texture; its path."""
    shutil.copy(DATA / "valid" / "textured_quads.usda", folder / "quads.usda")
    write_png(folder / "textures" / "quadrants.png", texels)
    return folder / "quads.usda"


def write_png(path, pixels: np.ndarray) -> None:
    """``pixels`` (H, W, C) uint8 as a PNG at ``path``, its folder made (the library's writer of texture images)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    write_color_png(path, np.ascontiguousarray(pixels, np.uint8))


def bilinear(image: np.ndarray, st: np.ndarray) -> np.ndarray:
    """(k, C) values of ``image`` (H, W, C; row 0 at the top) at USD ``st`` (k, 2), bilinear, repeat wrap."""
    h, w = image.shape[:2]
    x = st[:, 0] * w - 0.5
    y = (1.0 - st[:, 1]) * h - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]

    def at(yy, xx):
        return image[yy % h, xx % w]

    return ((1 - fx) * (1 - fy) * at(y0, x0) + fx * (1 - fy) * at(y0, x0 + 1)
            + (1 - fx) * fy * at(y0 + 1, x0) + fx * fy * at(y0 + 1, x0 + 1))


def reference_albedo(snapshot, camera, linear_texels: np.ndarray, W: int, H: int):
    """(H*W, 3) texel values at the first hit of every pixel-centre ray, and the (H*W,) hit mask."""
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    origins, dirs = camera.pixel_center_rays(W, H)
    verts, faces, owner = snapshot.world_triangles()
    uvs = np.concatenate([m.uvs for m in snapshot.meshes])
    mesh = trimesh.Trimesh(verts, faces, process=False, validate=False)
    tri, ray, where = RayMeshIntersector(mesh).intersects_id(origins, dirs, multiple_hits=False,
                                                             return_locations=True)
    bary = trimesh.triangles.points_to_barycentric(verts[faces[tri]], where)
    st = np.einsum("kc,kcd->kd", bary, uvs[faces[tri]])
    out = np.zeros((W * H, 3))
    out[ray] = bilinear(linear_texels, st)
    hit = np.zeros(W * H, bool)
    hit[ray] = True
    return out, hit


def mitsuba_albedo(mi, snapshot, camera, W: int, H: int):
    """(H*W, 3) diffuse reflectance of the BSDF at the first hit of every pixel-centre ray, and the hit mask."""
    tr = translate(mi, snapshot, camera, RenderConfig(width=W, height=H, spp=1))
    scene = tr.load(mi)
    origins, dirs = (a.astype(np.float32) for a in camera.pixel_center_rays(W, H))
    if mi.variant().startswith("scalar"):
        albedo, hit = np.zeros((W * H, 3)), np.zeros(W * H, bool)
        for k, (o, d) in enumerate(zip(origins, dirs)):
            si = scene.ray_intersect(mi.Ray3f(mi.Point3f(*o), mi.Vector3f(*d)))
            if si.is_valid():
                hit[k] = True
                albedo[k] = np.array(si.bsdf().eval_diffuse_reflectance(si))
        return albedo, hit
    ray = mi.Ray3f(mi.Point3f(*origins.T), mi.Vector3f(*dirs.T))
    si = scene.ray_intersect(ray)
    return np.array(si.bsdf().eval_diffuse_reflectance(si, si.is_valid())).T, np.array(si.is_valid())


def srgb_decoded(texels: np.ndarray) -> np.ndarray:
    import colour  # colour-science: imported by the tests that decode, not by every worker's collection

    return colour.models.eotf_sRGB(texels / 255.0)


def srgb_decoded(texels: np.ndarray) -> np.ndarray:
    """Linear values of 8-bit sRGB ``texels`` (colour-science, not synthua's decoder)."""
    import colour  # colour-science: imported by the tests that decode, not by every worker's collection

    return colour.models.eotf_sRGB(texels / 255.0)


def add_texture(stage, name: str, file: str, output: str, target: str, type_name, **inputs) -> None:
    """A UsdUVTexture ``name`` reading ``file`` through the material's st reader, feeding surface input
    ``target`` from ``output``."""
    looks = "/World/Looks/Quadrants"
    shader = UsdShade.Shader.Define(stage, f"{looks}/{name}")
    shader.CreateIdAttr("UsdUVTexture")
    shader.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(file)
    shader.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(
        UsdShade.Shader(stage.GetPrimAtPath(f"{looks}/StReader")).ConnectableAPI(), "result")
    for key, (vtype, value) in inputs.items():
        shader.CreateInput(key, vtype).Set(value)
    shader.CreateOutput(output, type_name)
    surface = UsdShade.Shader(stage.GetPrimAtPath(f"{looks}/Surface"))
    surface.CreateInput(target, type_name).ConnectToSource(shader.ConnectableAPI(), output)


def lit_from(stage, axis: str) -> None:
    """Replace the sky by a sun 60° off vertical, shining from +X or +Y (``axis``), and a dim sky."""
    stage.GetPrimAtPath("/World/Sky").GetAttribute("inputs:intensity").Set(0.05)
    sun = UsdLux.DistantLight.Define(stage, "/World/Sun")
    sun.CreateIntensityAttr(3.0)
    if axis == "x":
        UsdGeom.Xformable(sun).AddRotateYOp().Set(60.0)  # the light's -Z towards -X and down
    else:
        UsdGeom.Xformable(sun).AddRotateXOp().Set(-60.0)  # the light's -Z towards -Y and down
