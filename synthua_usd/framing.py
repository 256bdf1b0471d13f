"""Automatic cameras for a twin that comes without any (imports): an oblique overview of the whole extent
and an eye-level street view, as :class:`CameraSpec` values."""

from __future__ import annotations

import numpy as np

from synthua_usd.cameras import CameraSpec
from synthua_usd.errors import InputError
from synthua_usd.twin import TwinModel

#: Classes a street-level camera may stand on.
STREET_CLASSES = ("road", "street_road", "sidewalk")


def automatic_cameras(model: TwinModel) -> tuple[CameraSpec, ...]:
    """``Overview`` (45 degrees down, the whole horizontal extent in view) and ``Street`` (1.6 m above the
    road or sidewalk point nearest the twin's centre, looking along the road there); full-frame 24 mm."""
    points = [p.points for o in model.objects for p in o.parts if len(p.points)]
    if not points:
        raise InputError(f"{model.source}: the import produced no geometry")
    allp = np.concatenate(points)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    centre = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi[:2] - lo[:2])) / 2, 1.0)
    # 24 mm on 36 x 24 mm sees ~74 x 53 degrees; 1.4 radii away the extent's circle fits at 45 degrees.
    dist = 1.4 * radius
    eye = centre + np.array([-dist * 0.5, -dist * 0.5, dist * 0.7071])
    far = float(4 * dist + 1000)
    point, direction = _street_view(model, centre)
    ground = point if point is not None else np.array([centre[0], centre[1], lo[2]])
    street_eye = ground + [0.0, 0.0, 1.6]
    d = np.asarray(direction, float)
    d = d / (np.linalg.norm(d) or 1.0)
    return (
        CameraSpec("Overview", tuple(eye), tuple(centre), 24.0, 36.0, 24.0, "Oblique overview of the whole twin.",
                   clip_near_m=0.5, clip_far_m=far),
        CameraSpec("Street", tuple(street_eye), tuple(street_eye + [10 * d[0], 10 * d[1], -0.5]), 24.0, 36.0, 24.0,
                   "Eye level at the twin's centre.", clip_near_m=0.05, clip_far_m=far),
    )


def _street_view(model: TwinModel, centre: np.ndarray):
    """A ground point on the road (or sidewalk) part nearest the twin's centre, and the road's main
    direction there; (None, (1, 0)) when the twin has no road."""
    best = None
    for obj in model.objects:
        if obj.label not in STREET_CLASSES:
            continue
        for part in obj.parts:
            if len(part.triangles) == 0:
                continue
            tris = part.points[part.triangles]
            centroids = tris.mean(axis=1)
            up = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])[:, 2] > 0
            if not up.any():
                continue
            d = np.linalg.norm(centroids[up, :2] - centre[:2], axis=1)
            k = int(np.argmin(d))
            if best is None or d[k] < best[0]:
                best = (d[k], centroids[up][k], part.points)
    if best is None:
        return None, (1.0, 0.0)
    xy = best[2][:, :2] - best[2][:, :2].mean(axis=0)
    direction = np.linalg.svd(xy, full_matrices=False)[2][0] if len(xy) > 1 else np.array([1.0, 0.0])
    return best[1], tuple(direction)
