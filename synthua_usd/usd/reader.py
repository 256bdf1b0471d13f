"""Stage → :class:`SceneSnapshot`: the composed stage at one time code as plain world-space data.

Gprims are triangulated in world space (metres) by a handler registered per prim type; materials are
UsdPreviewSurface constants and textures (:mod:`synthua_usd.usd.shading`); lights are UsdLux distant and dome lights. Each gprim gets the class and
instance of the labelled prim above it (see :mod:`synthua_usd.usd.semantics`); instances that author
keypoints give them in world metres (:mod:`synthua_usd.usd.keypoints`). What the reader refuses it
finds with the checks of :mod:`synthua_usd.usd.prim_checks`, which ``synthua validate stage`` runs too.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np
from pxr import Sdf, Tf, Usd, UsdGeom, UsdLux

from synthua_usd.core.errors import StageError, UnsupportedPrimError, echo
from synthua_usd.model import meshes as geo
from synthua_usd.model.lamps import KINDS as LAMP_KINDS
from synthua_usd.model.photometry import CD_PER_M2_PER_UNIT, MAX_RENDERER_UNITS, distant_irradiance, dome_radiance
from synthua_usd.model.scene import Instance, Light, Material, MeshItem, SceneSnapshot
from synthua_usd.model.taxonomy import ClassMap
from synthua_usd.usd.keypoints import KEYPOINT_NAMES_ATTR, keypoint_prims, read_keypoints
from synthua_usd.usd.prim_checks import label_findings, mesh_topology, raise_first_error, shape_findings
from synthua_usd.usd.semantics import label_sites, renderable_gprims
from synthua_usd.usd.shading import Materials
from synthua_usd.usd.stage_io import check_time_code, meters_per_unit
from synthua_usd.usd.texcoords import corner_normals, corner_uvs, fan_corners, split_attributes

log = logging.getLogger(__name__)

#: The gprim attribute naming a lamp role (:mod:`synthua_usd.model.lamps`).
LAMP_ATTRIBUTE = "synthua:lamp"

#: Properties of a prim that its descendant gprims inherit (a change re-reads them).
INHERITED_BY_GPRIMS = ("material:binding", "primvars:", "doubleSided", LAMP_ATTRIBUTE)

Triangulator = Callable[[Usd.Prim, Usd.TimeCode], geo.Mesh]
GPRIM_HANDLERS: dict[str, Triangulator] = {}


def gprim_handler(type_name: str):
    """Register a function returning local-space ``(points, triangles)`` for one gprim type."""
    def register(fn: Triangulator) -> Triangulator:
        GPRIM_HANDLERS[type_name] = fn
        return fn
    return register


@gprim_handler("Mesh")
def _mesh(prim: Usd.Prim, t: Usd.TimeCode) -> geo.Mesh:
    points, indices, corners = _mesh_corners(prim, t)
    return points, indices[corners]


def _mesh_corners(prim: Usd.Prim, t: Usd.TimeCode) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A Mesh's points (n, 3), faceVertexIndices and triangle corners (m, 3) (:func:`texcoords.fan_corners`,
    wound counter-clockwise)."""
    findings, (points, counts, indices) = mesh_topology(prim, t)
    raise_first_error(findings)
    holes = set(np.asarray(UsdGeom.Mesh(prim).GetHoleIndicesAttr().Get(t) or [], np.int64).tolist())
    corners, _ = fan_corners(counts, holes)
    if UsdGeom.Mesh(prim).GetOrientationAttr().Get(t) == UsdGeom.Tokens.leftHanded:
        corners = corners[:, ::-1]
    return points, np.asarray(indices, np.int64), corners


@gprim_handler("Cube")
def _cube(prim: Usd.Prim, t: Usd.TimeCode) -> geo.Mesh:
    half = 0.5 * float(UsdGeom.Cube(prim).GetSizeAttr().Get(t))
    return geo.box((-half,) * 3, (half,) * 3)


@gprim_handler("Sphere")
def _sphere(prim: Usd.Prim, t: Usd.TimeCode) -> geo.Mesh:
    return geo.sphere((0, 0, 0), float(UsdGeom.Sphere(prim).GetRadiusAttr().Get(t)), subdivisions=3)


@gprim_handler("Cylinder")
def _cylinder(prim: Usd.Prim, t: Usd.TimeCode) -> geo.Mesh:
    cyl = UsdGeom.Cylinder(prim)
    return geo.cylinder((0, 0, 0), float(cyl.GetRadiusAttr().Get(t)), float(cyl.GetHeightAttr().Get(t)),
                        axis=str(cyl.GetAxisAttr().Get(t)).lower(), sections=32)


@gprim_handler("Cone")
def _cone(prim: Usd.Prim, t: Usd.TimeCode) -> geo.Mesh:
    cone = UsdGeom.Cone(prim)
    return geo.cone(float(cone.GetRadiusAttr().Get(t)), float(cone.GetHeightAttr().Get(t)),
                    axis=str(cone.GetAxisAttr().Get(t)).lower(), sections=32)


@gprim_handler("Capsule")
def _capsule(prim: Usd.Prim, t: Usd.TimeCode) -> geo.Mesh:
    cap = UsdGeom.Capsule(prim)
    return geo.capsule(float(cap.GetRadiusAttr().Get(t)), float(cap.GetHeightAttr().Get(t)),
                       axis=str(cap.GetAxisAttr().Get(t)).lower())


# --- lights -----------------------------------------------------------------------------------------------

def _light_power(light: UsdLux.LightAPI, t: Usd.TimeCode) -> tuple[float, tuple[float, float, float]]:
    intensity = float(light.GetIntensityAttr().Get(t)) * 2.0 ** float(light.GetExposureAttr().Get(t))
    return intensity, tuple(float(c) for c in light.GetColorAttr().Get(t))


#: UsdLux types the translator has an emitter for.
LIGHT_TYPES = ("DistantLight", "DomeLight")


def unsupported_light_message(prim: Usd.Prim) -> str | None:
    """Why render would refuse the light ``prim``, or None when it is supported."""
    if prim.GetTypeName() in LIGHT_TYPES:
        return None
    return f"light type '{prim.GetTypeName()}' is not supported; supported lights: {', '.join(LIGHT_TYPES)}"


def _read_light(prim: Usd.Prim, t: Usd.TimeCode) -> Light:
    """The light ``prim`` in renderer units (:mod:`synthua_usd.model.photometry`): UsdLux strength is
    ``inputs:intensity x 2^inputs:exposure``; a strength too great for our convention is read in the
    convention it must follow (:func:`photometry.distant_irradiance`, :func:`photometry.dome_radiance`), with
    a warning naming the light, its value and the rule."""
    path = str(prim.GetPath())
    message = unsupported_light_message(prim)
    if message:
        raise UnsupportedPrimError(f"{path}: {message}")
    light = UsdLux.LightAPI(prim)
    strength, color = _light_power(light, t)
    if prim.IsA(UsdLux.DistantLight):
        m = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(t), float).T
        d = m[:3, :3] @ np.array([0.0, 0.0, -1.0])
        d /= np.linalg.norm(d)
        angle = float(UsdLux.DistantLight(prim).GetAngleAttr().Get(t))
        irradiance, rule = distant_irradiance(strength, angle, bool(light.GetNormalizeAttr().Get(t)))
        _warn_convention(path, strength, rule, irradiance)
        return Light(path, "distant", color, direction=tuple(d), angle_deg=angle, irradiance=irradiance)
    if prim.IsA(UsdLux.DomeLight):
        if UsdLux.DomeLight(prim).GetTextureFileAttr().Get(t):
            log.warning("%s: dome textures are not supported yet; using its colour and intensity", path)
        radiance, rule = dome_radiance(strength)
        _warn_convention(path, strength, rule, radiance)
        return Light(path, "dome", color, radiance=radiance)
    raise AssertionError(f"{path}: LIGHT_TYPES lists a type with no reader")


def _warn_convention(path: str, strength: float, rule: str, value: float) -> None:
    if rule != "renderer units":
        log.warning("%s: intensity x 2^exposure = %g is beyond our renderer units (at most %g); read as %s: %.4g "
                    "units (%.0f lx or cd/m²)", path, strength, MAX_RENDERER_UNITS, rule, value,
                    value * CD_PER_M2_PER_UNIT)


#: The light a stage without UsdLux lights is rendered with: a uniform sky of our own stages' daytime strength.
DEFAULT_SKY = Light("/synthua:defaultSky", "dome", (0.75, 0.85, 1.0), radiance=0.08)


def animated_skins(stage: Usd.Stage) -> list[tuple[str, str, list[str]]]:
    """(SkelRoot path, animation path, skinned mesh paths) for every skeleton whose animation varies in time:
    meshes the reader can only show in their bind pose (it does not apply UsdSkel skinning)."""
    from pxr import UsdSkel

    found = []
    cache = UsdSkel.Cache()
    for prim in stage.Traverse():
        if not prim.IsA(UsdSkel.Root):
            continue
        root = UsdSkel.Root(prim)
        cache.Populate(root, Usd.PrimDefaultPredicate)
        for binding in cache.ComputeSkelBindings(root, Usd.PrimDefaultPredicate):
            anim = cache.GetSkelQuery(binding.GetSkeleton()).GetAnimQuery()
            if anim and anim.JointTransformsMightBeTimeVarying():
                targets = [str(t.GetPrim().GetPath()) for t in binding.GetSkinningTargets()]
                if targets:
                    found.append((str(prim.GetPath()), str(anim.GetPrim().GetPath()), targets))
    return found


def _lamp_role(prim: Usd.Prim) -> str:
    """The gprim's ``synthua:lamp`` value ('' when unauthored); an unknown role is a :class:`StageError`."""
    attr = prim.GetAttribute(LAMP_ATTRIBUTE)
    value = attr.Get() if attr and attr.HasAuthoredValue() else ""
    if value and value not in LAMP_KINDS:
        raise StageError(f"{prim.GetPath()}: {LAMP_ATTRIBUTE} is '{echo(value)}'; expected one of "
                         f"{', '.join(LAMP_KINDS)}")
    return str(value or "")


# --- the snapshot -------------------------------------------------------------------------------------------

def collect_instances(stage: Usd.Stage, class_map: ClassMap) -> dict[str, Instance]:
    """Every labelled prim above a gprim (visible or not, so ids stay stable over time), by prim path.

    Ids are 1-based in prim-path order. Raises :class:`StageError` for the errors of
    :func:`synthua_usd.usd.prim_checks.label_findings` (labels missing from the class map, label sites
    holding more than one label) and for more instances than 16-bit maps hold.
    """
    sites: dict[str, tuple[str, ...]] = {}
    for prim in Usd.PrimRange.Stage(stage, Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)):
        if prim.IsA(UsdGeom.Gprim):
            found = label_sites(prim, class_map.taxonomy)
            if found:
                sites.setdefault(found[0].prim_path, found[0].labels)
    out = {}
    for k, path in enumerate(sorted(sites), start=1):
        raise_first_error(label_findings(path, sites[path], class_map))
        cls = class_map.resolve(sites[path][0])
        out[path] = Instance(id=k, prim_path=path, class_id=cls.id, class_name=cls.name, isthing=cls.isthing,
                             relations=_relations(stage.GetPrimAtPath(path)))
    if len(out) > 65535:
        raise StageError(f"{stage.GetRootLayer().identifier}: {len(out)} labelled instances do not fit 16-bit "
                         f"instance maps (at most 65535)")
    return out


def _relations(prim: Usd.Prim) -> tuple[tuple[str, str], ...]:
    """``synthua:*`` relationships of an instance prim, as (name, first target path)."""
    out = []
    for rel in prim.GetRelationships():
        if rel.GetNamespace() == "synthua" and rel.GetTargets():
            out.append((rel.GetBaseName(), str(rel.GetTargets()[0])))
    return tuple(sorted(out))


def unsupported_gprim_message(prim: Usd.Prim) -> str | None:
    """Why render would refuse ``prim``, or None when a handler triangulates it."""
    if prim.GetTypeName() in GPRIM_HANDLERS:
        return None
    return (f"gprim type '{prim.GetTypeName()}' is not supported; supported types: "
            f"{', '.join(sorted(GPRIM_HANDLERS))}")


def _might_vary(prim: Usd.Prim, memo: dict[str, bool]) -> bool:
    """Whether ``prim``'s world transform may change over time (its own or an ancestor's xform ops)."""
    key = str(prim.GetPath())
    if key not in memo:
        own = prim.IsA(UsdGeom.Xformable) and UsdGeom.Xformable(prim).TransformMightBeTimeVarying()
        parent = prim.GetParent()
        memo[key] = bool(own) or (bool(parent) and not parent.IsPseudoRoot() and _might_vary(parent, memo))
    return memo[key]


class StageReader:
    """Reads a composed stage as :class:`SceneSnapshot` values, one per time code, cheaply.

    Instances, materials and the meshes of gprims that cannot change over time are read once; a snapshot
    at another time code re-reads only the gprims whose transform or geometry is time-varying and reuses
    the very same :class:`MeshItem` objects for the rest (so a backend can tell what moved by identity).
    A gprim whose own attributes are all constant and only its transform varies (a rigidly moving agent
    part) keeps its local triangles, texture coordinates, material and labels from the first read: a later
    time code only re-places them in the world (as for constant gprims, a colour primvar inherited from an
    ancestor that varies over time is read once). The list of renderable gprims is kept too while no prim in
    the stage has a time-varying visibility.

    Edits of the stage after the reader was made (a layer inserted into its session layer, attributes set on a
    layer of its stack: what scene randomisation does between images) reach the reader through USD's
    ``ObjectsChanged`` notices, and the next snapshot re-reads only what they touched: a changed transform
    re-places the gprims below it (their local triangles kept), a changed gprim or binding re-reads it, a
    changed shader re-reads its material (the gprims bound to it keep their triangles), and a resynced prim (added, removed,
    activated, recomposed) refreshes the list of gprims, labels, keypoints and lights and re-reads what lies
    below it. A snapshot after edits equals, array for array, the snapshot a new reader of the edited stage
    gives.
    """

    def __init__(self, stage: Usd.Stage, class_map: ClassMap) -> None:
        self.stage = stage
        self.class_map = class_map
        self.meters_per_unit = meters_per_unit(stage)
        self.instances = collect_instances(stage, class_map)
        self._keypoint_prims = keypoint_prims(stage, self.instances)
        self._materials = Materials()
        self._static: dict[str, MeshItem | None] = {}
        self._varying: dict[str, str] = {}
        self._xform_memo: dict[str, bool] = {}
        self._local: dict[str, _LocalGprim | None] = {}
        #: Prim path -> the keys of the renderable gprims at or below it, and the keys themselves (kept with the
        #: list of gprims).
        self._under: dict[str, list[str]] = {}
        self._gprim_keys: set[str] = set()
        self._resynced: set[Sdf.Path] = set()
        self._changed: set[Sdf.Path] = set()
        #: Gprims whose material changed: read it again with their next placement.
        self._rematerial: set[str] = set()
        self._notice = Tf.Notice.Register(Usd.Notice.ObjectsChanged, self._on_objects_changed, stage)
        #: The rigidly moving gprims placed last: (their paths, local points of all (n, 3), owner per point (n,),
        #: bounds (k + 1,) of each gprim's points), kept while the same gprims move.
        self._rigid_layout: tuple | None = None
        self._gprims: list[Usd.Prim] | None = None
        self._entries: tuple[list[Usd.Prim], list[tuple[Usd.Prim, str, str]]] | None = None
        self._light_prims: list[Usd.Prim] | None = None
        self._warned_unlabelled = False
        self._warned_unlit = False
        self._warned_skinned = False
        self._last: SceneSnapshot | None = None
        #: Whether :attr:`_last` still shows the stage as it is (False after an edit).
        self._current = False

    # --- edits of the stage --------------------------------------------------------------------------------

    def _on_objects_changed(self, notice, sender) -> None:
        """Collect what an edit touched (applied by the next :meth:`snapshot`)."""
        self._resynced.update(notice.GetResyncedPaths())
        self._changed.update(notice.GetChangedInfoOnlyPaths())
        self._current = False

    def _keys_under(self, path: str) -> list[str]:
        return self._under.get(path, [])

    def _forget(self, keys, geometry: bool) -> None:
        """Drop the placed items of gprim ``keys``; with ``geometry`` also their local gprims and their variation
        (an attribute of theirs may have become time-varying)."""
        for key in keys:
            self._static.pop(key, None)
            if geometry:
                self._local.pop(key, None)
                self._varying.pop(key, None)
        if geometry and keys:
            self._rigid_layout = None
            self._entries = None

    def _forget_transforms(self, prim_path: Sdf.Path, keys) -> None:
        """A transform at ``prim_path`` changed: the gprims ``keys`` below it are placed again. Whether their
        transforms vary over time changes only if ``prim_path``'s own does (a value set anew keeps it): then the
        variation memo of every prim between it and them goes too."""
        self._forget(keys, geometry=False)
        top = str(prim_path)
        if top not in self._xform_memo:
            return
        prim = self.stage.GetPrimAtPath(prim_path)
        parent = prim.GetParent() if prim else None
        own = bool(prim) and prim.IsA(UsdGeom.Xformable) and UsdGeom.Xformable(prim).TransformMightBeTimeVarying()
        now = own or (bool(parent) and not parent.IsPseudoRoot() and _might_vary(parent, self._xform_memo))
        if now == self._xform_memo[top]:
            return
        for key in keys:
            self._varying.pop(key, None)
            path = Sdf.Path(key)
            while True:
                self._xform_memo.pop(str(path), None)
                if str(path) == top or path.IsAbsoluteRootPath():
                    break
                path = path.GetParentPath()
        self._entries = None

    def _forget_materials(self, prim_path: Sdf.Path, below: bool = False) -> None:
        """Something at ``prim_path`` changed that may be part of a material network: every material at or
        above it (with ``below``, also below it) is read again, with the gprims bound to it."""
        dropped = self._materials.forget(str(prim_path), below)
        if dropped:
            bound = [k for k, local in self._local.items() if local is not None and local.material_base in dropped]
            self._forget(bound, geometry=False)
            self._rematerial.update(bound)

    def _changes_structure(self, prim_path: Sdf.Path, name: str) -> bool:
        """Whether a change of property ``name`` on ``prim_path`` may change which gprims render, the labelled
        instances or their relations, or which prims carry keypoints."""
        if name in ("visibility", "purpose", KEYPOINT_NAMES_ATTR) or name.startswith("semantics:"):
            return True
        if name.startswith("synthua:"):
            prim = self.stage.GetPrimAtPath(prim_path)
            return bool(prim) and bool(prim.GetRelationship(name))
        return False

    def _refresh_structure(self) -> None:
        """The list of gprims, the labelled instances (their ids) and the keypoint and light prims, read again."""
        self._gprims = self._entries = self._light_prims = None
        self._under, self._gprim_keys = {}, set()
        instances = collect_instances(self.stage, self.class_map)
        if instances != self.instances:
            self.instances = instances
            self._relabel()
        self._keypoint_prims = keypoint_prims(self.stage, self.instances)

    def _apply_edits(self) -> None:
        """Bring the caches up to date with the edits collected since the last snapshot."""
        resynced, changed = self._resynced, self._changed
        self._resynced, self._changed = set(), set()
        structural = sorted(p for p in resynced if not p.IsPropertyPath())
        properties: dict[Sdf.Path, set[str]] = {}
        for path in resynced | changed:
            # info-only changes of a prim itself (its documentation, custom data; USD also lists instances whose
            # ancestors' values changed) change nothing a snapshot holds: what would (activation, instancing,
            # references, specifiers) resyncs it
            if path.IsPropertyPath():
                properties.setdefault(path.GetPrimPath(), set()).add(path.name)
        # the outermost resynced prims only (USD also lists prims below one it resyncs)
        resynced_prims = {str(p) for p in structural}
        structural = [p for p in structural if not any(a in resynced_prims for a in list(_prefixes(str(p)))[1:])]
        for path in structural:
            if path.IsAbsoluteRootPath():
                self._forget(list(self._local), geometry=True)
                self._xform_memo.clear()
                self._materials.forget("/", below=True)
                continue
            self._forget(self._keys_under(str(path)), geometry=True)
            self._forget_materials(path, below=True)
        if structural and not structural[0].IsAbsoluteRootPath():
            tops = {str(p) for p in structural}
            for memo in [k for k in self._xform_memo if any(a in tops for a in _prefixes(k))]:
                del self._xform_memo[memo]
        structure = bool(structural)
        for path, names in sorted(properties.items()):
            self._forget_materials(path)
            keys = self._keys_under(str(path))
            if not keys:
                continue
            if any(self._changes_structure(path, n) for n in names):
                structure = True
            if any(n.startswith("xformOp") for n in names):
                self._forget_transforms(path, keys)
            if str(path) in self._gprim_keys and any(not n.startswith("xformOp") for n in names):
                self._forget([str(path)], geometry=True)
            elif any(n.startswith(INHERITED_BY_GPRIMS) for n in names):
                self._forget(keys, geometry=True)
        if structure:
            self._refresh_structure()

    def _relabel(self) -> None:
        """New instance ids (labelled prims came or went): the cached gprims keep their geometry and take the
        ids and classes of their labelled prims now."""
        for key, local in list(self._local.items()):
            if local is None:
                continue
            inst = self.instances.get(local.instance_path) if local.instance_path else None
            ids = (inst.id, inst.class_id) if inst else (0, 0)
            if ids != (local.instance_id, local.class_id):
                self._local[key] = replace(local, instance_id=ids[0], class_id=ids[1])
                item = self._static.get(key)
                if item is not None:
                    self._static[key] = replace(item, instance_id=ids[0], class_id=ids[1])

    def _variation(self, prim: Usd.Prim) -> str:
        """'geometry' when one of the gprim's own authored attributes may vary over time, else 'transform' when
        its world transform may, else '' (constant)."""
        key = str(prim.GetPath())
        if key not in self._varying:
            if any(a.ValueMightBeTimeVarying() for a in prim.GetAttributes() if a.HasAuthoredValue()):
                self._varying[key] = "geometry"
            else:
                self._varying[key] = "transform" if _might_vary(prim, self._xform_memo) else ""
        return self._varying[key]

    def _renderable_gprims(self, t: Usd.TimeCode) -> list[Usd.Prim]:
        """:func:`renderable_gprims` at ``t``; kept from the first call while no visibility in the stage varies."""
        if self._gprims is not None:
            return self._gprims
        gprims = renderable_gprims(self.stage, t)
        every = Usd.PrimRange.Stage(self.stage, Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate))
        if not any(UsdGeom.Imageable(p).GetVisibilityAttr().ValueMightBeTimeVarying()
                   for p in every if p.IsA(UsdGeom.Imageable)):
            self._gprims = gprims
        return gprims

    def _gprim_entries(self, t: Usd.TimeCode) -> list[tuple[Usd.Prim, str, str]]:
        """(prim, path, :meth:`_variation`) of each of :meth:`_renderable_gprims` at ``t``, kept with that list."""
        gprims = self._renderable_gprims(t)
        if self._entries is None or self._entries[0] is not gprims:
            self._entries = (gprims, [(p, str(p.GetPath()), self._variation(p)) for p in gprims])
            under: dict[str, list[str]] = {}
            for _, key, _ in self._entries[1]:
                path = Sdf.Path(key)
                while not path.IsAbsoluteRootPath():
                    under.setdefault(str(path), []).append(key)
                    path = path.GetParentPath()
            self._under, self._gprim_keys = under, {key for _, key, _ in self._entries[1]}
        return self._entries[1]

    def _local_gprim(self, prim: Usd.Prim, t: Usd.TimeCode) -> "_LocalGprim | None":
        """The gprim in its own space at ``t`` with its material and labels; None when it has no triangles."""
        message = unsupported_gprim_message(prim)
        if message:
            raise UnsupportedPrimError(f"{prim.GetPath()}: {message}")
        raise_first_error(shape_findings(prim, t))
        material = self._materials.of(prim, t)
        points, tris, uvs, normals = self._geometry(prim, t, material)
        if len(tris) == 0:
            return None
        sites = label_sites(prim, self.class_map.taxonomy)
        inst = self.instances.get(sites[0].prim_path) if sites else None
        return _LocalGprim(points=points, triangles=tris, uvs=uvs, normals=normals, material_key=material.key,
                           material_base=self._materials.base_of(material.key), textured=bool(material.textures),
                           instance_path=sites[0].prim_path if sites else None,
                           instance_id=inst.id if inst else 0, class_id=inst.class_id if inst else 0,
                           lamp=_lamp_role(prim), double_sided=bool(UsdGeom.Gprim(prim).GetDoubleSidedAttr().Get()))

    def _rematerialised(self, prim: Usd.Prim, t: Usd.TimeCode, local: "_LocalGprim | None") -> "_LocalGprim | None":
        """``local`` with its material read again when that material changed (its geometry kept while the material
        keeps having textures or not: the texture coordinates read depend on that), else as it is."""
        key = str(prim.GetPath())
        if key not in self._rematerial:
            return local
        self._rematerial.discard(key)
        if local is None:
            return self._local_gprim(prim, t)
        material = self._materials.of(prim, t)
        if bool(material.textures) != local.textured:
            return self._local_gprim(prim, t)
        return replace(local, material_key=material.key, material_base=self._materials.base_of(material.key))

    def _placed(self, prim: Usd.Prim, local: "_LocalGprim", t: Usd.TimeCode, xcache: UsdGeom.XformCache) -> MeshItem:
        """``local`` in world metres with ``prim``'s transform at ``t``."""
        m = np.array(xcache.GetLocalToWorldTransform(prim), float)  # row-vector convention
        world = (local.points @ m[:3, :3] + m[3, :3]) * self.meters_per_unit
        if not np.all(np.isfinite(world)):
            raise StageError(f"{prim.GetPath()}: has non-finite point coordinates at time {t.GetValue():g}")
        tris = local.triangles
        if np.all(np.isfinite(m[:3, :3])) and np.linalg.det(m[:3, :3]) < 0:  # a mirroring transform flips the winding
            tris = tris[:, ::-1]
        return MeshItem(prim_path=str(prim.GetPath()), points=world, triangles=np.ascontiguousarray(tris),
                        material_key=local.material_key, instance_id=local.instance_id, class_id=local.class_id,
                        lamp=local.lamp, uvs=local.uvs, double_sided=local.double_sided,
                        normals=_world_normals(local.normals, m[None, :3, :3], None))

    def _mesh_item(self, prim: Usd.Prim, t: Usd.TimeCode, xcache: UsdGeom.XformCache, keep: bool = False
                   ) -> MeshItem | None:
        """The gprim at ``t`` read whole and placed in world space (None without triangles); with ``keep`` its
        local gprim is kept (and taken when kept), for a constant gprim that an edit may move."""
        key = str(prim.GetPath())
        if keep and key in self._local:
            local = self._local[key] = self._rematerialised(prim, t, self._local[key])
        else:
            local = self._local_gprim(prim, t)
            if keep:
                self._local[key] = local
        return None if local is None else self._placed(prim, local, t, xcache)

    def _placed_rigid(self, rigid: list, t: Usd.TimeCode, xcache: UsdGeom.XformCache,
                      previous: dict[str, MeshItem]) -> list[MeshItem]:
        """The :class:`MeshItem` of each (place, prim, path, local gprim) of ``rigid`` at ``t``: every local gprim
        re-placed by its transform at once (the points of all of them in one array), as :meth:`_placed` places
        one; a gprim whose points and winding are those of its item in ``previous`` keeps that item."""
        if not rigid:
            return []
        layout = tuple(r[2] for r in rigid)
        if self._rigid_layout is None or self._rigid_layout[0] != layout:
            counts = np.array([len(r[3].points) for r in rigid], np.int64)
            self._rigid_layout = (layout, np.concatenate([r[3].points for r in rigid]),
                                  np.repeat(np.arange(len(rigid)), counts), np.concatenate([[0], np.cumsum(counts)]))
        _, local, owner, bounds = self._rigid_layout
        m = np.array([np.array(xcache.GetLocalToWorldTransform(r[1]), float) for r in rigid])  # (k, 4, 4), rows
        rot = m[owner, :3, :3]
        # a (1, 3) @ (3, 3) product per point: the same sums, in the same order, as one gprim's points @ its matrix
        world = (np.matmul(local[:, None, :], rot)[:, 0] + m[owner, 3, :3]) * self.meters_per_unit
        bad = ~np.isfinite(world).all(axis=1)
        if bad.any():
            prim = rigid[int(owner[np.argmax(bad)])][1]
            raise StageError(f"{prim.GetPath()}: has non-finite point coordinates at time {t.GetValue():g}")
        flip = np.linalg.det(m[:, :3, :3]) < 0  # a mirroring transform flips the winding
        out = []
        for k, (_, prim, key, gprim) in enumerate(rigid):
            points = world[bounds[k]:bounds[k + 1]]
            tris = gprim.triangles[:, ::-1] if flip[k] else gprim.triangles
            before = previous.get(key)
            if (before is not None and (before.instance_id, before.class_id, before.material_key, before.uvs) ==
                    (gprim.instance_id, gprim.class_id, gprim.material_key, gprim.uvs)
                    and np.array_equal(before.points, points) and np.array_equal(before.triangles, tris)):
                out.append(before)  # the same local gprim, placed where it was: its normals too
                continue
            out.append(MeshItem(prim_path=key, points=points, triangles=np.ascontiguousarray(tris),
                                material_key=gprim.material_key, instance_id=gprim.instance_id,
                                class_id=gprim.class_id, lamp=gprim.lamp, uvs=gprim.uvs,
                                double_sided=gprim.double_sided,
                                normals=_world_normals(gprim.normals, m[k:k + 1, :3, :3], None)))
        return out

    def _geometry(self, prim: Usd.Prim, t: Usd.TimeCode, material: Material
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
        """Local points, triangles, and for a Mesh, (n, 2) float32 uvs when ``material`` has textures and the mesh
        its texture coordinates, and (n, 3) float32 unit normals when it has authored normals (points split at
        face-varying seams of either); else those are None."""
        if prim.GetTypeName() != "Mesh":
            if material.textures:
                log.warning("%s: a %s has no texture coordinates; rendering the constants of its textured material %s",
                            prim.GetPath(), prim.GetTypeName(), material.key)
            points, tris = GPRIM_HANDLERS[prim.GetTypeName()](prim, t)
            return points, tris, None, None
        points, indices, corners = _mesh_corners(prim, t)
        uvs = corner_uvs(prim, t, material.uv_primvar, indices, corners, len(points)) if material.textures else None
        normals = corner_normals(prim, t, indices, corners, len(points))
        points, tris, (uvs, normals) = split_attributes(points, indices[corners], uvs, normals)
        return points, tris, uvs, normals

    def snapshot(self, time_code: float) -> SceneSnapshot:
        """Everything renderable at ``time_code`` (checked against the stage's time range). Asking for the
        same time code again returns the same snapshot; a time-varying mesh whose points did not change
        since the previous snapshot keeps its previous :class:`MeshItem`."""
        check_time_code(self.stage, time_code)
        if self._resynced or self._changed:
            self._apply_edits()
        if self._current and self._last is not None and self._last.time_code == time_code:
            return self._last
        if not self._warned_skinned:
            self._warned_skinned = True
            for root, anim, targets in animated_skins(self.stage):
                log.warning("%s: %d skinned meshes (e.g. %s) are animated by %s, and synthua cannot pose skinned "
                            "meshes: they render in their bind pose, not as animated", root, len(targets),
                            targets[0], anim)
        previous = {m.prim_path: m for m in self._last.meshes} if self._last is not None else {}
        t = Usd.TimeCode(time_code)
        xcache = UsdGeom.XformCache(t)
        meshes: list[MeshItem | None] = []
        rigid: list[tuple[int, Usd.Prim, str, _LocalGprim]] = []  # (place in meshes, prim, path, local gprim)
        for prim, key, variation in self._gprim_entries(t):
            if variation == "transform":  # placed below, all together
                if key not in self._local:
                    self._local[key] = self._local_gprim(prim, t)
                else:
                    self._local[key] = self._rematerialised(prim, t, self._local[key])
                if self._local[key] is not None:
                    rigid.append((len(meshes), prim, key, self._local[key]))
                    meshes.append(None)
                continue
            if variation:
                item = self._mesh_item(prim, t, xcache)
                before = previous.get(key)
                if (item is not None and before is not None and np.array_equal(before.points, item.points)
                        and np.array_equal(before.triangles, item.triangles)
                        and (before.instance_id, before.class_id, before.material_key, before.lamp) ==
                        (item.instance_id, item.class_id, item.material_key, item.lamp)
                        and _same_uvs(before.uvs, item.uvs) and _same_uvs(before.normals, item.normals)):
                    item = before
            else:
                if key not in self._static:
                    self._static[key] = self._mesh_item(prim, t, xcache, keep=True)
                item = self._static[key]
            if item is not None:
                meshes.append(item)
        for slot, item in zip((r[0] for r in rigid), self._placed_rigid(rigid, t, xcache, previous)):
            meshes[slot] = item
        unlabelled = [m.prim_path for m in meshes if m.instance_id == 0]
        if unlabelled and not self._warned_unlabelled:
            self._warned_unlabelled = True
            log.warning("%d gprims have no '%s' label and render as class 0 (unlabelled), e.g. %s",
                        len(unlabelled), self.class_map.taxonomy, unlabelled[0])
        if self._light_prims is None:  # which prims are lights does not change with time
            self._light_prims = [p for p in self.stage.Traverse() if p.HasAPI(UsdLux.LightAPI)]
        lights = tuple(_read_light(p, t) for p in self._light_prims)
        if not lights:
            lights = (DEFAULT_SKY,)
            if not self._warned_unlit:
                self._warned_unlit = True
                log.warning("%s: no UsdLux lights; lit by a default uniform sky (%g units, %.0f cd/m²)",
                            self.stage.GetRootLayer().identifier, DEFAULT_SKY.radiance,
                            DEFAULT_SKY.radiance * CD_PER_M2_PER_UNIT)
        self._last = SceneSnapshot(time_code=time_code, up_axis=str(UsdGeom.GetStageUpAxis(self.stage)),
                                   meshes=tuple(meshes), materials=dict(self._materials.by_key), lights=lights,
                                   instances=tuple(sorted(self.instances.values(), key=lambda i: i.id)),
                                   keypoints=read_keypoints(self._keypoint_prims, time_code, xcache,
                                                            self.meters_per_unit))
        self._current = True
        return self._last


@dataclass(frozen=True, eq=False)
class _LocalGprim:
    """A gprim in its own space: ``points`` (n, 3) float64 in stage units, ``triangles`` (m, 3) int64 as authored
    (winding not yet flipped for a mirroring transform), ``uvs`` as :attr:`MeshItem.uvs`, ``normals`` (n, 3) float32
    unit normals in the gprim's space or None, and the material key,
    instance, class, lamp role and sidedness of the :class:`MeshItem` it becomes."""

    points: np.ndarray
    triangles: np.ndarray
    uvs: np.ndarray | None
    normals: np.ndarray | None
    material_key: str
    #: The bound material's own key (``material_key`` less a per-gprim colour), and the labelled prim above.
    material_base: str
    #: Whether the material had textures when the gprim was read (``uvs`` were read for them).
    textured: bool
    instance_path: str | None
    instance_id: int
    class_id: int
    lamp: str
    double_sided: bool


def _prefixes(path: str):
    """``/A/B/C``, ``/A/B``, ``/A``: the prim path string and those of its ancestors."""
    while path and path != "/":
        yield path
        path = path.rsplit("/", 1)[0]


def _world_normals(normals: np.ndarray | None, rotations: np.ndarray, owner: np.ndarray | None) -> np.ndarray | None:
    """``normals`` (n, 3) of gprim space in world space, (n, 3) float32 unit vectors: each times the inverse
    transpose of its gprim's linear part (``rotations`` (k, 3, 3), USD's row-vector convention; ``owner`` (n,)
    the gprim of each normal, None for one gprim), which keeps them perpendicular to surfaces that a transform
    scales unevenly (and mirrors them with it)."""
    if normals is None:
        return None
    if np.any(np.abs(np.linalg.det(rotations)) < 1e-12):  # a flattened gprim: no direction is its normal
        return None
    inverse = np.linalg.inv(rotations).transpose(0, 2, 1)  # row vectors: n' = n @ inv(M).T
    turned = normals @ inverse[0] if owner is None else np.matmul(normals[:, None, :], inverse[owner])[:, 0]
    return (turned / np.maximum(np.linalg.norm(turned, axis=1, keepdims=True), 1e-12)).astype(np.float32)


def _same_uvs(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    return (a is None and b is None) or (a is not None and b is not None and np.array_equal(a, b))


def read_snapshot(stage: Usd.Stage, time_code: float, class_map: ClassMap) -> SceneSnapshot:
    """Everything renderable in ``stage`` at one ``time_code`` (a one-off :class:`StageReader`)."""
    return StageReader(stage, class_map).snapshot(time_code)
