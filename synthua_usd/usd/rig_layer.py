"""The cameras layer of placed rigs: one ``UsdGeom.Camera`` per rig under ``/World/Cameras``, with its
physical lens, a transform that is time-sampled for moving rigs (dashcams, riding cameras: a sample at
every time code), lens distortion as ``synthua:distortion:*`` attributes, and where it came from:

* ``synthua:rig:type`` (token): cctv, dashcam, uav_nadir, uav_oblique, pedestrian_eye, wheelchair_eye;
* ``synthua:rig:height_m`` (double): height above the ground under the camera (or the rider's feet);
* ``synthua:rig:target`` (relationship): the agent or labelled prim it aims at, when it aims;
* ``synthua:rig:rides_with`` (relationship): the agent it rides with;
* the prim's documentation: where the camera stands, in words.
"""

from __future__ import annotations

from dataclasses import dataclass

from pxr import Kind, Sdf, Usd

from synthua_usd.composition.rigs import RigSpec
from synthua_usd.composition.scenario import CAMERAS_ROOT, StageMetadata
from synthua_usd.geometry.placement import CLIP_M, Placement
from synthua_usd.usd.authoring import define_xform, new_layer
from synthua_usd.usd.cameras import author_camera


@dataclass(frozen=True, eq=False)
class PlacedRig:
    """A rig to author: its camera name, request, placement and what it aims at (a prim path or None)."""

    name: str
    spec: RigSpec
    placement: Placement
    target_path: str | None

    @property
    def prim_path(self) -> str:
        return f"{CAMERAS_ROOT}/{self.name}"


def build_rig_layer(meta: StageMetadata, rigs: list[PlacedRig], doc: str) -> Usd.Stage:
    """An in-memory cameras layer holding ``rigs``."""
    stage = new_layer(meta, doc)
    stage.SetDefaultPrim(stage.OverridePrim("/World"))
    define_xform(stage, CAMERAS_ROOT, kind=Kind.Tokens.group)
    for rig in rigs:
        spec, place = rig.spec, rig.placement
        h_ap, v_ap = spec.apertures_mm
        near, far = CLIP_M[spec.type]
        cam = author_camera(stage, rig.prim_path, place.pose, focal_length_mm=place.focal_length_mm,
                            horizontal_aperture_mm=h_ap, vertical_aperture_mm=v_ap, clip_near_m=near, clip_far_m=far,
                            meters_per_unit=meta.meters_per_unit, doc=f"{spec.type}: {place.where}.",
                            time_samples=place.track, distortion=spec.distortion, rig_type=spec.type)
        prim = cam.GetPrim()
        prim.CreateAttribute("synthua:rig:height_m", Sdf.ValueTypeNames.Double, custom=True).Set(spec.height_m)
        if rig.target_path:
            prim.CreateRelationship("synthua:rig:target", custom=True).SetTargets([Sdf.Path(rig.target_path)])
        if place.rides_with:
            prim.CreateRelationship("synthua:rig:rides_with", custom=True).SetTargets([Sdf.Path(place.rides_with)])
    return stage
