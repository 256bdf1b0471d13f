"""Scene randomisation as USD: the layers a randomised image composes over its scenario.

Three layers, strongest first, each sublayering the next:

- the **view layer** (``.usda``): what one image changes: where each person of the crowd stands and how
  (the agent's ``translate`` and ``rotateZ``, each body segment's ``translate`` and ``orient``, keypoints, a
  stepping aid's shift), the camera's pose, focal length and ``exposure`` (EV), and the environment's
  ``condition`` selection with its sun, turbidity and night sky;
- the **scene layer** (``.usda``): what the images of one scene share: the scenario's own crowd deactivated
  (``/World/Agents``, ``active = false``) and a new one under :data:`CROWD_ROOT` (labelled people and devices
  linked by ``synthua:uses``, companions linked to their aid user by ``synthua:pushes`` (the chair) or
  ``synthua:accompanies`` (the person), instances of the prototypes, their clothes and finishes as UsdPreviewSurface
  materials under :data:`LOOKS_ROOT`), and twin objects rebound to variants of their materials;
- the **prototypes layer** (``.usdc``): the meshes of the crowd's body segments, hair and devices, under the
  ``class`` prim :data:`PROTOTYPES_ROOT` (USD scenegraph instancing, as the agents layer).

Nothing else is touched: the scenario's layers stay as they are, and a viewer or ``synthua render --layer``
composes the view layer over the scenario to see the image's scene. Every value is a default (no time
samples): the layers describe one instant, at whatever time code it is viewed.

Authored into fresh layers by plain functions (:func:`scene_layers`, :func:`view_layer`); a caller moves a fresh
layer's content into a layer its stage composes with ``Sdf.Layer.TransferContent``, which notifies only what
differs, so the same structure with new values re-places the crowd without recomposing the scene.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from pxr import Gf, Kind, Sdf, Usd, UsdGeom, Vt

from synthua_usd.assets.bodies import REGIONS, SEGMENTS
from synthua_usd.assets.devices import DEVICE_MODELS
from synthua_usd.assets.look_images import LOOKS_DIR
from synthua_usd.assets.postures import STEPPING_AIDS, BodyParts
from synthua_usd.composition.scenario import CROWD_ROOT, ENVIRONMENT_PATH, RANDOM_ROOT, StageMetadata
from synthua_usd.model import meshes as geo
from synthua_usd.model.conditions import Condition
from synthua_usd.model.keypoint_classes import KEYPOINT_CLASSES
from synthua_usd.model.materials import PALETTE
from synthua_usd.model.scene import Material, SceneSnapshot
from synthua_usd.randomisation.poses import posture_of, pose_member
from synthua_usd.randomisation.scene import CastMember, Recolour, Recolourable, SceneDraw
from synthua_usd.randomisation.view import Placement
from synthua_usd.randomisation.wear import garment_material, shoes_material, skin_material
from synthua_usd.usd.agents_writer import AGENTS_ROOT, PrototypeLibrary, posture_name, prim_name, quat
from synthua_usd.usd.authoring import apply_metadata, bind_material_path, define_preview_material, define_xform
from synthua_usd.usd.conditions import SUN, VARIANT_SET, attribute_name
from synthua_usd.usd.keypoints import KEYPOINT_NAMES_ATTR, KEYPOINTS_ATTR

LOOKS_ROOT = f"{RANDOM_ROOT}/Looks"
PROTOTYPES_ROOT = f"{RANDOM_ROOT}/Prototypes"
#: Palette keys of device parts that keep their palette material (tyres, the white cane's colours).
_DEVICE_ROLES = {"Frame": "frame", "Wood": "frame", "Seat": "seat"}
_ROOT_OPS = ("xformOp:translate", "xformOp:rotateZ")
_SEGMENT_OPS = ("xformOp:translate", "xformOp:orient")
#: The segment holding the head, whose part a person's hair is.
HAIR_SEGMENT = "Torso"


def agent_path(k: int) -> str:
    return f"{CROWD_ROOT}/Agent_{k:04d}"


def recolourable_objects(stage: Usd.Stage, snapshot: SceneSnapshot, classes) -> tuple[list[Recolourable], dict]:
    """The twin objects of ``classes`` a scene may recolour, with the material that covers most of each (by
    surface area), and ``{prim path: gprim paths bound to that material}``. Objects of the scenario's own crowd and
    gprims inside instances (their bindings cannot be overridden per object) are left out."""
    by_id = {inst.id: inst for inst in snapshot.instances if inst.class_name in classes}
    area: dict[str, dict[str, int]] = {}
    gprims: dict[tuple[str, str], list[str]] = {}
    for mesh in snapshot.meshes:
        inst = by_id.get(mesh.instance_id)
        if inst is None or inst.prim_path.startswith((AGENTS_ROOT + "/", RANDOM_ROOT + "/")):
            continue
        if stage.GetPrimAtPath(mesh.prim_path).IsInstanceProxy():
            continue
        tri = mesh.points[mesh.triangles]
        surface = 0.5 * float(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum())
        area.setdefault(inst.prim_path, {}).setdefault(mesh.material_key, 0.0)
        area[inst.prim_path][mesh.material_key] += surface
        gprims.setdefault((inst.prim_path, mesh.material_key), []).append(mesh.prim_path)
    objects, bound = [], {}
    classes_of = {inst.prim_path: inst.class_name for inst in by_id.values()}
    for path in sorted(area):
        key = max(sorted(area[path]), key=lambda k: area[path][k])
        material = snapshot.materials[key]
        if not key.startswith("/"):  # a displayColor or the default grey: no material to vary
            continue
        objects.append(Recolourable(path, classes_of[path], key, material.base_color_texture is not None,
                                    tuple(material.base_color)))
        bound[path] = tuple(sorted(gprims[(path, key)]))
    return objects, bound


def _relative(path: str, root: Path | None) -> str:
    """``path`` relative to ``root`` (``./`` first, as USD's anchored asset paths), unchanged when not absolute."""
    if root is None or not os.path.isabs(path):
        return path
    rel = Path(os.path.relpath(path, root)).as_posix()
    return rel if rel.startswith("../") else f"./{rel}"


def recoloured(material: Material, recolour: Recolour, key: str) -> Material:
    """``material`` as ``recolour`` makes it, keyed ``key``: a new base colour, or its colour and base-colour
    texture multiplied by the tint (the texture's UsdUVTexture ``scale``)."""
    textures = {}
    for name, texture in material.textures.items():
        if name == "base_color_texture" and recolour.tint is not None:
            scale = tuple(float(s * t) for s, t in zip(texture.scale, (*recolour.tint, 1.0)))
            textures[name] = replace(texture, scale=scale)
    colour = recolour.base_color
    if colour is None:
        colour = tuple(float(np.clip(c * t, 0.0, 1.0)) for c, t in zip(material.base_color, recolour.tint))
    return replace(material, key=key, base_color=tuple(colour), **textures)


@dataclass(frozen=True, eq=False)
class CastPrims:
    """Where each cast member lives in the scene layer: per member its agent path, posture, and the prim paths
    of its person, segments and device (None without one)."""

    agents: tuple[str, ...]
    persons: tuple[str, ...]
    devices: tuple[str | None, ...]
    members: tuple[CastMember, ...] = field(repr=False)


def _material(stage: Usd.Stage, path: str, name: str, rgb, roughness: float, metallic: float = 0.0) -> str:
    define_preview_material(stage, path, Material(name, tuple(float(c) for c in rgb), float(roughness),
                                                  float(metallic)))
    return path


def _scene_stage(layer: Sdf.Layer, meta: StageMetadata, doc: str) -> Usd.Stage:
    stage = Usd.Stage.Open(layer)
    apply_metadata(stage, meta)
    layer.documentation = doc
    return stage


def scene_layers(scene: SceneDraw, meta: StageMetadata, taxonomy: str, bodies: BodyParts,
                 materials: dict[str, Material], bound: dict[str, tuple[str, ...]],
                 deactivate_agents: bool) -> tuple[Sdf.Layer, Sdf.Layer, CastPrims]:
    """(prototypes layer, scene layer, cast prims) of ``scene``: fresh anonymous layers, the scene layer
    sublayering the prototypes layer. ``materials`` are the snapshot's (what recolours vary), ``bound`` the
    gprims of each recoloured object (:func:`recolourable_objects`)."""
    prototypes = Sdf.Layer.CreateAnonymous("prototypes.usdc")
    proto_stage = _scene_stage(prototypes, meta, f"synthua randomisation: the meshes of scene {scene.scene_seed}'s "
                                                 f"crowd ({len(scene.cast)} people).")
    proto_stage.SetDefaultPrim(proto_stage.OverridePrim("/World"))
    layer = Sdf.Layer.CreateAnonymous("scene.usda")
    layer.subLayerPaths.append(prototypes.identifier)
    stage = _scene_stage(layer, meta, f"synthua randomisation: scene {scene.scene_seed} "
                                      f"({len(scene.cast)} people, {len(scene.recolours)} objects recoloured).")
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    if deactivate_agents:
        stage.OverridePrim(AGENTS_ROOT).SetActive(False)
    define_xform(stage, RANDOM_ROOT, kind=Kind.Tokens.group)
    stage.DefinePrim(LOOKS_ROOT, "Scope")
    define_xform(stage, CROWD_ROOT, kind=Kind.Tokens.group)
    library = PrototypeLibrary(proto_stage, {}, root=PROTOTYPES_ROOT)
    shared: dict[str, str] = {}

    def palette_material(key: str) -> str:
        if key not in shared:
            spec = PALETTE[key]
            shared[key] = _material(stage, f"{LOOKS_ROOT}/{key}", key, spec.base_color, spec.roughness, spec.metallic)
        return shared[key]

    def wardrobe_material(kind: str, k: int) -> str:  # one per garment of the scene's wardrobe, shared
        path = f"{LOOKS_ROOT}/{kind}_{k:02d}"
        if path not in shared:
            wardrobe = scene.wardrobe
            spec = (shoes_material(path, wardrobe.shoes[k]) if kind == "Shoes" else
                    garment_material(path, (wardrobe.uppers if kind == "Upper" else wardrobe.lowers)[k]))
            define_preview_material(stage, path, spec)
            shared[path] = path
        return shared[path]

    def skin_with_face(key: str) -> str:  # one per skin tone, shared
        if f"{key}Face" not in shared:
            path = f"{LOOKS_ROOT}/{key}Face"
            define_preview_material(stage, path, skin_material(path, PALETTE[key].base_color))
            shared[f"{key}Face"] = path
        return shared[f"{key}Face"]

    # materials and prototypes through the Usd API first; then the crowd's ~20 prims a person as plain specs
    plans = []
    for k, member in enumerate(scene.cast):
        name = f"Agent_{k:04d}"
        if member.wear is None:  # flat colours, faceless matte skin, faceted
            looks = {"skin": palette_material(member.skin)}
            for region, rough in (("upper", 0.85), ("lower", 0.85), ("shoes", 0.5)):
                looks[region] = _material(stage, f"{LOOKS_ROOT}/{name}_{region.title()}", f"{name}_{region}",
                                          member.region_colour(region), rough)
        else:
            looks = {"skin": skin_with_face(member.skin), "upper": wardrobe_material("Upper", member.wear.upper),
                     "lower": wardrobe_material("Lower", member.wear.lower),
                     "shoes": wardrobe_material("Shoes", member.wear.shoes)}
        posture, asked = posture_of(member)
        fit, _, parts = bodies.get(member.body, posture, asked)
        surfaces = bodies.surfaces(member.body, posture, asked) if member.wear is not None else None
        instances = []
        for seg in SEGMENTS:
            for region in REGIONS:
                if (seg, region) in parts:
                    shape = f"Body{member.body:02d}{posture_name(posture)}{seg}{region.title()}"
                    colour = member.region_colour(region)
                    look = looks["skin"] if isinstance(colour, str) else looks[
                        {"forearm": "upper", "shin": "lower"}.get(region, region)]
                    if surfaces is None:
                        prototype = library.part(shape, parts[(seg, region)])
                    else:
                        points, triangles, uvs, normals = surfaces[(seg, region)]
                        prototype = library.part(shape, (points, triangles), uvs, normals)
                    instances.append((seg, region.title(), prototype, look))
        hair = member.hair
        if hair is not None and hair.style != "none":
            # a part of the segment holding the head, bound to the person's own hair material
            shape = f"Body{member.body:02d}{posture_name(posture)}Hair{hair.style.title()}"
            look = _material(stage, f"{LOOKS_ROOT}/{name}_Hair", f"{name}_hair", hair.base_color, hair.roughness)
            mesh = bodies.hair(member.body, posture, asked, hair.style)
            normals = None if member.wear is None else geo.vertex_normals(*mesh)  # smooth with the looks
            instances.append((HAIR_SEGMENT, "Hair", library.part(shape, mesh, normals=normals), look))
        device = None
        if member.aid is not None and member.device is not None:
            look = member.device
            finish = {"frame": _material(stage, f"{LOOKS_ROOT}/{name}_Frame", f"{name}_frame", look.frame.base_color,
                                         look.frame.roughness, look.frame.metallic),
                      "seat": _material(stage, f"{LOOKS_ROOT}/{name}_Seat", f"{name}_seat", look.seat.base_color,
                                        look.seat.roughness, look.seat.metallic)}
            keys = {p.material for p in DEVICE_MODELS[member.aid][look.model](fit)}
            bindings = {key: finish[_DEVICE_ROLES[key]] if key in _DEVICE_ROLES else palette_material(key)
                        for key in sorted(keys)}
            device = library.device(member.aid, fit, look.model, bindings, name=f"{name}_{prim_name(member.aid)}")
        plans.append((member, instances, device))
    agents, persons, device_paths = [], [], []
    with Sdf.ChangeBlock():
        for k, (member, instances, prototype) in enumerate(plans):
            root = _define(layer, agent_path(k), kind=Kind.Tokens.group)
            _attr(root, "synthua:profile", Sdf.ValueTypeNames.String, member.profile, custom=True)
            if member.seat is not None:
                _attr(root, "synthua:behaviour", Sdf.ValueTypeNames.String, "sits_on_bench", custom=True)
            if member.group is not None:
                _attr(root, "synthua:group", Sdf.ValueTypeNames.Int, member.group, custom=True)
            if member.pushes is not None:
                _attr(root, "synthua:behaviour", Sdf.ValueTypeNames.String, "pushes_wheelchair", custom=True)
            elif member.accompanies is not None:
                _attr(root, "synthua:behaviour", Sdf.ValueTypeNames.String, "accompanies_aid_user", custom=True)
            person_path = f"{agent_path(k)}/Person"
            person = _define(layer, person_path, kind=Kind.Tokens.component)
            _label(person, taxonomy, "person")
            _attr(person, KEYPOINT_NAMES_ATTR, Sdf.ValueTypeNames.TokenArray, list(KEYPOINT_CLASSES["person"].names),
                  uniform=True, custom=True)
            for seg in SEGMENTS:
                _define(layer, f"{person_path}/{seg}")
            for seg, region, part, look in instances:
                _instance_spec(layer, f"{person_path}/{seg}/{region}", part, look)
            device = None
            if prototype is not None:
                device = f"{agent_path(k)}/{prim_name(member.aid)}"
                aid = _instance_spec(layer, device, prototype, None, kind=Kind.Tokens.component)
                _label(aid, taxonomy, member.aid)
                _attr(aid, KEYPOINT_NAMES_ATTR, Sdf.ValueTypeNames.TokenArray,
                      list(KEYPOINT_CLASSES[member.aid].names), uniform=True, custom=True)
                uses = Sdf.RelationshipSpec(person, "synthua:uses", True)
                uses.targetPathList.explicitItems = [Sdf.Path(device)]
            # a companion's relation to its aid user: the chair it pushes, or the person it walks beside
            if member.pushes is not None:
                pushed = scene.cast[member.pushes]
                pushes = Sdf.RelationshipSpec(person, "synthua:pushes", True)
                pushes.targetPathList.explicitItems = [Sdf.Path(f"{agent_path(member.pushes)}/{prim_name(pushed.aid)}")]
            if member.accompanies is not None:
                with_ = Sdf.RelationshipSpec(person, "synthua:accompanies", True)
                with_.targetPathList.explicitItems = [Sdf.Path(f"{agent_path(member.accompanies)}/Person")]
            agents.append(agent_path(k))
            persons.append(person_path)
            device_paths.append(device)
    for k, recolour in enumerate(scene.recolours):
        path = f"{LOOKS_ROOT}/Twin_{k:04d}"
        define_preview_material(stage, path, recoloured(materials[recolour.material], recolour, path))
        for gprim in bound.get(recolour.prim_path, ()):
            bind_material_path(stage.OverridePrim(gprim), path)
    return prototypes, layer, CastPrims(tuple(agents), tuple(persons), tuple(device_paths), scene.cast)


# --- plain specs: the crowd of the scene layer, and the view layer (the same structure for every view) -----

def _define(layer: Sdf.Layer, path: str, type_name: str = "Xform", kind: str | None = None) -> Sdf.PrimSpec:
    spec = Sdf.CreatePrimInLayer(layer, path)
    spec.specifier = Sdf.SpecifierDef
    spec.typeName = type_name
    if kind:
        spec.kind = kind
    return spec


def _apply_api(spec: Sdf.PrimSpec, schema: str) -> None:
    """Prepend an applied API schema, as ``Usd.Prim.ApplyAPI`` authors it."""
    ops = spec.GetInfo("apiSchemas") if spec.HasInfo("apiSchemas") else Sdf.TokenListOp()
    spec.SetInfo("apiSchemas", Sdf.TokenListOp.Create(prependedItems=[*ops.prependedItems, schema]))


def _label(spec: Sdf.PrimSpec, taxonomy: str, label: str) -> None:
    """The class ``label`` of ``taxonomy`` (UsdSemantics.LabelsAPI), as :func:`authoring.apply_label` authors it."""
    _apply_api(spec, f"SemanticsLabelsAPI:{taxonomy}")
    _attr(spec, f"semantics:labels:{taxonomy}", Sdf.ValueTypeNames.TokenArray, [label])


def _instance_spec(layer: Sdf.Layer, path: str, prototype, material: str | None, kind: str | None = None
                   ) -> Sdf.PrimSpec:
    """An instanceable Xform referencing ``prototype``, bound to ``material`` when given."""
    spec = _define(layer, path, kind=kind)
    spec.referenceList.Prepend(Sdf.Reference(primPath=Sdf.Path(str(prototype))))
    spec.instanceable = True
    if material is not None:
        _apply_api(spec, "MaterialBindingAPI")
        rel = Sdf.RelationshipSpec(spec, "material:binding", False)
        rel.targetPathList.explicitItems = [Sdf.Path(material)]
    return spec


def _over(layer: Sdf.Layer, path: str) -> Sdf.PrimSpec:
    spec = layer.GetPrimAtPath(path)
    return spec if spec else Sdf.CreatePrimInLayer(layer, path)


def _attr(spec: Sdf.PrimSpec, name: str, value_type, value, uniform: bool = False, custom: bool = False) -> None:
    attr = Sdf.AttributeSpec(spec, name, value_type,
                             Sdf.VariabilityUniform if uniform else Sdf.VariabilityVarying, custom)
    attr.default = value


def _ops(spec: Sdf.PrimSpec, names) -> None:
    _attr(spec, "xformOpOrder", Sdf.ValueTypeNames.TokenArray, Vt.TokenArray(list(names)), uniform=True)


def _points(points: np.ndarray) -> Vt.Vec3fArray:
    return Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(points, np.float32))


@dataclass(frozen=True)
class CameraOverride:
    """A view's camera as USD authors it: ``local`` the (4, 4) local-to-parent matrix in stage units in USD's
    row-vector convention, ``focal_length`` in the stage's lens units (as the prim's ``focalLength``), and
    the ``exposure`` compensation in EV."""

    path: str
    local: tuple
    focal_length: float
    exposure_ev: float


def camera_override(stage: Usd.Stage, path: str, time_code: float, camera_to_world: np.ndarray,
                    focal_length_mm: float, base_focal_mm: float, exposure_ev: float) -> CameraOverride:
    """The :class:`CameraOverride` that puts the camera at ``path`` at ``camera_to_world`` (4x4 column-vector,
    world metres) with ``focal_length_mm`` (its prim's ``focalLength`` scaled by the ratio to ``base_focal_mm``,
    whatever its units)."""
    prim = stage.GetPrimAtPath(path)
    t = Usd.TimeCode(time_code)
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    world = np.array(camera_to_world, float).copy()
    world[:3, 3] /= mpu
    parent = np.array(UsdGeom.Xformable(prim).ComputeParentToWorldTransform(t), float)
    local = world.T @ np.linalg.inv(parent)
    focal = float(UsdGeom.Camera(prim).GetFocalLengthAttr().Get(t)) * focal_length_mm / base_focal_mm
    return CameraOverride(path, tuple(map(tuple, local.tolist())), focal, float(exposure_ev))


def view_layer(cast: CastPrims, placements: tuple[Placement, ...], bodies: BodyParts, meta: StageMetadata,
               camera: CameraOverride | None = None, condition: Condition | None = None,
               doc: str = "") -> Sdf.Layer:
    """A fresh anonymous view layer: each member of ``cast`` at its placement (posed by
    :func:`synthua_usd.randomisation.poses.pose_member`), the ``camera`` override and the ``condition`` (its
    selection in the environment's variant set, and its sun, turbidity and night sky as local opinions, which
    win over the variant's), for any time code."""
    layer = Sdf.Layer.CreateAnonymous("view.usda")
    layer.documentation = doc
    pseudo = layer.pseudoRoot
    layer.defaultPrim = "World"
    for key, value in (("upAxis", meta.up_axis), ("metersPerUnit", float(meta.meters_per_unit))):
        pseudo.SetInfo(key, value)
    with Sdf.ChangeBlock():
        for member, agent, person, device, place in zip(cast.members, cast.agents, cast.persons, cast.devices,
                                                        placements):
            pose = pose_member(bodies, member, place)
            spec = _over(layer, agent)
            _ops(spec, _ROOT_OPS)
            _attr(spec, "xformOp:translate", Sdf.ValueTypeNames.Double3, Gf.Vec3d(*map(float, place.position)))
            _attr(spec, "xformOp:rotateZ", Sdf.ValueTypeNames.Float, float(place.heading_deg))
            _attr(spec, "synthua:speed_mps", Sdf.ValueTypeNames.Double, float(place.speed_mps), custom=True)
            person_spec = _over(layer, person)
            _attr(person_spec, KEYPOINTS_ATTR, Sdf.ValueTypeNames.Point3fArray, _points(pose.keypoints), custom=True)
            for seg in SEGMENTS:
                m = pose.segments[seg]
                seg_spec = _over(layer, f"{person}/{seg}")
                _ops(seg_spec, _SEGMENT_OPS)
                _attr(seg_spec, "xformOp:translate", Sdf.ValueTypeNames.Double3, Gf.Vec3d(*map(float, m[:, 3])))
                _attr(seg_spec, "xformOp:orient", Sdf.ValueTypeNames.Quatf, quat(m[:, :3]))
            if device is not None:
                dev_spec = _over(layer, device)
                if member.aid in STEPPING_AIDS:
                    _ops(dev_spec, ("xformOp:translate",))
                    _attr(dev_spec, "xformOp:translate", Sdf.ValueTypeNames.Double3,
                          Gf.Vec3d(pose.device_shift_m, 0.0, 0.0))
                _attr(dev_spec, KEYPOINTS_ATTR, Sdf.ValueTypeNames.Point3fArray, _points(pose.contacts), custom=True)
        if camera is not None:
            spec = _over(layer, camera.path)
            _ops(spec, ("xformOp:transform",))
            _attr(spec, "xformOp:transform", Sdf.ValueTypeNames.Matrix4d,
                  Gf.Matrix4d(*[float(v) for row in camera.local for v in row]))
            _attr(spec, "focalLength", Sdf.ValueTypeNames.Float, float(camera.focal_length))
            _attr(spec, "exposure", Sdf.ValueTypeNames.Float, float(camera.exposure_ev))
        if condition is not None:
            spec = _over(layer, ENVIRONMENT_PATH)
            spec.variantSelections[VARIANT_SET] = condition.name
            for name in ("sun_elevation_deg", "sun_azimuth_deg", "turbidity", "night_sky_luminance_cd_m2"):
                _attr(spec, attribute_name(name), Sdf.ValueTypeNames.Double, float(getattr(condition, name)),
                      custom=True)
            sun = _over(layer, f"{ENVIRONMENT_PATH}/{SUN}")  # the viewers' approximation follows the sun
            _attr(sun, "xformOp:rotateX", Sdf.ValueTypeNames.Float, float(90.0 - condition.sun_elevation_deg))
            _attr(sun, "xformOp:rotateZ", Sdf.ValueTypeNames.Float, float(180.0 - condition.sun_azimuth_deg))
    return layer


def _relative_assets(layer: Sdf.Layer, root: Path) -> None:
    """Make the absolute asset paths authored in ``layer`` (the recoloured materials' textures, read from the
    scenario as absolute paths) relative to ``root``, where the layer is written."""
    def visit(path: Sdf.Path) -> None:
        if not path.IsPropertyPath():
            return
        spec = layer.GetAttributeAtPath(path)
        if spec and spec.typeName == Sdf.ValueTypeNames.Asset and isinstance(spec.default, Sdf.AssetPath):
            value = spec.default.path
            if os.path.isabs(value):
                spec.default = Sdf.AssetPath(_relative(value, Path(os.path.abspath(root))))

    layer.Traverse(Sdf.Path.absoluteRootPath, visit)


def _local_looks(layer: Sdf.Layer, folder: Path, name: str) -> None:
    """Copy the package's look images (:mod:`synthua_usd.assets.look_images`) that ``layer``'s textures read into
    ``folder / name`` and point the textures at the copies (``./<name>/<file>``): the written layers then hold
    every file they read in their own folder tree, as ``synthua render --layer`` asks."""
    import shutil

    looks = LOOKS_DIR.resolve()

    def visit(path: Sdf.Path) -> None:
        spec = layer.GetAttributeAtPath(path) if path.IsPropertyPath() else None
        if not spec or spec.typeName != Sdf.ValueTypeNames.Asset or not isinstance(spec.default, Sdf.AssetPath):
            return
        source = Path(spec.default.path)
        if source.is_absolute() and source.resolve().parent == looks:
            (folder / name).mkdir(exist_ok=True)
            shutil.copyfile(source, folder / name / source.name)
            spec.default = Sdf.AssetPath(f"./{name}/{source.name}")

    layer.Traverse(Sdf.Path.absoluteRootPath, visit)


def export_layers(view: Sdf.Layer, scene: Sdf.Layer, prototypes: Sdf.Layer, out: Path,
                  anchor: Path | None = None) -> tuple[Path, Path, Path]:
    """Write ``view`` to ``out`` (``.usda``), ``scene`` beside it as ``<stem>.scene.usda`` and ``prototypes`` as
    ``<stem>.prototypes.usdc``, each sublayering the next by a relative path, asset paths relative to ``anchor``
    (the folder they will be read from, default ``out``'s), and the look images the scene's people wear copied
    into ``<stem>.looks/`` beside them; returns the three layers' paths. The caller writes them as one output
    set (they are useless apart)."""
    out = Path(out)
    scene_path = out.with_name(f"{out.stem}.scene.usda")
    proto_path = out.with_name(f"{out.stem}.prototypes.usdc")
    for source, target, sub in ((prototypes, proto_path, None), (scene, scene_path, proto_path.name),
                                (view, out, scene_path.name)):
        layer = Sdf.Layer.CreateAnonymous(target.suffix)
        layer.TransferContent(source)
        layer.subLayerPaths.clear()
        if sub is not None:
            layer.subLayerPaths.append(f"./{sub}")
        _local_looks(layer, target.parent, f"{out.stem}.looks")
        _relative_assets(layer, Path(anchor) if anchor is not None else target.parent)
        if not layer.Export(str(target)):
            raise OSError(f"{target}: USD could not write the layer")
    return out, scene_path, proto_path
