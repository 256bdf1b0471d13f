"""A scene's distractors (:mod:`synthua_usd.randomisation.distractors`) authored into its scene layer
(:mod:`synthua_usd.usd.randomisation_layer`): one labelled ``Xform`` per distractor under :data:`DISTRACTORS_ROOT`
(``Kind`` component, ``semantics:labels:<taxonomy>`` its class; ``unlabelled`` for void, so that a viewer sees the
choice was made), a ``Mesh`` per part in world coordinates (texture coordinates where it wears a pattern), and a
``UsdPreviewSurface`` per part under the scene's looks. Nothing else of the scene layer is touched.
"""

from __future__ import annotations

from dataclasses import replace

from pxr import Kind, Sdf, Usd

from synthua_usd.composition.scenario import RANDOM_ROOT
from synthua_usd.randomisation.distractors import DistractorsDraw
from synthua_usd.usd.authoring import apply_label, bind_material, define_mesh, define_preview_material, define_xform

DISTRACTORS_ROOT = f"{RANDOM_ROOT}/Distractors"
LOOKS = f"{RANDOM_ROOT}/Looks"


def distractor_path(k: int, name: str) -> str:
    """``/World/Randomisation/Distractors/D<kkk>_<Object>``."""
    return f"{DISTRACTORS_ROOT}/D{k:03d}_{''.join(w.title() for w in name.split('_'))}"


def author_distractors(layer: Sdf.Layer, draw: DistractorsDraw, taxonomy: str) -> None:
    """Author ``draw``'s distractors into ``layer`` (a scene layer that defines :data:`RANDOM_ROOT`)."""
    if not draw.items:
        return
    stage = Usd.Stage.Open(layer)
    define_xform(stage, DISTRACTORS_ROOT, kind=Kind.Tokens.group)
    stage.DefinePrim(LOOKS, "Scope")
    for k, item in enumerate(draw.items):
        path = distractor_path(k, item.object)
        prim = define_xform(stage, path, kind=Kind.Tokens.component).GetPrim()
        apply_label(prim, taxonomy, item.label)
        prim.CreateAttribute("synthua:distractor", Sdf.ValueTypeNames.String, custom=True).Set(item.object)
        for name, points, triangles, uvs, spec in item.parts():
            look = f"{LOOKS}/{path.rsplit('/', 1)[1]}_{name}"
            material = define_preview_material(stage, look, replace(spec, key=look))
            define_mesh(stage, f"{path}/{name}", points, triangles, uvs=uvs)
            bind_material(stage.GetPrimAtPath(f"{path}/{name}"), material)
