"""Checks of single prims that both the reader and ``synthua validate stage`` run.

Each returns findings (never raises); the reader turns the first error into a :class:`StageError`
(:func:`raise_first_error`), the stage rules of :mod:`synthua_usd.usd.stage_checks` report them all. So
whatever render refuses, validation reports, with the same words.
"""

from __future__ import annotations

import math

import numpy as np
from pxr import Usd, UsdGeom

from synthua_usd.core.errors import InputError, StageError
from synthua_usd.core.findings import Finding, Severity
from synthua_usd.model.distortion import COEFFICIENTS, MODEL, BrownConrady
from synthua_usd.model.taxonomy import ClassMap

#: Plausible physical lens values; outside them the authored numbers are probably in the wrong unit.
FOCAL_RANGE_MM = (1.0, 2000.0)
APERTURE_RANGE_MM = (1.0, 100.0)
#: Plausible field of view across the wider side of the authored filmback (a rectilinear lens: from a CCTV dome's zoom
#: at its longest, about 2.3 degrees, to the widest ultra-wides, about 135). Each value can look plausible alone
#: while the three mix units: focalLength 20 (a 20 mm lens typed in millimetres) over a 0.36 filmback is 2000 mm
#: over 36 mm, 1 degree; 0.02 (typed in metres) is 2 mm, 167 degrees.
FOV_RANGE_DEG = (2.0, 150.0)
#: Lens distortion lives on the camera prim as custom attributes: ``synthua:distortion:model`` (token,
#: ``brown_conrady``) and one double per coefficient (``synthua:distortion:k1`` ... ``:p2``).
DISTORTION_PREFIX = "synthua:distortion:"


def lens_unit_mm(meters_per_unit: float) -> float:
    """Millimetres in one USD lens unit (a tenth of a scene unit): USD measures focalLength and the
    apertures in tenths of a scene unit, so millimetres on a centimetre stage."""
    return 100.0 * meters_per_unit


def raise_first_error(findings: list[Finding]) -> None:
    """Raise :class:`StageError` for the first error among ``findings``; warnings and notes pass."""
    for f in findings:
        if f.severity is Severity.ERROR:
            raise StageError(f"{f.where}: {f.message}")


def mesh_topology(prim: Usd.Prim, t: Usd.TimeCode, rule: str = "mesh-topology") -> tuple[list[Finding], tuple]:
    """Findings for a ``UsdGeom.Mesh`` at ``t`` and, when it has none, its arrays
    ``(points (n, 3) float64, faceVertexCounts (f,) int64, faceVertexIndices (k,) int64)``."""
    path = str(prim.GetPath())
    mesh = UsdGeom.Mesh(prim)
    points = np.asarray(mesh.GetPointsAttr().Get(t) or [], np.float64).reshape(-1, 3)
    counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get(t) or [], np.int64)
    indices = np.asarray(mesh.GetFaceVertexIndicesAttr().Get(t) or [], np.int64)
    out = []
    if counts.sum() != len(indices):
        out.append(Finding(rule, path, f"faceVertexCounts sum to {counts.sum()} but there are {len(indices)} "
                                       f"faceVertexIndices; expected equal"))
    if len(counts) and counts.min() < 3:
        out.append(Finding(rule, path, f"faceVertexCounts has a face of {counts.min()} vertices; expected at least 3"))
    if len(indices) and (indices.min() < 0 or indices.max() >= len(points)):
        out.append(Finding(rule, path, f"faceVertexIndices reach {indices.min() if indices.min() < 0 else indices.max()} "
                                       f"but there are {len(points)} points; expected indices in 0..{len(points) - 1}"))
    if not np.all(np.isfinite(points)):
        out.append(Finding(rule, path, "points hold NaN or infinite coordinates; expected finite numbers"))
    return out, (points, counts, indices)


#: The size parameters of the implicit gprims and whether 0 is allowed (a Capsule's height, its cylinder
#: part, may be 0: a sphere); every other must be > 0.
SHAPE_PARAMETERS = {"Cube": (("size", False),), "Sphere": (("radius", False),),
                    "Cylinder": (("radius", False), ("height", False)), "Cone": (("radius", False), ("height", False)),
                    "Capsule": (("radius", False), ("height", True))}


def shape_findings(prim: Usd.Prim, t: Usd.TimeCode, rule: str = "gprim-shape") -> list[Finding]:
    """An implicit gprim's (Cube, Sphere, Cylinder, Cone, Capsule) size, radius and height at ``t``: finite
    and > 0 (scene units; see :data:`SHAPE_PARAMETERS`). Other prims have none."""
    out = []
    for name, zero_allowed in SHAPE_PARAMETERS.get(prim.GetTypeName(), ()):
        value = prim.GetAttribute(name).Get(t)
        if value is None or not math.isfinite(value) or value < 0 or (value == 0 and not zero_allowed):
            out.append(Finding(rule, str(prim.GetPath()), f"{name} is {value}; expected a finite value "
                                                          f"{'>=' if zero_allowed else '>'} 0"))
    return out


def label_findings(path: str, labels: tuple[str, ...], class_map: ClassMap, rule: str = "label-in-class-map") -> list[Finding]:
    """A labelled prim holds exactly one label, and it names a class (or alias) of the class map."""
    if len(labels) != 1:
        return [Finding("gprim-has-one-class", path, f"has {len(labels)} labels {list(labels)} in taxonomy "
                                                     f"'{class_map.taxonomy}'; expected exactly one")]
    if class_map.resolve(labels[0]) is None:
        return [Finding(rule, path, f"label '{labels[0]}' is not a class of {class_map.source}; use a class name "
                                    f"or alias from it (see `synthua inspect`)")]
    return []


def camera_findings(prim: Usd.Prim, t: Usd.TimeCode, meters_per_unit: float, rule: str = "camera-lens") -> list[Finding]:
    """A perspective camera with positive (and plausible) lens values, no lens shift, 0 < near < far, and
    a finite, invertible transform."""
    path = str(prim.GetPath())
    cam = UsdGeom.Camera(prim)
    unit = lens_unit_mm(meters_per_unit)
    out = []
    projection = cam.GetProjectionAttr().Get(t)
    if projection != UsdGeom.Tokens.perspective:
        out.append(Finding(rule, path, f"projection '{projection}' is not supported; expected 'perspective'"))
    for attr, (lo, hi) in (("focalLength", FOCAL_RANGE_MM), ("horizontalAperture", APERTURE_RANGE_MM),
                           ("verticalAperture", APERTURE_RANGE_MM)):
        value = prim.GetAttribute(attr).Get(t)
        if value is None or not math.isfinite(value) or value <= 0:
            out.append(Finding(rule, path, f"{attr} is {value}; expected a finite value > 0"))
            continue
        mm = value * unit
        if not lo <= mm <= hi:
            # Only the ratios reach the image, so such a lens renders: but every intrinsic in millimetres
            # (frame.json, the metadata table) would be off by the same factor. Authored, that is an error (a
            # lens in the wrong unit); USD's fallback lens (50, 20.955 x 15.2908) on a metre stage is a warning.
            if prim.GetAttribute(attr).HasAuthoredValue():
                out.append(Finding(rule, path, f"{attr} = {value:g} is {mm:g} mm, outside the plausible {lo:g}-{hi:g} "
                                               f"mm; USD lens values are in tenths of a scene unit ({unit:g} mm here): "
                                               f"{value:g} mm is authored as {value / unit:g}"))
            else:
                out.append(Finding(rule, path, f"{attr} is not authored: USD's fallback {value:g} is {mm:g} mm here, "
                                               f"outside the plausible {lo:g}-{hi:g} mm; author the lens in tenths of a "
                                               f"scene unit ({unit:g} mm here)", Severity.WARNING))
    lens = {a: prim.GetAttribute(a).Get(t) for a in ("focalLength", "horizontalAperture", "verticalAperture")}
    if all(v is not None and math.isfinite(v) and v > 0 for v in lens.values()):
        wide = max(("horizontalAperture", "verticalAperture"), key=lambda a: lens[a])  # the view across its wider side
        focal_mm, aperture_mm = lens["focalLength"] * unit, lens[wide] * unit
        fov = math.degrees(2 * math.atan(lens[wide] / (2 * lens["focalLength"])))
        plausible = FOCAL_RANGE_MM[0] <= focal_mm <= FOCAL_RANGE_MM[1] and \
            APERTURE_RANGE_MM[0] <= aperture_mm <= APERTURE_RANGE_MM[1]
        if plausible and not FOV_RANGE_DEG[0] <= fov <= FOV_RANGE_DEG[1]:  # each value alone is reported above
            out.append(Finding(rule, path, f"focalLength = {lens['focalLength']:g} over {wide} = {lens[wide]:g} "
                                           f"({focal_mm:g} mm over {aperture_mm:g} mm) is a field of view of {fov:.3g} "
                                           f"degrees, outside the plausible {FOV_RANGE_DEG[0]:g}-{FOV_RANGE_DEG[1]:g}; "
                                           f"expected the three lens values in one unit, tenths of a scene unit "
                                           f"({unit:g} mm here): a 20 mm lens over a 36 mm filmback is "
                                           f"{20 / unit:g} over {36 / unit:g}"))
    for attr in ("horizontalApertureOffset", "verticalApertureOffset"):
        offset = prim.GetAttribute(attr).Get(t)
        if offset:
            out.append(Finding(rule, path, f"{attr} = {offset} is not supported; expected 0 (no lens shift)"))
    near, far = cam.GetClippingRangeAttr().Get(t)
    if not (math.isfinite(near) and math.isfinite(far) and 0 < near < far):
        out.append(Finding(rule, path, f"clippingRange is ({near:g}, {far:g}); expected 0 < near < far"))
    m = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(t), float)
    if not np.all(np.isfinite(m)) or abs(np.linalg.det(m[:3, :3])) < 1e-12:
        out.append(Finding(rule, path, "transform is not finite and invertible (a zero scale?); expected a rigid "
                                       "placement"))
    distortion_found, distortion = read_distortion(prim, t, rule)
    out += distortion_found
    focal, h_ap, v_ap = (prim.GetAttribute(a).Get(t) for a in ("focalLength", "horizontalAperture", "verticalAperture"))
    if distortion is not None and all(v is not None and math.isfinite(v) and v > 0 for v in (focal, h_ap, v_ap)):
        try:  # over the authored filmback; a render checks its own (conformed) image again
            distortion.check_field(h_ap / 2 / focal, v_ap / 2 / focal, where="distortion")
        except InputError as exc:
            out.append(Finding(rule, path, str(exc)))
    return out


def read_distortion(prim: Usd.Prim, t: Usd.TimeCode, rule: str = "camera-lens") -> tuple[list[Finding], BrownConrady | None]:
    """Findings for the camera's ``synthua:distortion:*`` attributes and, when they hold none, the
    distortion they author (None when the prim has none)."""
    path = str(prim.GetPath())
    attrs = [a for a in prim.GetAttributes() if a.GetName().startswith(DISTORTION_PREFIX)]
    if not attrs:
        return [], None
    values, out = {}, []
    for attr in attrs:
        name = attr.GetName()[len(DISTORTION_PREFIX):]
        value = attr.Get(t)
        if name == "model":
            if value != MODEL:
                out.append(Finding(rule, path, f"{attr.GetName()} is {value!r}; expected '{MODEL}'"))
        elif name not in COEFFICIENTS:
            out.append(Finding(rule, path, f"{attr.GetName()} is not a distortion coefficient; expected "
                                           f"{', '.join(DISTORTION_PREFIX + c for c in COEFFICIENTS)}"))
        elif isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            out.append(Finding(rule, path, f"{attr.GetName()} is {value!r}; expected a finite number"))
        else:
            values[name] = float(value)
    if out:
        return out, None
    return [], BrownConrady(**values)
