"""Small helpers that author layers the way every synthua layer is authored.

Every layer states (:class:`synthua_usd.composition.scenario.StageMetadata`) ``upAxis``, ``metersPerUnit``, ``defaultPrim`` and ``timeCodesPerSecond``; meshes carry
extents; materials are UsdPreviewSurface; labels use UsdSemantics.LabelsAPI with the taxonomy as
instance name.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pxr import Gf, Kind, Sdf, Tf, Usd, UsdGeom, UsdSemantics, UsdShade, Vt

from synthua_usd.composition.scenario import StageMetadata
from synthua_usd.core.atomic import atomic_path, write_failure
from synthua_usd.core.errors import InputError, echo
from synthua_usd.model.scene import Material
from synthua_usd.usd.stage_io import tf_message


def new_layer(meta: StageMetadata, doc: str) -> Usd.Stage:
    """An in-memory stage whose root layer will be saved as a synthua layer."""
    stage = Usd.Stage.CreateInMemory()
    apply_metadata(stage, meta)
    stage.GetRootLayer().documentation = doc
    return stage


def apply_metadata(stage: Usd.Stage, meta: StageMetadata) -> None:
    UsdGeom.SetStageUpAxis(stage, meta.up_axis)
    UsdGeom.SetStageMetersPerUnit(stage, meta.meters_per_unit)
    stage.SetTimeCodesPerSecond(meta.time_codes_per_second)
    stage.SetFramesPerSecond(meta.time_codes_per_second)
    stage.SetStartTimeCode(meta.start_time_code)
    stage.SetEndTimeCode(meta.end_time_code)
    stage.GetRootLayer().defaultPrim = meta.default_prim


#: The extensions a layer is written under: OpenUSD picks the format by them (``.usd`` is a crate) and
#: writes text under any other name, a USDA that no USD tool opens as ``out.txt``. (``.usdz`` is a package.)
LAYER_SUFFIXES = (".usda", ".usdc", ".usd")


def check_layer_path(path: str | Path, what: str = "the layer") -> Path:
    """``path`` when its extension is one of :data:`LAYER_SUFFIXES`, else an :class:`InputError` naming it."""
    path = Path(path)
    if path.suffix.lower() not in LAYER_SUFFIXES:
        raise InputError(f"{echo(path)}: {what} needs a USD file name (.usda text, .usdc binary or .usd); found the "
                         f"extension '{echo(path.suffix)}'")
    return path


def save_layer_atomic(layer: Sdf.Layer, path: str | Path) -> Path:
    """Export ``layer`` to ``path`` through a temporary file and a rename; the suffix picks the format
    (``.usda`` text, ``.usdc`` binary crate)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        export_layer(layer, tmp, path)
    return path


def export_layer(layer: Sdf.Layer, tmp: Path, path: Path) -> None:
    """Write ``layer`` to the temporary file ``tmp`` of the output ``path``. OpenUSD reports a failed write
    (a full disk, a file-size limit) as a Tf error or a False without an errno: either becomes the
    ``OSError`` naming ``path`` that :func:`synthua_usd.core.atomic.write_failure` finds (ENOSPC on a full disk)."""
    check_layer_path(path)
    try:
        written = layer.Export(str(tmp))
        reason = "OpenUSD could not write the layer"
    except Tf.ErrorException as exc:
        written, reason = False, f"OpenUSD could not write the layer ({tf_message(exc)})"
    if not written:
        raise write_failure(path, tmp, reason)


def define_xform(stage: Usd.Stage, path: str, kind: str | None = None,
                 translate: tuple[float, float, float] | None = None,
                 rotate_z_deg: float | None = None) -> UsdGeom.Xform:
    xf = UsdGeom.Xform.Define(stage, path)
    if kind:
        Usd.ModelAPI(xf.GetPrim()).SetKind(kind)
    if translate is not None:
        xf.AddTranslateOp().Set(Gf.Vec3d(*translate))
    if rotate_z_deg is not None:
        xf.AddRotateZOp().Set(float(rotate_z_deg))
    return xf


def define_mesh(stage: Usd.Stage, path: str, points: np.ndarray, triangles: np.ndarray,
                material: UsdShade.Material | None = None, uvs: np.ndarray | None = None,
                uv_primvar: str = "st", normals: np.ndarray | None = None) -> UsdGeom.Mesh:
    """A triangle mesh. ``points`` (n, 3) float, local metres; ``triangles`` (m, 3) int, CCW front faces;
    ``uvs`` (n, 2) texture coordinates per point, authored as ``primvars:<uv_primvar>`` (texCoord2f, vertex);
    ``normals`` (n, 3) unit shading normals per point (``normals``, vertex interpolation: smooth shading)."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    pts = np.asarray(points, np.float32)
    tris = np.asarray(triangles, np.int32)
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pts))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(tris), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(tris.reshape(-1)))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateExtentAttr(Vt.Vec3fArray([Gf.Vec3f(*map(float, pts.min(0))), Gf.Vec3f(*map(float, pts.max(0)))]))
    if uvs is not None:
        UsdGeom.PrimvarsAPI(mesh).CreatePrimvar(uv_primvar, Sdf.ValueTypeNames.TexCoord2fArray,
                                                UsdGeom.Tokens.vertex).Set(
            Vt.Vec2fArray.FromNumpy(np.ascontiguousarray(uvs, np.float32)))
    if normals is not None:
        mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(normals, np.float32)))
        mesh.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    if material is not None:
        bind_material(mesh.GetPrim(), material)
    return mesh


def bind_material(prim: Usd.Prim, material: UsdShade.Material) -> None:
    UsdShade.MaterialBindingAPI.Apply(prim).Bind(material)


def bind_material_path(prim: Usd.Prim, material: Sdf.Path | str) -> None:
    """Bind the material at ``material``, a path that may live in another layer of the stack (not composed in
    the stage being authored)."""
    UsdShade.MaterialBindingAPI.Apply(prim)
    prim.CreateRelationship(UsdShade.Tokens.materialBinding, False).SetTargets([Sdf.Path(str(material))])


def define_preview_material(stage: Usd.Stage, path: str, spec: Material) -> UsdShade.Material:
    """A UsdPreviewSurface material: constant inputs, and a UsdUVTexture per texture of ``spec`` (its path
    authored relative to the layer, ``./textures/...``) reading st through one UsdPrimvarReader_float2 whose
    varname is the material's interface input ``frame:stPrimvarName``, as USD's own examples do."""
    material = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, f"{path}/PreviewSurface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*spec.base_color))
    shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(float(spec.roughness))
    shader.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(float(spec.metallic))
    if any(spec.emissive_color):
        shader.CreateInput("emissiveColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*spec.emissive_color))
    if spec.opacity != 1.0:
        shader.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(float(spec.opacity))
    if spec.opacity_threshold != 0.0:
        shader.CreateInput("opacityThreshold", Sdf.ValueTypeNames.Float).Set(float(spec.opacity_threshold))
    if spec.clearcoat != 0.0:
        shader.CreateInput("clearcoat", Sdf.ValueTypeNames.Float).Set(float(spec.clearcoat))
        shader.CreateInput("clearcoatRoughness", Sdf.ValueTypeNames.Float).Set(float(spec.clearcoat_roughness))
    if spec.textures:
        _define_textures(stage, material, shader, spec)
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    return material


#: Material texture field → (UsdPreviewSurface input, its value type).
_TEXTURE_INPUTS = {"base_color_texture": ("diffuseColor", Sdf.ValueTypeNames.Color3f),
                   "roughness_texture": ("roughness", Sdf.ValueTypeNames.Float),
                   "metallic_texture": ("metallic", Sdf.ValueTypeNames.Float),
                   "normal_texture": ("normal", Sdf.ValueTypeNames.Normal3f),
                   "opacity_texture": ("opacity", Sdf.ValueTypeNames.Float)}


def _define_textures(stage: Usd.Stage, material: UsdShade.Material, surface: UsdShade.Shader, spec: Material) -> None:
    path = material.GetPath()
    frame = material.CreateInput("frame:stPrimvarName", Sdf.ValueTypeNames.String)
    frame.Set(spec.uv_primvar)
    reader = UsdShade.Shader.Define(stage, path.AppendChild("StReader"))
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.String).ConnectToSource(frame)
    st = reader.CreateOutput("result", Sdf.ValueTypeNames.Float2)
    for field_name, texture in spec.textures.items():
        name, value_type = _TEXTURE_INPUTS[field_name]
        image = UsdShade.Shader.Define(stage, path.AppendChild(f"{name[0].upper()}{name[1:]}Texture"))
        image.CreateIdAttr("UsdUVTexture")
        file = texture.path if texture.path.startswith(("./", "../", "/")) else f"./{texture.path}"
        image.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(file))
        image.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(st)
        image.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set(texture.color_space)
        image.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set(texture.wrap_s)
        image.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set(texture.wrap_t)
        if texture.scale != (1.0, 1.0, 1.0, 1.0):
            image.CreateInput("scale", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(*texture.scale))
        if texture.bias != (0.0, 0.0, 0.0, 0.0):
            image.CreateInput("bias", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(*texture.bias))
        output_type = Sdf.ValueTypeNames.Float3 if texture.channel == "rgb" else Sdf.ValueTypeNames.Float
        output = image.CreateOutput(texture.channel, output_type)
        surface.CreateInput(name, value_type).ConnectToSource(output)


def apply_label(prim: Usd.Prim, taxonomy: str, label: str) -> None:
    """Give ``prim`` (and, by inheritance, everything below it) one class of ``taxonomy``."""
    UsdSemantics.LabelsAPI.Apply(prim, taxonomy).CreateLabelsAttr([label])


def set_kind(prim: Usd.Prim, kind: str = Kind.Tokens.component) -> None:
    Usd.ModelAPI(prim).SetKind(kind)
