"""Scenario roots: a layer whose sublayers are the chosen layers, with the stage metadata stated once."""

from __future__ import annotations

import math
import os
from pathlib import Path

from pxr import Sdf, UsdGeom

from synthua_usd.core.errors import InputError, StageError, echo
from synthua_usd.core.input_guard import check_not_inputs
from synthua_usd.usd.authoring import check_layer_path, save_layer_atomic
from synthua_usd.usd.stage_io import open_layer

# Metadata that only the root layer of a stage decides: sublayers' values are ignored on composition,
# so the root must state them and the parts must agree.
_AGREE = ("upAxis", "metersPerUnit", "timeCodesPerSecond")


def compose_layers(out_path: str | Path, layer_paths: list[str | Path], doc: str = "",
                   allow_external_assets: bool = True) -> Path:
    """Write a root layer at ``out_path`` that sublayers ``layer_paths`` (strongest first).

    Sublayer paths are written relative to the root's folder. The root takes upAxis, metersPerUnit and
    timeCodesPerSecond from the layers (which must agree), the union of their time ranges, and the
    first defaultPrim stated. Raises :class:`StageError` for a missing layer or disagreeing metadata, and
    :class:`InputError` for an ``out_path`` without a USD layer's extension, and, unless
    ``allow_external_assets``, for a layer outside the root's folder tree (which opening the scenario would
    refuse: :func:`synthua_usd.usd.stage_io.check_layers_inside`).
    """
    out_path = check_layer_path(out_path, "the scenario root")
    if not layer_paths:
        raise StageError(f"{out_path}: no layers to compose; give at least one layer file")
    check_not_inputs([out_path], {"LAYERS": layer_paths})  # a scenario cannot sublayer itself
    layers = [(Path(p), open_layer(p)) for p in layer_paths]
    if not allow_external_assets:
        folder = out_path.resolve().parent
        for p in layer_paths:
            if not Path(p).resolve().is_relative_to(folder):
                raise InputError(f"{echo(p)}: outside the scenario's folder {echo(folder)}, so validate, render and "
                                 f"generate would refuse {echo(out_path)}; expected layers in that folder tree (write "
                                 f"the scenario beside them, or pass --allow-external-assets to compose it anyway)")
    root = Sdf.Layer.CreateAnonymous(".usda")
    for key in _AGREE:
        values = {(str(p), layer.pseudoRoot.GetInfo(key)) for p, layer in layers if layer.pseudoRoot.HasInfo(key)}
        distinct = {v for _, v in values}
        if len(distinct) > 1:
            found = ", ".join(f"{p}: {v}" for p, v in sorted(values))
            raise StageError(f"{out_path}: layers disagree on {key} ({found}); convert them to one value first")
        if distinct:
            value = distinct.pop()
            if key == "upAxis" and value not in ("Y", "Z"):
                raise StageError(f"{out_path}: upAxis of the layers is {echo(value)!r}; expected 'Y' or 'Z'")
            if key != "upAxis" and not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise StageError(f"{out_path}: {key} of the layers is {value!r}; expected a finite number > 0")
            root.pseudoRoot.SetInfo(key, value)
    if not root.pseudoRoot.HasInfo("upAxis"):
        root.pseudoRoot.SetInfo("upAxis", UsdGeom.Tokens.z)
    if not root.pseudoRoot.HasInfo("metersPerUnit"):
        root.pseudoRoot.SetInfo("metersPerUnit", 1.0)
    starts = [layer.startTimeCode for _, layer in layers if layer.HasStartTimeCode()]
    ends = [layer.endTimeCode for _, layer in layers if layer.HasEndTimeCode()]
    if starts and ends:
        root.startTimeCode, root.endTimeCode = min(starts), max(ends)
    if root.pseudoRoot.HasInfo("timeCodesPerSecond"):
        root.framesPerSecond = root.timeCodesPerSecond
    for _, layer in layers:
        if layer.defaultPrim:
            root.defaultPrim = layer.defaultPrim
            break
    root.subLayerPaths = [os.path.relpath(p.resolve(), out_path.resolve().parent) for p, _ in layers]
    root.documentation = doc or "synthua scenario: composes its sublayers, strongest first."
    return save_layer_atomic(root, out_path)
