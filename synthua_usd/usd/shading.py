"""UsdPreviewSurface networks → :class:`synthua_usd.model.scene.Material`: constants and UsdUVTexture images.

An input of the surface shader is either a value or a connection. Connections are followed through node
graphs and interface inputs (``UsdShade.Utils.GetValueProducingAttributes``) to what produces the value:

* an interface input of the material or a node graph: its value;
* an output of a ``UsdUVTexture`` whose ``st`` comes from a ``UsdPrimvarReader_float2`` (its ``varname``
  often an interface input such as ``frame:stPrimvarName``): a :class:`Texture` (file, ``sourceColorSpace``,
  ``wrapS``/``wrapT``, ``scale``, ``bias``, the output used) on the input;
* for diffuseColor, a ``UsdPrimvarReader_float3``: the gprim's primvar (:class:`Materials`);
* anything else (``UsdTransform2d``, other shaders, node graphs without a value): the input's constant,
  after a one-line warning naming the prim. So is a texture whose file is missing or cannot be read (the
  warning names the file and OpenImageIO's reason; only its header is read here).

A texture inside a ``.usdz`` package resolves (OpenUSD's Ar) to a package-relative path,
``/a/car.usdz[textures/body.png]``, which :class:`Texture` keeps as its ``path``; the image is read from the
package (:mod:`synthua_usd.core.texture_files`).

Supported textured inputs: diffuseColor, roughness, metallic, normal, opacity.
"""

from __future__ import annotations

import logging
import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade

from synthua_usd.core.errors import echo
from synthua_usd.core.texture_files import is_packaged, unreadable
from synthua_usd.model.scene import Material, Texture

log = logging.getLogger(__name__)

DEFAULT_MATERIAL = Material("default", (0.18, 0.18, 0.18), 0.5)

#: UsdPreviewSurface input → (Material constant field, Material texture field, channel count).
TEXTURED = {"diffuseColor": ("base_color", "base_color_texture", 3), "roughness": ("roughness", "roughness_texture", 1),
            "metallic": ("metallic", "metallic_texture", 1), "normal": (None, "normal_texture", 3),
            "opacity": ("opacity", "opacity_texture", 1)}
#: UsdUVTexture's wrap tokens → ours. 'useMetadata' asks the image file, which for PNG and JPEG says
#: nothing; repeat is what glTF and the DCC tools exporting UsdPreviewSurface assume.
WRAP = {"repeat": "repeat", "mirror": "mirror", "clamp": "clamp", "black": "black", "useMetadata": "repeat"}
COLOR_SPACE = {"auto": "auto", "sRGB": "sRGB", "raw": "raw"}


class Materials:
    """The materials of a stage's gprims, each network read once: what a stage reader holds.

    ``by_key`` maps material keys (a bound material's path, a ``displayColor(...)`` or ``default``) to
    :class:`Material`. A surface whose diffuseColor comes from a ``UsdPrimvarReader_float3`` (``displayColor``,
    as the usd-wg teapot's ceramic variants author it) takes each gprim's own primvar value: one material per
    colour, keyed ``<material>[<primvar>=(r,g,b)]``.
    """

    def __init__(self) -> None:
        self.by_key: dict[str, Material] = {}
        self._colour_primvar: dict[str, tuple[str, tuple[float, float, float] | None] | None] = {}

    def of(self, prim: Usd.Prim, t: Usd.TimeCode) -> Material:
        """The material of gprim ``prim``: its bound UsdPreviewSurface, else its displayColor, else grey."""
        bound, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
        if bound:
            key = str(bound.GetPath())
            if key not in self.by_key:
                self.by_key[key] = preview_surface(bound, key)
                self._colour_primvar[key] = _colour_primvar(bound)
            reader = self._colour_primvar[key]
            return self.by_key[key] if reader is None else self._coloured(prim, t, self.by_key[key], *reader)
        color = UsdGeom.Gprim(prim).GetDisplayColorAttr().Get(t)
        if color is not None and len(color) >= 1:
            rgb = tuple(float(c) for c in color[0])
            key = "displayColor(%.4f,%.4f,%.4f)" % rgb
            return self.by_key.setdefault(key, Material(key, rgb, 0.6))
        return self.by_key.setdefault(DEFAULT_MATERIAL.key, DEFAULT_MATERIAL)

    @staticmethod
    def base_of(key: str) -> str:
        """The bound material's own key of a material key (``<material>[<primvar>=...]`` -> ``<material>``)."""
        return key.split("[", 1)[0] if key.startswith("/") else key

    def forget(self, path: str, below: bool = False) -> set[str]:
        """Forget every bound material at or above the prim ``path`` (a shader in its network changed), and with
        ``below`` also those below it (the prim was recomposed), with their per-gprim colours; returns the
        material paths forgotten."""
        dropped = set()
        walk = Sdf.Path(path)
        while walk != Sdf.Path.emptyPath:
            if str(walk) in self._colour_primvar:
                dropped.add(str(walk))
            if walk.IsAbsoluteRootPath():
                break
            walk = walk.GetParentPath()
        if below:
            top = Sdf.Path(path)
            dropped |= {base for base in self._colour_primvar if Sdf.Path(base).HasPrefix(top)}
        if dropped:
            self.by_key = {k: v for k, v in self.by_key.items() if self.base_of(k) not in dropped}
            for base in dropped:
                del self._colour_primvar[base]
        return dropped

    def _coloured(self, prim: Usd.Prim, t: Usd.TimeCode, base: Material, name: str,
                  fallback: tuple[float, float, float] | None) -> Material:
        primvar = UsdGeom.PrimvarsAPI(prim).FindPrimvarWithInheritance(name)
        values = primvar.ComputeFlattened(t) if primvar and primvar.HasValue() else None
        data = np.asarray(values, np.float64) if values is not None else np.zeros((0, 3))
        if data.ndim == 2 and data.shape[1] == 3 and len(data) and np.all(np.isfinite(data)):
            rgb = tuple(float(c) for c in data.mean(axis=0))  # vertex colours: their mean, as flat shading can
        else:
            rgb = fallback if fallback is not None else base.base_color
        key = "%s[%s=(%.4f,%.4f,%.4f)]" % (base.key, name, *rgb)
        return self.by_key.setdefault(key, replace(base, key=key, base_color=rgb))


def preview_surface(material: UsdShade.Material, key: str) -> Material:
    """``material``'s UsdPreviewSurface as a :class:`Material` keyed ``key`` (grey, after a warning, when its
    surface is another shader)."""
    shader = material.ComputeSurfaceSource()[0]
    if not shader or shader.GetIdAttr().Get() != "UsdPreviewSurface":
        found = shader.GetIdAttr().Get() if shader else "no surface shader"
        log.warning("%s: surface is %s, not UsdPreviewSurface; rendering it grey", key, found)
        return Material(key, DEFAULT_MATERIAL.base_color, DEFAULT_MATERIAL.roughness)
    fields: dict = {}
    primvars: list[str] = []
    defaults = {"diffuseColor": Gf.Vec3f(0.18), "roughness": 0.5, "metallic": 0.0, "emissiveColor": Gf.Vec3f(0.0),
                "opacity": 1.0, "opacityThreshold": 0.0, "normal": None, "clearcoat": 0.0, "clearcoatRoughness": 0.01}
    values = {}
    for name, fallback in defaults.items():
        value, texture, primvar = _input(shader, name, fallback)
        values[name] = value
        if texture is not None:
            fields[TEXTURED[name][1]] = texture
            primvars.append(primvar)
    if len(set(primvars)) > 1:
        log.warning("%s: textures read texture coordinates from different primvars (%s); using '%s' for all",
                    key, ", ".join(sorted(set(primvars))), primvars[0])
    return Material(key, base_color=tuple(float(c) for c in values["diffuseColor"]),
                    roughness=float(values["roughness"]), metallic=float(values["metallic"]),
                    emissive_color=tuple(float(c) for c in values["emissiveColor"]),
                    opacity=float(values["opacity"]), opacity_threshold=float(values["opacityThreshold"]),
                    clearcoat=float(values["clearcoat"]), clearcoat_roughness=float(values["clearcoatRoughness"]),
                    uv_primvar=primvars[0] if primvars else "st", **fields)


def _input(shader: UsdShade.Shader, name: str, fallback):
    """(constant, texture or None, primvar name or None) of the surface input ``name``."""
    inp = shader.GetInput(name)
    if not inp:
        return fallback, None, None
    own = inp.Get() if inp.GetAttr().HasAuthoredValue() else None
    constant = fallback if own is None else own
    if not inp.HasConnectedSource():
        return constant, None, None
    where = f"{shader.GetPath()}: input '{name}'"
    attrs = UsdShade.Utils.GetValueProducingAttributes(inp)
    if not attrs:
        log.warning("%s is connected to nothing that produces a value; using the constant %s", where, constant)
        return constant, None, None
    attr = attrs[0]
    base, kind = UsdShade.Utils.GetBaseNameAndType(attr.GetName())
    if kind != UsdShade.AttributeType.Output:  # an interface input with a value
        value = attr.Get()
        return (constant if value is None else value), None, None
    source = UsdShade.Shader(attr.GetPrim())
    shader_id = source.GetShaderId() if source else None
    if shader_id == "UsdPrimvarReader_float3" and name == "diffuseColor":  # per gprim: Materials.of
        return constant, None, None
    if shader_id != "UsdUVTexture" or name not in TEXTURED:
        what = f"'{shader_id}'" if shader_id else "a node graph"
        log.warning("%s is connected to %s at %s, which synthua does not translate; using the constant %s",
                    where, echo(what), attr.GetPrim().GetPath(), constant)
        return constant, None, None
    found = _texture(source, base, where)
    if found is None:
        return constant, None, None
    return constant, found[0], found[1]


def _colour_primvar(material: UsdShade.Material) -> tuple[str, tuple[float, float, float] | None] | None:
    """(primvar name, the reader's fallback colour or None) when ``material``'s diffuseColor comes from a
    UsdPrimvarReader_float3, else None."""
    shader = material.ComputeSurfaceSource()[0]
    inp = shader.GetInput("diffuseColor") if shader else None
    if not inp or not inp.HasConnectedSource():
        return None
    attrs = UsdShade.Utils.GetValueProducingAttributes(inp)
    if not attrs or UsdShade.Utils.GetBaseNameAndType(attrs[0].GetName())[1] != UsdShade.AttributeType.Output:
        return None
    reader = UsdShade.Shader(attrs[0].GetPrim())
    if not reader or reader.GetShaderId() != "UsdPrimvarReader_float3":
        return None
    name = _value(reader, "varname", "")
    fallback = _value(reader, "fallback", None)
    return (str(name), tuple(float(c) for c in fallback) if fallback is not None else None) if name else None


def _texture(shader: UsdShade.Shader, output: str, where: str) -> tuple[Texture, str] | None:
    """The UsdUVTexture ``shader`` read through its ``output`` as (texture, st primvar name), or None after a
    warning that says why the input falls back to its constant."""
    path = shader.GetPath()
    asset = _value(shader, "file", Sdf.AssetPath(""))
    authored = asset.path if isinstance(asset, Sdf.AssetPath) else str(asset)
    if "<UDIM>" in authored:
        log.warning("%s: texture %s: UDIM file '%s' is not supported; using the input's constant", where, path,
                    echo(authored))
        return None
    resolved = asset.resolvedPath if isinstance(asset, Sdf.AssetPath) else ""
    if not authored or not resolved:
        log.warning("%s: texture file '%s' of %s was not found; using the input's constant", where, echo(authored),
                    path)
        return None
    reason = unreadable(resolved)
    if reason is not None:
        log.warning("%s: texture file '%s' of %s (%s) cannot be read: %s; using the input's constant", where,
                    echo(authored), path, echo(resolved), echo(reason))
        return None
    primvar = _st_primvar(shader, where)
    if primvar is None:
        return None
    wrap = []
    for axis in ("wrapS", "wrapT"):
        token = str(_value(shader, axis, "useMetadata"))
        if token not in WRAP:
            log.warning("%s: %s: %s '%s' is not a UsdUVTexture wrap mode; using repeat", where, path, axis, echo(token))
        wrap.append(WRAP.get(token, "repeat"))
    space = str(_value(shader, "sourceColorSpace", "auto"))
    if space not in COLOR_SPACE:
        log.warning("%s: %s: sourceColorSpace '%s' is not auto, sRGB or raw; using auto", where, path, echo(space))
    channel = output if output in ("rgb", "r", "g", "b", "a") else None
    if channel is None:
        log.warning("%s: %s: output '%s' is not rgb, r, g, b or a; using the input's constant", where, path,
                    echo(output))
        return None
    factors = {}
    for name, default in (("scale", Gf.Vec4f(1.0)), ("bias", Gf.Vec4f(0.0))):
        value = _value(shader, name, default)
        numbers = tuple(float(v) for v in value) if hasattr(value, "__len__") else (value,)
        if len(numbers) != 4 or not all(math.isfinite(v) for v in numbers):
            log.warning("%s: texture %s: %s is %s; expected 4 finite numbers (float4, RGBA); using the input's "
                        "constant", where, path, name, echo(numbers))
            return None
        factors[name] = numbers
    return Texture(resolved if is_packaged(resolved) else str(Path(resolved).resolve()), channel=channel,
                   color_space=COLOR_SPACE.get(space, "auto"),
                   wrap_s=wrap[0], wrap_t=wrap[1], **factors), primvar


def _st_primvar(shader: UsdShade.Shader, where: str) -> str | None:
    """The primvar name the texture's ``st`` reads, through a UsdPrimvarReader_float2; None after a warning."""
    st = shader.GetInput("st")
    attrs = UsdShade.Utils.GetValueProducingAttributes(st) if st and st.HasConnectedSource() else []
    reader = UsdShade.Shader(attrs[0].GetPrim()) if attrs else None
    kind = UsdShade.Utils.GetBaseNameAndType(attrs[0].GetName())[1] if attrs else None
    if not reader or kind != UsdShade.AttributeType.Output or reader.GetShaderId() != "UsdPrimvarReader_float2":
        found = f"'{reader.GetShaderId()}' at {reader.GetPath()}" if reader and kind == UsdShade.AttributeType.Output \
            else "no primvar reader"
        log.warning("%s: texture %s: st comes from %s; supported: a UsdPrimvarReader_float2; using the input's "
                    "constant", where, shader.GetPath(), echo(found))
        return None
    name = _value(reader, "varname", "")
    if not name:
        log.warning("%s: primvar reader %s has no varname; using the input's constant", where, reader.GetPath())
        return None
    return str(name)


def _value(shader: UsdShade.Shader, name: str, fallback):
    """The value of ``shader``'s input ``name``, following a connection to an interface input."""
    inp = shader.GetInput(name)
    if not inp:
        return fallback
    if inp.HasConnectedSource():
        attrs = UsdShade.Utils.GetValueProducingAttributes(inp)
        value = attrs[0].Get() if attrs else None
    else:
        value = inp.Get()
    return fallback if value is None else value
