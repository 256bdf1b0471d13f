"""Composing over an opened stage without touching its files: through its session layer, or by composing its root
layer again under a session layer of its own.

- :func:`recompose`: the stage as its files compose it (what a randomiser reads of the scenario, never an earlier
  image's randomisation), optionally with prims deactivated (the scenario's crowd, when only the twin is read);
- :class:`RandomisationLayers`: the three layers of a randomised image (:mod:`synthua_usd.usd.randomisation_layer`)
  sublayered by the stage's session layer, their content replaced scene by scene and view by view through
  ``Sdf.Layer.TransferContent`` (USD notifies only what differs), a scene's subtree swapped by
  :func:`replace_subtree`;
- :func:`use_session_sublayer` and :func:`extend_end_time_code`: a sequence's crowd layer composed over the stage in
  place of another seed's, and the stage's time range reaching its frames.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from pathlib import Path

from pxr import Sdf, Usd

from synthua_usd.composition.scenario import RANDOM_ROOT
from synthua_usd.usd.randomisation_layer import export_layers


def recompose(stage: Usd.Stage, session_name: str, inactive: Iterable[str] = ()) -> Usd.Stage:
    """``stage``'s root layer composed again (every payload loaded) under a new anonymous session layer tagged
    ``session_name`` (e.g. ``base-session.usda``), in which the prims at ``inactive`` that exist are deactivated:
    the stage as its files compose it, without what is composed over it through its own session layer."""
    again = Usd.Stage.Open(stage.GetRootLayer(), Sdf.Layer.CreateAnonymous(session_name))
    for path in inactive:
        if again.GetPrimAtPath(path):
            with Usd.EditContext(again, again.GetSessionLayer()):
                again.GetPrimAtPath(path).SetActive(False)
    return again


def replace_subtree(target: Sdf.Layer, fresh: Sdf.Layer, root: str) -> None:
    """Replace ``target``'s prim spec at ``root`` (an absolute prim path) and everything below it, and its layer
    documentation, with ``fresh``'s: the subtree is removed where ``fresh`` has none. Specs outside ``root`` and
    ``target``'s sublayers stay as they are; ``root``'s parent must have a spec in ``target`` when ``fresh`` has
    ``root`` (a scene layer after its first scene has ``/World``)."""
    path = Sdf.Path(root)
    parent = target.GetPrimAtPath(path.GetParentPath())
    if parent is not None and path.name in parent.nameChildren:
        del parent.nameChildren[path.name]
    if fresh.GetPrimAtPath(path):
        Sdf.CopySpec(fresh, path, target, path)
    target.documentation = fresh.documentation


class RandomisationLayers:
    """The layers a randomised image composes over ``stage``, anonymous, strongest first, each sublayering the
    next: :attr:`view` over :attr:`scene` over :attr:`prototypes` (what each holds:
    :mod:`synthua_usd.usd.randomisation_layer`). The view layer is the first sublayer of ``stage``'s session layer
    until :meth:`close`."""

    def __init__(self, stage: Usd.Stage) -> None:
        self.stage = stage
        self.prototypes = Sdf.Layer.CreateAnonymous("prototypes.usdc")
        self.scene = Sdf.Layer.CreateAnonymous("scene.usda")
        self.scene.subLayerPaths.append(self.prototypes.identifier)
        self.view = Sdf.Layer.CreateAnonymous("view.usda")
        self.view.subLayerPaths.append(self.scene.identifier)
        stage.GetSessionLayer().subLayerPaths.insert(0, self.view.identifier)
        self._has_scene = False

    def close(self) -> None:
        """Take the layers out of the stage's session layer again (the stage as composed before)."""
        session = self.stage.GetSessionLayer()
        if self.view.identifier in session.subLayerPaths:
            session.subLayerPaths.remove(self.view.identifier)

    def set_scene(self, prototypes: Sdf.Layer, scene: Sdf.Layer) -> None:
        """Make the fresh ``prototypes`` and ``scene`` layers (:func:`~synthua_usd.usd.randomisation_layer.scene_layers`)
        the stage's, both in one change, so the stage never composes old instances over new prototypes. The first
        scene moves in whole (the scene layer still sublayering :attr:`prototypes`); a later one swaps only the
        :data:`RANDOM_ROOT` subtree (:func:`replace_subtree`): everything outside it (the scenario's crowd
        deactivated, recoloured objects bound to ``Looks/Twin_<k>``) is the same for every scene of one stage's
        randomisation, so USD resyncs the crowd and its materials and nothing of the twin."""
        with Sdf.ChangeBlock():
            if not self._has_scene:
                linked = Sdf.Layer.CreateAnonymous("scene.usda")
                linked.TransferContent(scene)
                linked.subLayerPaths.clear()
                linked.subLayerPaths.append(self.prototypes.identifier)
                self.prototypes.TransferContent(prototypes)
                self.scene.TransferContent(linked)
            else:
                replace_subtree(self.prototypes, prototypes, RANDOM_ROOT)
                replace_subtree(self.scene, scene, RANDOM_ROOT)
        self._has_scene = True

    def set_view(self, fresh: Sdf.Layer) -> str:
        """Make the fresh view layer ``fresh`` (:func:`~synthua_usd.usd.randomisation_layer.view_layer`, without
        sublayers) the stage's, sublayering :attr:`scene`; returns the SHA-256 (hex) of ``fresh`` as authored,
        before that link (the same draws author the same bytes)."""
        digest = hashlib.sha256(fresh.ExportToString().encode("utf-8")).hexdigest()
        fresh.subLayerPaths.append(self.scene.identifier)
        self.view.TransferContent(fresh)
        return digest

    def export(self, out: Path, anchor: Path | None = None) -> tuple[Path, Path, Path]:
        """Write the current layers as one image's files (:func:`~synthua_usd.usd.randomisation_layer.export_layers`):
        ``out`` (the view layer), ``<stem>.scene.usda`` and ``<stem>.prototypes.usdc`` beside it."""
        return export_layers(self.view, self.scene, self.prototypes, Path(out), anchor)


def use_session_sublayer(stage: Usd.Stage, path: str, among: Iterable[str]) -> None:
    """Compose the layer file ``path`` over ``stage`` as its session layer's last (weakest) sublayer, in place of
    any of ``among`` (layer paths as the session layer lists them) it sublayers now."""
    session = stage.GetSessionLayer()
    for other in among:
        if other in session.subLayerPaths:
            session.subLayerPaths.remove(other)
    session.subLayerPaths.append(path)


def extend_end_time_code(stage: Usd.Stage, end_time_code: float) -> None:
    """Make ``stage``'s end time code at least ``end_time_code``, authored in its session layer (its files keep
    theirs)."""
    if stage.GetEndTimeCode() < end_time_code:
        with Usd.EditContext(stage, stage.GetSessionLayer()):
            stage.SetEndTimeCode(end_time_code)
