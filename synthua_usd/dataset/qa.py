"""Quality checks of one written image: measures from its display RGB and its record's instances, and the
verdict (accepted, flagged or rejected) with a short reason per failed check.

Measures (names as stored in the record's ``qa.measures``):

* ``blur_laplacian_var``: variance of the Laplacian of the luma, in squared 8-bit levels. Luma is
  ``0.299 R + 0.587 G + 0.114 B`` of the 8-bit sRGB display image (0..255); the Laplacian is the 4-neighbour
  kernel ``[[0,1,0],[1,-4,1],[0,1,0]]`` over interior pixels (no padding), i.e. OpenCV's classic
  ``cv2.Laplacian(gray, cv2.CV_64F).var()`` without its reflected border. A sharp image scores thousands, a
  defocused or foggy one tens; it depends on the image size, so thresholds hold for one output size.
* ``shadows_clipped`` / ``highlights_clipped``: share of pixels whose three channels are all 0 / all 255
  (the pixel lost all detail; a saturated colour with one channel at 255 is not counted).
* ``aid_users``: aid users in the image (see :func:`aid_users`); when there is at least one,
  ``aid_min_pixels`` (visible pixels of the smallest, person and device together) and, when known,
  ``aid_max_occlusion`` (the most occluded one's occlusion).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from synthua_usd.dataset.config import QAThresholds
from synthua_usd.dataset.record import REJECTED

UNKNOWN_AID = "unknown"
LUMA = np.array([0.299, 0.587, 0.114])


@dataclass(frozen=True)
class AidUser:
    """A person instance whose ``relations`` name a device it ``uses``, with that device.

    ``aid_type`` is the device instance's class name (:data:`UNKNOWN_AID` when the device shows no pixel and
    so has no instance); ``visible_pixels`` and ``amodal_pixels`` add person and device; ``occlusion`` is
    ``1 - visible / amodal`` of the pair (the person's own occlusion when the device is not visible; None
    when neither is known)."""

    person_prim: str
    device_prim: str
    aid_type: str
    person_pixels: int
    device_pixels: int
    occlusion: float | None

    @property
    def visible_pixels(self) -> int:
        return self.person_pixels + self.device_pixels


def aid_users(instances: Sequence[Mapping[str, Any]]) -> list[AidUser]:
    """The aid users among a record's ``instances`` (dicts with ``class_name``, ``prim_path``, ``area``,
    optional ``amodal_area``, ``occlusion`` and ``relations``), in instance order. A device out of view
    takes its type from the person's ``relations.uses_class``."""
    by_prim = {inst.get("prim_path"): inst for inst in instances}
    out = []
    for person in instances:
        uses = (person.get("relations") or {}).get("uses")
        if person.get("class_name") != "person" or not uses:
            continue
        device = by_prim.get(uses)
        visible = int(person["area"]) + (int(device["area"]) if device else 0)
        occlusion = person.get("occlusion")
        if device is not None and "amodal_area" in person and "amodal_area" in device:
            amodal = int(person["amodal_area"]) + int(device["amodal_area"])
            occlusion = 1.0 - visible / amodal if amodal > 0 else None
        aid_type = device["class_name"] if device else (person.get("relations") or {}).get("uses_class", UNKNOWN_AID)
        out.append(AidUser(person.get("prim_path", ""), uses, aid_type,
                           int(person["area"]), int(device["area"]) if device else 0,
                           None if occlusion is None else float(occlusion)))
    return out


def laplacian_variance(rgb: np.ndarray) -> float:
    """Variance of the 4-neighbour Laplacian of the luma of ``rgb`` ((H, W, 3) uint8 sRGB), interior pixels,
    squared 8-bit levels; 0.0 for an image smaller than 3 x 3."""
    luma = np.asarray(rgb, dtype=np.float64) @ LUMA
    if luma.shape[0] < 3 or luma.shape[1] < 3:
        return 0.0
    lap = (luma[:-2, 1:-1] + luma[2:, 1:-1] + luma[1:-1, :-2] + luma[1:-1, 2:]) - 4.0 * luma[1:-1, 1:-1]
    return float(lap.var())


def clipped_shares(rgb: np.ndarray) -> tuple[float, float]:
    """(share of pixels with all channels 0, share with all channels 255) of ``rgb`` ((H, W, 3) uint8)."""
    rgb = np.asarray(rgb)
    if rgb.dtype != np.uint8 or rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"expected an (H, W, 3) uint8 display image, got {rgb.dtype} {rgb.shape}")
    pixels = rgb.shape[0] * rgb.shape[1]
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]  # channel by channel: a reduction over the last axis is slow
    return (float(np.count_nonzero((r | g | b) == 0)) / pixels,
            float(np.count_nonzero((r & g & b) == 255)) / pixels)


def measure(rgb: np.ndarray, instances: Sequence[Mapping[str, Any]]) -> dict[str, float]:
    """The QA measures of one image (see the module docstring) from its display RGB ((H, W, 3) uint8) and
    its record's instances."""
    shadows, highlights = clipped_shares(rgb)
    users = aid_users(instances)
    out = {"blur_laplacian_var": laplacian_variance(rgb), "shadows_clipped": shadows,
           "highlights_clipped": highlights, "aid_users": float(len(users))}
    if users:
        out["aid_min_pixels"] = float(min(u.visible_pixels for u in users))
        known = [u.occlusion for u in users if u.occlusion is not None]
        if known:
            out["aid_max_occlusion"] = float(max(known))
    return out


def failures(measures: dict[str, float], thresholds: QAThresholds) -> list[tuple[str, str]]:
    """(check, reason) of every failed check, in the order of :data:`config.QA_CHECKS`."""
    t, m, out = thresholds, measures, []
    if t.blur_min is not None and m["blur_laplacian_var"] < t.blur_min:
        out.append(("blur", f"blur: laplacian variance {m['blur_laplacian_var']:.1f} < {t.blur_min:g}"))
    if t.shadows_clipped_max is not None and m["shadows_clipped"] > t.shadows_clipped_max:
        out.append(("shadows", f"shadows: {100 * m['shadows_clipped']:.1f} % of pixels at 0 > "
                               f"{100 * t.shadows_clipped_max:g} %"))
    if t.highlights_clipped_max is not None and m["highlights_clipped"] > t.highlights_clipped_max:
        out.append(("highlights", f"highlights: {100 * m['highlights_clipped']:.1f} % of pixels at 255 > "
                                  f"{100 * t.highlights_clipped_max:g} %"))
    if t.aid_min_pixels is not None and "aid_min_pixels" in m and m["aid_min_pixels"] < t.aid_min_pixels:
        out.append(("aid_size", f"aid_size: smallest aid user {m['aid_min_pixels']:.0f} px < {t.aid_min_pixels}"))
    if t.aid_max_occlusion is not None and "aid_max_occlusion" in m and m["aid_max_occlusion"] > t.aid_max_occlusion:
        out.append(("aid_occlusion", f"aid_occlusion: most occluded aid user {m['aid_max_occlusion']:.2f} > "
                                     f"{t.aid_max_occlusion:g}"))
    return out


def verdict(measures: dict[str, float], thresholds: QAThresholds) -> tuple[str, list[str]]:
    """(``accepted`` | ``flagged`` | ``rejected``, reasons): rejected when a failed check is in
    ``thresholds.reject``, flagged when any other check failed, else accepted with no reasons."""
    failed = failures(measures, thresholds)
    if not failed:
        return "accepted", []
    rejected = any(thresholds.action(check) == REJECTED for check, _ in failed)
    return (REJECTED if rejected else "flagged"), [reason for _, reason in failed]
