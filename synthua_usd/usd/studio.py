"""The studio of ``synthua cutouts``: an in-memory scenario holding one group of people (an aid user with its
device and companions, or a pedestrian) under the shipped conditions, seen by one camera.

The group is authored as a randomised scene's crowd is (:func:`synthua_usd.usd.randomisation_layer.scene_layers`,
:func:`~synthua_usd.usd.randomisation_layer.view_layer`: the same bodies, devices, hair and wear), in layers the
studio's session layer sublayers: a new group replaces the scene and prototypes layers, a new view (placements,
camera, condition) the view layer, so a :class:`~synthua_usd.usd.reader.StageReader` of :attr:`Studio.stage`
re-reads what moved. There is no ground, no twin: what a group receives from the ground comes from the condition's
environment (its lower half is a ground plain), and what it casts on the ground is measured by the renderer.
"""

from __future__ import annotations

import numpy as np
from pxr import Sdf, Usd

from synthua_usd.assets.postures import BodyParts
from synthua_usd.composition.scenario import SHIPPED_ENVIRONMENT, StageMetadata
from synthua_usd.model.conditions import Condition
from synthua_usd.randomisation.scene import SceneDraw
from synthua_usd.randomisation.view import Placement
from synthua_usd.usd.authoring import define_xform
from synthua_usd.usd.cameras import author_camera
from synthua_usd.usd.randomisation_layer import CastPrims, camera_override, scene_layers, view_layer
from synthua_usd.usd.scenario_layers import build_environment

#: The studio's one camera.
CAMERA_PATH = "/World/Cameras/Cutout"
#: The time code everything is read at (a studio does not move).
TIME_CODE = 1.0
#: The camera's film: 36 mm wide, its height by the frame's aspect.
APERTURE_MM = 36.0
BASE_FOCAL_MM = 50.0


class Studio:
    """One studio stage of frames ``width`` x ``height`` (pixels) for ``bodies`` (a process's shared
    :class:`BodyParts`) labelled in ``taxonomy``."""

    def __init__(self, bodies: BodyParts, taxonomy: str, width: int, height: int) -> None:
        self.bodies, self.taxonomy = bodies, taxonomy
        self.meta = StageMetadata(start_time_code=TIME_CODE, end_time_code=TIME_CODE)
        # kept alive: the root layer sublayers its anonymous layer by identifier
        self._environment = build_environment(self.meta, SHIPPED_ENVIRONMENT)
        root = Sdf.Layer.CreateAnonymous("studio.usda")
        root.subLayerPaths.append(self._environment.GetRootLayer().identifier)
        self.stage = Usd.Stage.Open(root, Sdf.Layer.CreateAnonymous("studio-session.usda"))
        self.stage.SetMetadata("upAxis", "Z")
        self.stage.SetMetadata("metersPerUnit", 1.0)
        self.stage.SetStartTimeCode(TIME_CODE)
        self.stage.SetEndTimeCode(TIME_CODE)
        with Usd.EditContext(self.stage, root):
            define_xform(self.stage, "/World")
            self.stage.SetDefaultPrim(self.stage.GetPrimAtPath("/World"))
            define_xform(self.stage, "/World/Cameras")
            author_camera(self.stage, CAMERA_PATH, np.eye(4), focal_length_mm=BASE_FOCAL_MM,
                          horizontal_aperture_mm=APERTURE_MM, vertical_aperture_mm=APERTURE_MM * height / width,
                          clip_near_m=0.05, clip_far_m=500.0, meters_per_unit=1.0,
                          doc="synthua cutouts: the studio camera")
        # the camera as authored, never overridden: what a view's override is computed against
        self.base = Usd.Stage.Open(root, Sdf.Layer.CreateAnonymous("studio-base.usda"))
        # the three layers of a group, strongest first, each sublayering the next (as a Randomiser's)
        self.prototypes = Sdf.Layer.CreateAnonymous("prototypes.usdc")
        self.scene_layer = Sdf.Layer.CreateAnonymous("scene.usda")
        self.view = Sdf.Layer.CreateAnonymous("view.usda")
        self.stage.GetSessionLayer().subLayerPaths.insert(0, self.view.identifier)
        self.cast: CastPrims | None = None

    def set_group(self, draw: SceneDraw) -> CastPrims:
        """Make ``draw``'s cast (one group) the studio's people; returns where each member lives."""
        prototypes, scene, cast = scene_layers(draw, self.meta, self.taxonomy, self.bodies, {}, {}, False)
        with Sdf.ChangeBlock():
            self.view.Clear()
            self.prototypes.TransferContent(prototypes)
            linked = Sdf.Layer.CreateAnonymous("scene.usda")
            linked.TransferContent(scene)
            linked.subLayerPaths.clear()
            linked.subLayerPaths.append(self.prototypes.identifier)
            self.scene_layer.TransferContent(linked)
            self.view.subLayerPaths.append(self.scene_layer.identifier)
        self.cast = cast
        return cast

    def set_view(self, placements: tuple[Placement, ...], camera_to_world: np.ndarray, focal_length_mm: float,
                 condition: Condition) -> None:
        """Pose the group at ``placements``, the camera at ``camera_to_world`` (4x4 column-vector, world metres)
        with ``focal_length_mm``, under ``condition`` (its sun as drawn)."""
        override = camera_override(self.base, CAMERA_PATH, TIME_CODE, camera_to_world, focal_length_mm,
                                   BASE_FOCAL_MM, 0.0)
        fresh = view_layer(self.cast, placements, self.bodies, self.meta, override, condition,
                           doc="synthua cutouts: a view of the studio's group")
        fresh.subLayerPaths.append(self.scene_layer.identifier)
        self.view.TransferContent(fresh)
