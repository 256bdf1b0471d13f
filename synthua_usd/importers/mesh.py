"""Meshes (OBJ, PLY, GLB/glTF, STL) through trimesh, keeping the source's object/material structure.

Each source object becomes one prim per class found in it (usually one), with one mesh per material;
materials keep their textures (:mod:`synthua_usd.importers.mesh_materials`) and meshes their texture coordinates.
Classes come from :class:`AssignmentRules` matched against the object name, material name and group;
geometry no rule matches gets the rules' default class (``unlabelled``) and is listed in the report.
"""

from __future__ import annotations

import logging
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np
import trimesh

from synthua_usd.core.errors import InputError, echo
from synthua_usd.core.input_files import check_input_file, shown
from synthua_usd.importers.limits import MAX_MESH_BYTES, MAX_TRIANGLES, SCALE
from synthua_usd.importers.mesh_materials import ImageFailures, geometry_material, obj_texture_problems
from synthua_usd.model.class_assignment import AssignmentRules
from synthua_usd.model.ranges import COORDINATE
from synthua_usd.model.scene import Material
from synthua_usd.model.twin import TwinModel, TwinObject, TwinPart, prim_name, unique_paths

log = logging.getLogger(__name__)

SUFFIXES = {".obj": "obj", ".ply": "ply", ".glb": "glb", ".gltf": "gltf", ".stl": "stl"}
#: glTF is Y-up by specification; the others say nothing, and survey/CAD exports are usually Z-up.
DEFAULT_UP = {"glb": "Y", "gltf": "Y"}
_Y_TO_Z = trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0])


def import_mesh(path: str | Path, rules: AssignmentRules, up_axis: str | None = None, scale: float = 1.0,
                **_ignored) -> TwinModel:
    """Read a mesh file and assign classes by ``rules``.

    ``up_axis`` is the file's up axis ('Y' or 'Z'; default Y for glTF, Z otherwise); ``scale`` converts
    file units to metres.
    """
    path = Path(path)
    where = shown(path)
    kind = SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise InputError(f"{where}: unsupported mesh format '{echo(path.suffix)}'; expected one of {', '.join(SUFFIXES)}")
    SCALE.check(scale, "scale")
    up = (up_axis or DEFAULT_UP.get(kind, "Z")).upper()
    if up not in ("Y", "Z"):
        raise InputError(f"up_axis: {echo(repr(up_axis))}; expected Y or Z")
    check_input_file(path, MAX_MESH_BYTES, f"a {kind.upper()} mesh")
    try:
        with warnings.catch_warnings(), ImageFailures() as failures:  # numpy's overflow warnings: refused below
            warnings.simplefilter("ignore", RuntimeWarning)
            scene = trimesh.load(str(path), force="scene", split_objects=True, split_groups=False)
    except Exception as exc:  # trimesh raises many types for malformed files (MemoryError included)
        raise InputError(f"{where}: cannot read as {kind.upper()}: {echo(exc) or type(exc).__name__}; expected a "
                         f"valid {kind.upper()} file") from None
    _warn_unread_textures(path, kind, failures.reasons)
    # Object name -> class -> parts, in file order.
    grouped: dict[str, dict[str, list[TwinPart]]] = defaultdict(lambda: defaultdict(list))
    materials: dict[str, Material] = {}
    images: dict[str, np.ndarray] = {}
    unmatched: list[str] = []
    matched_by: dict[str, int] = defaultdict(int)
    nodes = list(scene.graph.nodes_geometry)
    meshes = [(node, *scene.graph[node]) for node in nodes]
    meshes = [(node, transform, name) for node, transform, name in meshes
              if isinstance(scene.geometry.get(name), trimesh.Trimesh) and len(scene.geometry[name].faces)]
    if not meshes:
        points = sum(len(getattr(g, "vertices", ())) for g in scene.geometry.values())
        raise InputError(f"{where}: no geometry with triangles ({len(nodes)} geometries, {points} vertices, no face "
                         f"of 3 or more vertices); expected a mesh with faces")
    triangles = sum(len(scene.geometry[name].faces) for _, _, name in meshes)
    if triangles > MAX_TRIANGLES:
        raise InputError(f"{where}: {triangles} triangles; expected at most {MAX_TRIANGLES} (simplify or tile the mesh)")
    for node, transform, geom_name in meshes:
        geom = scene.geometry[geom_name]
        faces = np.asarray(geom.faces, np.int64)
        if faces.min() < 0 or faces.max() >= len(geom.vertices):
            raise InputError(f"{where}: object '{echo(node)}': a face refers to vertex {int(faces.max()) + 1} of "
                             f"{len(geom.vertices)}; expected indices of existing vertices")
        with np.errstate(over="ignore", invalid="ignore"):
            points = trimesh.transform_points(np.asarray(geom.vertices, float), transform)
            if up == "Y":
                points = trimesh.transform_points(points, _Y_TO_Z)
            points *= scale
        if not np.all(np.isfinite(points)):
            raise InputError(f"{where}: object '{echo(node)}' has NaN or infinite coordinates; expected finite numbers")
        if np.abs(points).max() > COORDINATE.high:
            raise InputError(f"{where}: object '{echo(node)}' has coordinates up to {np.abs(points).max():.3g} m "
                             f"(after scale {scale:g}); expected coordinates within ±{COORDINATE.high:g} m")
        mat_name, material, material_images, uvs = geometry_material(geom, "default")
        materials.setdefault(mat_name, material)
        for rel, pixels in material_images.items():
            images.setdefault(rel, pixels)
        obj = _object_name(node, geom_name, mat_name, kind, path)
        fields = {"object": obj, "material": mat_name, "group": geom_name}
        label, rule = rules.classify(fields)
        if rule is None:
            unmatched.append(geom_name)
        else:
            matched_by[f"rules[{rule}]"] += 1
        grouped[obj][label].append(TwinPart(prim_name(mat_name, "Mesh"), points, faces, mat_name,
                                            {"source_group": geom_name, "source_material": mat_name},
                                            uvs if materials[mat_name].textures else None))
    objects = []
    for obj, by_class in grouped.items():
        for label, parts in by_class.items():
            path_ = prim_name(obj) if len(by_class) == 1 else f"{prim_name(obj)}/{prim_name(label)}"
            objects.append(TwinObject(path_, label, tuple(_unique_part_names(parts)), {"source_object": obj}))
    if unmatched:
        log.warning("%s: %d of %d meshes matched no rule and are labelled '%s': %s", where, len(unmatched),
                    len(meshes), rules.default, echo(", ".join(unmatched[:5]) + (" ..." if len(unmatched) > 5 else "")))
    model = TwinModel(objects=tuple(unique_paths(objects)), materials=materials, source=str(path),
                      double_sided=True,
                      report={"meshes": len(meshes), "unmatched": unmatched, "matched_by": dict(matched_by),
                              "rules": rules.source, "textures": sorted(images)}, images=images)
    return model


def _warn_unread_textures(path: Path, kind: str, reasons: list[str]) -> None:
    """One warning per texture image the file names that could not be read (its material renders its colour):
    an OBJ's by material and file (:func:`obj_texture_problems`), other formats' with trimesh's reason."""
    where = shown(path)
    if kind == "obj":
        for material, name, reason in obj_texture_problems(path):
            log.warning("%s: material '%s': texture '%s' cannot be read: %s; the material renders its colour "
                        "without it", where, echo(material), echo(name), echo(reason))
        return
    for reason in reasons:
        log.warning("%s: a texture image of the file cannot be read (%s); its material renders its colour without "
                    "it", where, echo(reason))


def _object_name(node: str, geom_name: str, material: str, kind: str, path: Path) -> str:
    """The source object a geometry came from. trimesh names OBJ pieces '<object>_<material>'."""
    if kind == "obj" and geom_name.endswith(f"_{material}") and len(geom_name) > len(material) + 1:
        return geom_name[: -len(material) - 1]
    if kind in ("ply", "stl"):
        return path.stem
    return node


def _unique_part_names(parts: list[TwinPart]) -> list[TwinPart]:
    seen: dict[str, int] = {}
    out = []
    for p in parts:
        n = seen.get(p.name, 0)
        seen[p.name] = n + 1
        out.append(p if n == 0 else p.renamed(f"{p.name}_{n + 1}"))
    return out
