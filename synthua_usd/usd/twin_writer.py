"""Authoring a :class:`TwinModel` as two layers: the twin (geometry, UsdPreviewSurface materials) and the
semantics (UsdSemantics label overs). Every object path and label is checked against the class map first."""

from __future__ import annotations

import logging

from pxr import Gf, Kind, Sdf, Usd

from synthua_usd.composition.scenario import StageMetadata
from synthua_usd.core.errors import InputError
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.model.twin import TwinModel, prim_name
from synthua_usd.usd.authoring import (apply_label, define_mesh, define_preview_material, define_xform, new_layer,
                                       set_kind)

log = logging.getLogger(__name__)

TWIN_ROOT = "/World/Twin"


def author_twin(model: TwinModel, class_map: ClassMap, meta: StageMetadata) -> tuple[Usd.Stage, Usd.Stage]:
    """The twin layer and the semantics layer of ``model`` as two in-memory stages."""
    for obj in model.objects:
        if class_map.resolve(obj.label) is None:
            raise InputError(f"{model.source}: object {obj.path}: label '{obj.label}' is not a class of "
                             f"{class_map.source}")
    _check_textures(model)
    twin = new_layer(meta, f"synthua twin from {model.source}: geometry and UsdPreviewSurface materials.")
    twin.SetDefaultPrim(define_xform(twin, "/World", kind=Kind.Tokens.assembly).GetPrim())
    define_xform(twin, TWIN_ROOT, kind=Kind.Tokens.group)
    data = {"synthua:source": model.source,
            "synthua:origin_offset_m": Gf.Vec3d(*model.origin_offset_m)}
    if model.crs:
        data["synthua:crs"] = model.crs
    twin.GetRootLayer().customLayerData = data
    looks = {key: define_preview_material(twin, f"/World/Looks/{_safe(key)}", spec)
             for key, spec in sorted(model.materials.items())}
    semantics = new_layer(meta, f"synthua twin from {model.source}: class labels (taxonomy '{class_map.taxonomy}').")
    semantics.SetDefaultPrim(semantics.OverridePrim("/World"))
    for obj in model.objects:
        path = f"{TWIN_ROOT}/{obj.path}"
        parent = path.rsplit("/", 1)[0]
        if not twin.GetPrimAtPath(parent):
            # Intermediate folders group models.
            pieces = parent.split("/")
            for i in range(4, len(pieces) + 1):
                sub = "/".join(pieces[:i])
                if not twin.GetPrimAtPath(sub):
                    define_xform(twin, sub, kind=Kind.Tokens.group)
        xf = define_xform(twin, path)
        set_kind(xf.GetPrim(), Kind.Tokens.component)
        for key, value in sorted(obj.attributes.items()):
            _set_custom(xf.GetPrim(), key, value)
        for part in obj.parts:
            if len(part.triangles) == 0:
                continue
            spec = model.materials[part.material]
            uvs = part.uvs if spec.textures else None
            mesh = define_mesh(twin, f"{path}/{part.name}", part.points, part.triangles, looks[part.material], uvs,
                               spec.uv_primvar)
            if model.double_sided:
                mesh.CreateDoubleSidedAttr(True)
            for key, value in sorted(part.attributes.items()):
                _set_custom(mesh.GetPrim(), key, value)
        apply_label(semantics.OverridePrim(path), class_map.taxonomy, class_map.resolve(obj.label).name)
    return twin, semantics



def _check_textures(model: TwinModel) -> None:
    """Every texture a material names is one of the model's images, and every textured part has uvs."""
    for key, spec in model.materials.items():
        for texture in spec.textures.values():
            if texture.path not in model.images:
                raise InputError(f"{model.source}: material {key}: texture '{texture.path}' is not among the "
                                 f"twin's images ({', '.join(sorted(model.images)) or 'none'}); expected every "
                                 f"texture to come with its image")
    for obj in model.objects:
        for part in obj.parts:
            if part.uvs is None and model.materials[part.material].textures:
                log.warning("%s: %s/%s has textured material %s but no texture coordinates; it renders the "
                            "material's constants", model.source, obj.path, part.name, part.material)


def _safe(key: str) -> str:
    return prim_name(key, "Material")


def _set_custom(prim, key: str, value) -> None:
    """A ``synthua:``-namespaced custom attribute holding source provenance (strings, numbers)."""
    name = key if ":" in key else f"synthua:{key}"
    if isinstance(value, bool):
        prim.CreateAttribute(name, Sdf.ValueTypeNames.Bool, custom=True).Set(value)
    elif isinstance(value, int):
        prim.CreateAttribute(name, Sdf.ValueTypeNames.Int, custom=True).Set(value)
    elif isinstance(value, float):
        prim.CreateAttribute(name, Sdf.ValueTypeNames.Double, custom=True).Set(value)
    else:
        prim.CreateAttribute(name, Sdf.ValueTypeNames.String, custom=True).Set(str(value))
