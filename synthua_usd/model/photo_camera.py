"""The camera model of a photo that cut-outs are pasted into: a level ground plane seen by a pinhole camera.

A photo gives no camera, so a composite assumes the least that places people believably: the ground is a plane,
the camera stands ``height_m`` above it, its focal length is ``focal_px`` pixels, and the plane's vanishing line
(the horizon) is the image row ``horizon_row_px`` (rows grow downward; the horizon may lie above or below the
image). Rolls are not modelled: the horizon is a row.

A point of the ground at distance ``Z`` metres in front of the camera (along the ground) appears on row
``y = y_h + f H / Z`` (the camera's pitch moves the horizon, not this relation, for the small pitches of street
photos). Hence, for a paste whose ground point (its *anchor*) lands on row ``y_a > y_h``:

* its distance is ``Z = f H / (y_a - y_h)``;
* it is seen from the elevation ``atan2(H, Z) = atan((y_a - y_h) / f)`` above the ground (what a cut-out's
  rendering camera must match);
* an object ``h`` metres tall standing there is ``h f / Z = h (y_a - y_h) / H`` pixels tall: farther is smaller and
  higher in the frame, and the size does not depend on the focal length.

Read the other way, a photo's own people place its horizon (:func:`horizon_from_people`): a person ``h`` metres tall
(standing, or seated in a wheelchair, from the ground up) whose box stands on row ``y_b`` and is ``p`` pixels tall
puts it on ``y_h = y_b - p H / h``.

Pixel coordinates: (0, 0) is the top-left corner of the image, pixel centres at integer + 0.5 (as in
:mod:`synthua_usd.model.cameras`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np

from synthua_usd.core.errors import InputError

#: The width of the 35 mm film frame, mm: a 35 mm equivalent focal length ``f35`` is ``f35 / 36`` times the long
#: side of the image, in pixels.
FILM_WIDTH_MM = 36.0


def focal_px_from_35mm(f35_mm: float, width_px: int, height_px: int) -> float:
    """The focal length in pixels of an image ``width_px`` x ``height_px`` whose EXIF gives the 35 mm equivalent
    focal length ``f35_mm`` (the film's 36 mm lie along the image's long side)."""
    return float(f35_mm) / FILM_WIDTH_MM * max(int(width_px), int(height_px))


#: A box places the horizon only where it is whole in the photo: both of its top and bottom edges at least this share
#: of the photo's height inside it (a box the photo's edge cuts shows part of a person; a label tool may stop one a
#: pixel or two short of the edge) and at least :data:`MIN_PERSON_PX` tall (written pixels).
PERSON_EDGE_SHARE = 0.01
MIN_PERSON_PX = 16.0


def horizon_from_people(people: Sequence[tuple[tuple[float, float, float, float], float]],
                        photo_rows: tuple[float, float], camera_height_m: float) -> tuple[float, int] | None:
    """The horizon row that a photo's people on the ground put it on, and how many did: for each ``(box,
    height_m)``, a box ``(x0, y0, x1, y1)`` in written pixels, not clipped to the frame, of someone ``height_m``
    tall from the ground up (standing, or seated in a wheelchair), whose rows lie whole in the photo's
    (``photo_rows``: its top and bottom edges in written rows; a cut for the output may crop the box, the photo must
    not), ``y1 - (y1 - y0) camera_height_m / height_m``; their median. None where no box is whole."""
    rows = [box[3] - (box[3] - box[1]) * camera_height_m / height_m for box, height_m in people
            if whole_in_photo(box, photo_rows)]
    return (float(np.median(rows)), len(rows)) if rows else None


def whole_in_photo(box: tuple[float, float, float, float], photo_rows: tuple[float, float]) -> bool:
    """Whether a box ``(x0, y0, x1, y1)`` may place the horizon: its rows whole in the photo's ``photo_rows`` (top
    and bottom edges, the box's coordinates), :data:`PERSON_EDGE_SHARE` of the photo's height inside them, and at
    least :data:`MIN_PERSON_PX` tall."""
    top, bottom = photo_rows
    edge = PERSON_EDGE_SHARE * (bottom - top)
    return box[1] >= top + edge and box[3] <= bottom - edge and box[3] - box[1] >= MIN_PERSON_PX


@dataclass(frozen=True)
class PhotoCamera:
    """The ground-plane camera of one written image (see the module docstring).

    Attributes
    ----------
    width_px, height_px : int
        The written image's size.
    horizon_row_px : float
        Row of the horizon, pixels from the top edge (any value: above the image is negative).
    height_m : float
        Height of the camera above the ground, metres (> 0).
    focal_px : float
        Focal length in pixels (> 0).
    """

    width_px: int
    height_px: int
    horizon_row_px: float
    height_m: float
    focal_px: float

    def __post_init__(self) -> None:
        for name in ("horizon_row_px", "height_m", "focal_px"):
            value = float(getattr(self, name))
            if not math.isfinite(value) or (name != "horizon_row_px" and value <= 0):
                raise InputError(f"camera model: {name} = {value!r}; expected a finite number"
                                 + ("" if name == "horizon_row_px" else " > 0"))
            object.__setattr__(self, name, value)
        if self.width_px < 1 or self.height_px < 1:
            raise InputError(f"camera model: size {self.width_px}x{self.height_px}; expected at least 1x1 pixels")

    @classmethod
    def from_pitch(cls, width_px: int, height_px: int, pitch_deg: float, height_m: float,
                   focal_px: float) -> "PhotoCamera":
        """The camera whose horizon follows from its pitch (negative looks down): ``cy + f tan(pitch)``."""
        horizon = height_px / 2.0 + focal_px * math.tan(math.radians(pitch_deg))
        return cls(width_px, height_px, horizon, height_m, focal_px)

    @property
    def pitch_deg(self) -> float:
        """The pitch this horizon means (negative: the camera looks down, the horizon above the middle row)."""
        return math.degrees(math.atan((self.horizon_row_px - self.height_px / 2.0) / self.focal_px))

    def intrinsics(self) -> np.ndarray:
        """(3, 3) float64 OpenCV intrinsics: ``focal_px`` on both axes, principal point at the image's centre."""
        return np.array([[self.focal_px, 0.0, self.width_px / 2.0], [0.0, self.focal_px, self.height_px / 2.0],
                         [0.0, 0.0, 1.0]])

    def distance_m(self, anchor_row_px: float) -> float:
        """Ground distance of the ground point on ``anchor_row_px`` (which must lie below the horizon), metres."""
        drop = anchor_row_px - self.horizon_row_px
        if drop <= 0:
            raise ValueError(f"anchor row {anchor_row_px:g} is not below the horizon row {self.horizon_row_px:g}")
        return self.focal_px * self.height_m / drop

    def elevation_deg(self, anchor_row_px: float) -> float:
        """Angle from the ground point on ``anchor_row_px`` up to the camera, degrees: atan2(H, Z)."""
        return math.degrees(math.atan2(self.height_m, self.distance_m(anchor_row_px)))

    def pixel_height(self, subject_height_m: float, anchor_row_px: float) -> float:
        """Pixel height of an object ``subject_height_m`` tall standing on the ground point on ``anchor_row_px``:
        ``h (y_a - y_h) / H``."""
        return subject_height_m * (anchor_row_px - self.horizon_row_px) / self.height_m

    def anchor_row(self, subject_height_m: float, pixel_height: float) -> float:
        """The row where an object ``subject_height_m`` tall appears ``pixel_height`` pixels tall (the inverse of
        :meth:`pixel_height`)."""
        return self.horizon_row_px + pixel_height * self.height_m / subject_height_m

    def lowest_anchor_row(self) -> float:
        """The lowest row a ground point may take and still lie in the image: the centre of the last row."""
        return self.height_px - 0.5

    def ground_depth(self) -> np.ndarray:
        """(H, W) float32 z-depth in metres of the ground plane at each pixel centre's row (the distance of the
        ground point on that row; for a level camera z-depth and ground distance agree), 0 (nothing: infinity) on
        and above the horizon."""
        rows = np.arange(self.height_px, dtype=np.float64) + 0.5
        drop = rows - self.horizon_row_px
        depth = np.where(drop > 0, self.focal_px * self.height_m / np.where(drop > 0, drop, 1.0), 0.0)
        return np.repeat(depth.astype(np.float32)[:, None], self.width_px, axis=1)

    def to_dict(self) -> dict:
        return {**asdict(self), "pitch_deg": self.pitch_deg}
