"""One composite painted: cut-outs placed on a photo with their shadows, matched exposure, white balance and
(where asked) sharpness, contrast and saturation, and their blend edges, with the label maps that follow from them.
Pixel work only: where each paste goes is planned in :mod:`synthua_usd.dataset.composite_plan`.

Order of operations, all in linear light (8-bit sRGB decoded by the sRGB curve, encoded back and rounded once per
step) but step 4's, which works on the sRGB values:

0. **Tone** of each paste (where ``contrast_strength`` or ``saturation_strength`` > 0), a partial transfer of colour
   statistics from the photo around the paste (as Reinhard et al., "Color transfer between images", 2001, transfer
   a spread; Xue et al., "Understanding and improving the realism of image composites", 2012, found such statistics
   of foreground and background to decide whether a composite looks real). Both parts are sampled as in step 1
   (every other pixel of every other row; the photo's pixels around the paste, the paste's own of alpha > 0.5,
   weighted by alpha), and only pixels brighter than ``TONE_MIN_LUMINANCE`` count: contrast is the standard
   deviation of ln Y, saturation the mean of ``||rgb - Y|| / Y`` (Euclidean over the channels). The paste's chroma
   ``rgb - Y`` is scaled by ``clip((s_photo / s_paste) ^ saturation_strength)``, Y kept (a pixel whose channel would
   go below 0 is scaled only until that channel reaches 0); then its ln Y is scaled about its mean (over the
   pixels measured) by ``clip((c_photo / c_paste) ^ contrast_strength)``, chromaticity kept (pixels darker than the
   threshold take the threshold's factor). A photo with no spread or chroma asks for the gain's lower clamp; a paste
   with none, or either part with too few pixels to measure, gets 1. The two measures move independently, and
   steps 1-3 work on the paste so toned (a contrast above 1 raises its mean linear luminance, which exposure
   matching then answers). Renders are more colourful and flatter than the photos they are pasted into (their
   palettes and light, not a camera's tone curve, set them).
1. **Gains** of each paste, measured on the photo as it came: the mean linear RGB of the photo in the paste's box
   widened by ``surround_share`` of its size on every side (every other pixel of every other row; the paste's own
   pixels, alpha > 0, left out) against
   the paste's alpha-weighted mean colour. Exposure gain ``clip((Y_photo / Y_paste) ^ exposure_strength)``; white
   balance gains per channel ``(c_photo ^ white_balance_strength)``, with ``c = rgb / Y`` the chromaticity of the
   photo around the paste (grey world: the cast of its light, (1, 1, 1) for a neutral one), normalised to keep
   luminance, then clipped: the paste takes part of the photo's colour cast (the cut-out's own colours, a red
   coat, say nothing of its light, so they are not compared). Y is Rec. 709 luminance.
   **Sharpness** (where ``sharpness_strength`` > 0): the blur of an image part's edges is estimated by re-blurring
   (after Zhuo and Sim, "Defocus map estimation from a single image", 2011, with two Gaussians for noise): the
   gradient of its sRGB luminance is taken by derivative-of-Gaussian filters at two scales s1 < s2
   (``EDGE_SCALES_PX``); at its edges (local maxima, the strongest tenth, of the gradient at s2) the ratio R of the
   two gradient magnitudes gives a Gaussian edge of blur b with b^2 = (s2^2 - R^2 s1^2) / (R^2 - 1); the part's
   blur is the median (a pixel-sampled sharp edge reads about 0.3-0.45 px, whatever its direction). The filters
   are normalised convolutions, weighted by the pixels that belong to the part (the photo's around the paste, the
   cut-out's alpha), so a silhouette's edge is not an edge. A paste whose edges are sharper than the photo's
   (b_paste < b_photo) has its colour blurred, within its own pixels, by a Gaussian of ``sqrt(b^2 - b_paste^2)``,
   ``b = b_paste + strength x (b_photo - b_paste)``, at most ``sharpness_sigma_px``; never sharpened. Its labelled
   pixels and alpha stay as they are (the silhouette's edge is the blend mode's).
2. **Shadows** of every paste on the photo: each pixel times ``1 - strength x (1 - shadow)``, the shadows of all
   pastes multiplied (they fall on the ground, under every paste).
3. **Pastes**, far to near (their ``order``), each with its mode: ``hard`` (the paste covers exactly its labelled
   pixels, in its straight colour; a labelled pixel no sample of the cut-out covered, a spoke thinner than a pixel,
   keeps the photo), ``feather`` (alpha x clip(d / feather_px, 0, 1), d the distance in pixels from the pixel to the
   nearest one the paste does not label: the edge fades inwards, and nothing shows outside the labels), ``blur``
   (alpha and premultiplied colour blurred by a Gaussian of ``sigma_px``) or ``poisson``
   (:mod:`synthua_usd.backends.poisson_blend` over the labelled pixels widened by 2 px within the crop, bounded by
   the photo's pixels around it: the paste's own gradients and the photo's, none across the silhouette, so the
   paste's colour slides to meet the photo; jobs whose ``generate.json`` has no ``job_key.seamless_poisson`` took
   every gradient of the hard composite, which gives the hard paste back where the domain keeps off the crop's
   own edges, and imposed the photo's values on those edges, labelled pixels there too). Where the frame's edge
   cuts a paste, the paste goes on beyond it: the blur repeats the paste's last row or column there, Poisson leaves
   the cut open (no photo value imposed along it), and feather's d is measured within the frame (the cut does not
   fade).
   Jobs whose ``generate.json`` has no ``job_key.open_cuts`` (made before it, on or before 7 December 2026) faded
   blurred and Poisson pastes towards the photo along a cut (``open_cuts`` False keeps that for their replay).
4. **Sharpening** of a paste the plan sharpens, right after its blend (a nearer paste painted later covers it): the
   composite's sRGB values ``v`` around the paste, ``v + amount x (v - G(v))`` with ``G`` a Gaussian of
   ``sigma_px`` (reflecting at the frame's edges), written back over the paste's labelled pixels only. The
   photo's pixels keep their values; the paste's silhouette is sharpened against the photo behind it.

Labels: a pasted pixel takes the instance of the cut-out's ``ids`` there (nearest, :mod:`.cutout_pixels`), a nearer
paste over a farther one; the photo's pixels are void (class 0, no instance). Amodal masks are each cut-out's own,
placed, never reduced by another paste.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy import ndimage

from synthua_usd.backends.cutout_pixels import LINEAR_LUT, CutoutPixels, PlacedCutout, place
from synthua_usd.backends.poisson_blend import poisson_blend
from synthua_usd.dataset.composite_config import MatchSettings
from synthua_usd.dataset.composite_plan import Placement
from synthua_usd.dataset.cutout_bank import BankEntry
from synthua_usd.model.scene import Instance
from synthua_usd.model.srgb import from_linear
from synthua_usd.model.taxonomy import ClassMap

LUMINANCE = np.array([0.2126, 0.7152, 0.0722], np.float64)
#: The two scales (px) of the edge-blur estimate's derivative-of-Gaussian filters.
EDGE_SCALES_PX = (1.0, 2.0)
#: Edges: local gradient maxima in this top share of a part's gradients, and at least this many of them.
EDGE_TOP_SHARE, EDGE_MIN_COUNT = 0.1, 12
#: The least gradient (sRGB luminance per px, at the larger scale) an edge has: flat parts have no edges.
EDGE_MIN_GRADIENT = 0.01
#: Contrast and saturation are measured over pixels brighter than this linear luminance (darker ones carry sensor
#: noise and quantisation, not tone), and only where at least this many sampled pixels are left.
TONE_MIN_LUMINANCE, TONE_MIN_PIXELS = 0.005, 64
#: Pixels the Poisson domain reaches beyond the labelled ones.
POISSON_MARGIN_PX = 2


def encode(linear: np.ndarray) -> np.ndarray:
    """Linear values -> 8-bit sRGB (clipped to [0, 1], rounded)."""
    return np.round(from_linear(np.clip(linear, 0.0, 1.0)) * 255.0).astype(np.uint8)


@dataclass(frozen=True)
class PasteInput:
    """What painting one paste needs: its cut-out (entry and pixels) and its placement."""

    entry: BankEntry
    pixels: CutoutPixels = field(repr=False)
    placement: Placement


@dataclass(eq=False)
class Composite:
    """A painted composite. ``rgb`` (H, W, 3) uint8 sRGB; ``class_ids`` (H, W) uint8 and ``instance_ids`` (H, W)
    uint16 (0: the photo); ``instances`` every pasted instance (visible or not); ``amodal`` instance id -> sorted
    row-major flat indices of its amodal pixels in the frame; ``truncation`` instance id -> share of its amodal
    pixels the frame cuts off; ``keypoints`` instance id -> (k, 3) float64 frame (x, y, v) as the cut-out gives
    them (visibility not yet updated); ``pastes`` per paste (in ``order``): the instance ids it got and its gains;
    ``first_id`` per paste."""

    rgb: np.ndarray = field(repr=False)
    class_ids: np.ndarray = field(repr=False)
    instance_ids: np.ndarray = field(repr=False)
    instances: list[Instance]
    amodal: dict
    truncation: dict
    keypoints: dict
    pastes: list[dict]


def _around(photo: np.ndarray, placed: PlacedCutout, box, share: float) -> np.ndarray:
    """The photo's linear RGB around a paste (n, 3) float32: its box widened by ``share`` of its size on every side,
    every other pixel of every other row, the paste's own pixels (alpha > 0) left out."""
    wx0, wy0, wx1, wy1 = window = _window(photo.shape, box, share)
    keep = _photo_only(placed, window)
    return LINEAR_LUT[photo[wy0:wy1:2, wx0:wx1:2]][keep[::2, ::2]]


def paste_gains(photo: np.ndarray, placed: PlacedCutout, box, settings: MatchSettings) -> tuple[float, list[float]]:
    """(exposure gain, [r, g, b] white-balance gains) of one paste over ``photo`` (H, W, 3) uint8 (see the module
    docstring, step 1)."""
    # every other pixel of every other row: the mean of a few thousand pixels, at a quarter of the cost
    around = _around(photo, placed, box, settings.surround_share).astype(np.float64)
    weight = float(placed.premultiplied[..., 3].sum())
    if around.size == 0 or weight <= 0:
        return 1.0, [1.0, 1.0, 1.0]
    m_photo = around.mean(axis=0)
    m_paste = placed.premultiplied[..., :3].reshape(-1, 3).sum(axis=0).astype(np.float64) / weight
    y_photo, y_paste = float(m_photo @ LUMINANCE), float(m_paste @ LUMINANCE)
    if y_photo <= 1e-6 or y_paste <= 1e-6 or m_photo.min() <= 1e-6:
        return 1.0, [1.0, 1.0, 1.0]
    exposure = float(np.clip((y_photo / y_paste) ** settings.exposure_strength, *settings.exposure_gain))
    balance = (m_photo / y_photo) ** settings.white_balance_strength
    balance = np.clip(balance / float(balance @ LUMINANCE), *settings.white_balance_gain)
    return exposure, [float(v) for v in balance]


def _tone_measures(linear: np.ndarray, weight: np.ndarray) -> tuple[float | None, float | None]:
    """(contrast, saturation) of linear RGB pixels (n, 3) weighted by ``weight`` (n,), in float64: the standard
    deviation of the natural log of luminance, and the mean chroma ``||rgb - Y|| / Y`` (Euclidean over the
    channels), over the pixels of weight > 0 brighter than ``TONE_MIN_LUMINANCE``; (None, None) where fewer than
    ``TONE_MIN_PIXELS`` of them are left."""
    linear = linear.astype(np.float64)
    luminance = linear @ LUMINANCE
    bright = (luminance > TONE_MIN_LUMINANCE) & (weight > 0)
    if int(bright.sum()) < TONE_MIN_PIXELS:
        return None, None
    y, w = luminance[bright], weight[bright].astype(np.float64)
    w = w / w.sum()
    log_y = np.log(y)
    contrast = float(np.sqrt(w @ (log_y - w @ log_y) ** 2))
    chroma = np.linalg.norm(linear[bright] - y[:, None], axis=1) / y
    return contrast, float(w @ chroma)


def _straight(premultiplied: np.ndarray) -> np.ndarray:
    """Straight (un-premultiplied) linear RGB of premultiplied RGBA pixels (..., 4)."""
    return premultiplied[..., :3] / np.maximum(premultiplied[..., 3:], 1e-6)


def _tone_gain(photo: float | None, paste: float | None, strength: float, clamp) -> float:
    """(photo / paste) ^ strength, clamped; 1 where matching is off or the paste has nothing to scale (a photo with
    nothing asks for the clamp's low end)."""
    if strength <= 0 or photo is None or paste is None or paste <= 1e-9:
        return 1.0
    return round(float(np.clip((photo / paste) ** strength, *clamp)), 4)


def tone_gains(photo: np.ndarray, placed: PlacedCutout, box, settings: MatchSettings) -> tuple[float, float]:
    """(contrast gain, saturation gain) of one paste over ``photo`` (module docstring, step 0)."""
    if settings.contrast_strength <= 0 and settings.saturation_strength <= 0:
        return 1.0, 1.0
    around = _around(photo, placed, box, settings.surround_share)
    photo_c, photo_s = _tone_measures(around, np.ones(len(around)))
    sampled = placed.premultiplied[::2, ::2]
    inside = sampled[..., 3] > 0.5
    paste_c, paste_s = _tone_measures(_straight(sampled[inside]), sampled[..., 3][inside])
    return (_tone_gain(photo_c, paste_c, settings.contrast_strength, settings.contrast_gain),
            _tone_gain(photo_s, paste_s, settings.saturation_strength, settings.saturation_gain))


def retone(placed: PlacedCutout, contrast: float, saturation: float) -> PlacedCutout:
    """``placed`` with its colour's contrast and saturation scaled (module docstring, step 0): each pixel's chroma
    ``rgb - Y`` times ``saturation`` (Y kept; where a channel would go below 0, only as far as it reaching 0), then
    its ln Y moved from the paste's mean ln Y (alpha-weighted over its pixels of alpha > 0.5 brighter than
    ``TONE_MIN_LUMINANCE``, summed in float64) by ``contrast``, chromaticity kept; alpha, silhouette and labels
    unchanged."""
    if contrast == 1.0 and saturation == 1.0:
        return placed
    out = placed.premultiplied.copy()
    shown = out[..., 3] > 0
    alpha = out[..., 3][shown]
    straight = _straight(out[shown])
    weights = LUMINANCE.astype(np.float32)
    luminance = straight @ weights
    if saturation != 1.0:
        chroma = straight - luminance[:, None]
        lowest = chroma.min(axis=1)                      # the most a channel may lose is its share of Y
        room = np.where(lowest < 0, luminance / np.maximum(-lowest, 1e-12), np.inf)
        factor = np.minimum(np.float32(saturation), room).astype(np.float32)
        straight = np.maximum(luminance[:, None] + factor[:, None] * chroma, 0.0)
    if contrast != 1.0:
        log_y = np.log(np.maximum(luminance, TONE_MIN_LUMINANCE))
        counted = (luminance > TONE_MIN_LUMINANCE) & (alpha > 0.5)
        w = alpha[counted].astype(np.float64)
        mean = float(w @ log_y[counted].astype(np.float64) / w.sum()) if counted.any() else 0.0
        factor = np.exp(np.float32(contrast - 1.0) * (log_y - np.float32(mean)))
        straight = straight * np.where(luminance > 0, factor, np.float32(1.0))[:, None]
    out[..., :3][shown] = straight * alpha[:, None]
    return replace(placed, premultiplied=out)


def _smooth(values: np.ndarray, weight: np.ndarray, sigma: float) -> np.ndarray:
    """``values`` (h, w) smoothed by a Gaussian of ``sigma`` px weighted by ``weight`` (a normalised convolution:
    pixels of weight 0 do not count; a pixel with no weighted pixel within reach comes out 0)."""
    num = ndimage.gaussian_filter(values * weight, sigma, mode="constant")
    den = ndimage.gaussian_filter(weight, sigma, mode="constant")
    return np.where(den > 1e-6, num / np.maximum(den, 1e-6), 0.0).astype(np.float32)


def _gradient(values: np.ndarray, weight: np.ndarray, sigma: float) -> np.ndarray:
    """The gradient magnitude (h, w) of ``values`` smoothed by the normalised convolution of :func:`_smooth`,
    taken analytically with derivative-of-Gaussian filters: grad(N / D) = (D grad N - N grad D) / D^2."""
    weighted = values * weight
    num = ndimage.gaussian_filter(weighted, sigma, mode="constant")
    den = ndimage.gaussian_filter(weight, sigma, mode="constant")
    reached = den > 1e-3
    square = np.where(reached, den * den, 1.0)
    parts = []
    for order in ((1, 0), (0, 1)):
        d_num = ndimage.gaussian_filter(weighted, sigma, order=order, mode="constant")
        d_den = ndimage.gaussian_filter(weight, sigma, order=order, mode="constant")
        parts.append(np.where(reached, (d_num * den - num * d_den) / square, 0.0))
    return np.hypot(*parts).astype(np.float32)


def edge_blur(luma: np.ndarray, weight: np.ndarray, mask: np.ndarray) -> float | None:
    """The Gaussian blur (px) of the edges of ``luma`` (h, w) within ``mask`` (module docstring, step 1), the
    smoothing weighted by ``weight``; None where the part has fewer than ``EDGE_MIN_COUNT`` edges."""
    inner = ndimage.binary_erosion(mask, iterations=2)
    if int(inner.sum()) < EDGE_MIN_COUNT:
        return None
    first, second = EDGE_SCALES_PX
    sharp, soft = _gradient(luma, weight, first), _gradient(luma, weight, second)
    candidates = inner & (soft >= EDGE_MIN_GRADIENT)
    if int(candidates.sum()) < EDGE_MIN_COUNT:
        return None
    floor = float(np.quantile(soft[candidates], 1.0 - EDGE_TOP_SHARE))
    edges = candidates & (soft >= floor) & (soft >= ndimage.maximum_filter(soft, size=3))
    ratio = sharp[edges] / soft[edges]
    ratio = ratio[ratio > 1.0 + 1e-3]
    if ratio.size < EDGE_MIN_COUNT:
        return None
    squared = (second * second - ratio * ratio * first * first) / (ratio * ratio - 1.0)
    return float(np.sqrt(max(float(np.median(squared)), 0.0)))


def _luma(srgb: np.ndarray) -> np.ndarray:
    """Rec. 709 luminance of sRGB-coded values in [0, 1] (h, w, 3) -> (h, w) float32."""
    return (srgb.astype(np.float32) @ LUMINANCE.astype(np.float32)).astype(np.float32)


def _window(shape: tuple[int, ...], box, share: float) -> tuple[int, int, int, int]:
    """The paste's box widened by ``share`` of its size on every side, clipped to the frame: x0, y0, x1, y1."""
    height, width = shape[:2]
    x0, y0, x1, y1 = box
    grow_x, grow_y = share * (x1 - x0), share * (y1 - y0)
    return (max(0, int(np.floor(x0 - grow_x))), max(0, int(np.floor(y0 - grow_y))),
            min(width, int(np.ceil(x1 + grow_x))), min(height, int(np.ceil(y1 + grow_y))))


def _photo_only(placed: PlacedCutout, window: tuple[int, int, int, int]) -> np.ndarray:
    """(h, w) bool over ``window``: the photo's pixels there, the paste's own (alpha > 0) left out."""
    wx0, wy0, wx1, wy1 = window
    keep = np.ones((wy1 - wy0, wx1 - wx0), bool)
    rx0, ry0, rx1, ry1 = placed.region
    ox0, oy0, ox1, oy1 = max(rx0, wx0), max(ry0, wy0), min(rx1, wx1), min(ry1, wy1)
    if ox0 < ox1 and oy0 < oy1:
        keep[oy0 - wy0:oy1 - wy0, ox0 - wx0:ox1 - wx0] &= placed.premultiplied[oy0 - ry0:oy1 - ry0,
                                                                               ox0 - rx0:ox1 - rx0, 3] <= 0
    return keep


def sharpness_sigma(photo: np.ndarray, placed: PlacedCutout, box, settings: MatchSettings) -> float:
    """The Gaussian sigma (px) that softens one paste's colour toward the edge blur of the photo around it (module
    docstring, step 1); 0 where matching is off, the paste is no sharper than the photo, or either part has too
    few edges to measure."""
    strength = settings.sharpness_strength
    if strength <= 0 or settings.sharpness_sigma_px <= 0:
        return 0.0
    wx0, wy0, wx1, wy1 = window = _window(photo.shape, box, settings.surround_share)
    keep = _photo_only(placed, window)
    blur_photo = edge_blur(_luma(photo[wy0:wy1, wx0:wx1] / 255.0), keep.astype(np.float32), keep)
    alpha = placed.premultiplied[..., 3]
    straight = np.clip(_straight(placed.premultiplied), 0.0, 1.0)
    blur_paste = edge_blur(_luma(from_linear(straight)), alpha, alpha >= 0.999)
    if blur_photo is None or blur_paste is None or blur_paste >= blur_photo:
        return 0.0
    wanted = blur_paste + strength * (blur_photo - blur_paste)
    return round(min(float(np.sqrt(wanted * wanted - blur_paste * blur_paste)), settings.sharpness_sigma_px), 3)


def soften(premultiplied: np.ndarray, sigma: float) -> np.ndarray:
    """Premultiplied linear RGB (h, w, 3) of a cut-out blurred within its own pixels by a Gaussian of ``sigma``
    (the straight colour smoothed by alpha-weighted normalised convolution, times alpha again): alpha and the
    silhouette stay as they are; nothing transparent bleeds in."""
    if sigma <= 0:
        return premultiplied[..., :3]
    alpha = premultiplied[..., 3]
    straight = _straight(premultiplied)
    return np.stack([_smooth(straight[..., c], alpha, sigma) * alpha for c in range(3)], axis=-1)


def _blur_beyond_cuts(values: np.ndarray, sigma: float, cut: tuple[bool, bool, bool, bool]) -> np.ndarray:
    """``values`` (h, w) or (h, w, C) blurred by a Gaussian of ``sigma`` over its first two axes: transparent (0)
    beyond the crop's own edges, and beyond an edge where the frame cuts it (``cut``: left, top, right, bottom) the
    crop's last row or column repeated (the paste goes on there)."""
    reach = int(4.0 * sigma + 0.5) + 1              # the Gaussian below reaches int(truncate x sigma + 0.5) pixels
    left, top, right, bottom = (reach if side else 0 for side in cut)
    pad = ((top, bottom), (left, right)) + ((0, 0),) * (values.ndim - 2)
    padded = np.pad(values, pad, mode="edge")
    blurred = ndimage.gaussian_filter(padded, (sigma, sigma) + (0,) * (values.ndim - 2), mode="constant",
                                      truncate=4.0)
    h, w = values.shape[:2]
    return blurred[top:top + h, left:left + w]


def _blend(region: np.ndarray, placed: PlacedCutout, colour: np.ndarray, blend: dict,
           open_cuts: bool = True, seamless_poisson: bool = True,
           around: tuple[np.ndarray, tuple[int, int, int, int]] | None = None) -> np.ndarray:
    """The region (h, w, 3) float32 linear with the paste blended over it; ``colour`` its premultiplied linear RGB
    with gains applied. ``open_cuts``: where the frame cuts the paste, the blur and Poisson blends take the paste
    to go on beyond the frame (else, as jobs without ``job_key.open_cuts`` did, the blur fades it to transparent and
    Poisson meets the photo's colour along the cut). ``seamless_poisson``: Poisson imports the paste's own gradients
    and the photo's but not the jump at its silhouette, over a domain that may reach the crop's own edges, bounded
    by the photo's pixels beyond them: ``around`` holds the linear image over the region grown by the frame pixels
    beyond each edge (at most one) and how many (top, bottom, left, right); where there is none (the frame cuts
    the paste there, or the crop ends at the frame's edge) the domain is open. Else, as jobs without
    ``job_key.seamless_poisson`` did, the hard composite's every gradient, which gives the hard paste back where
    the domain keeps off the crop's edges; there the photo's values are imposed, a labelled pixel on the edge keeps
    the photo, and the clash fades into the paste."""
    alpha = placed.premultiplied[..., 3]
    mode = blend["mode"]
    cut = placed.cut if open_cuts else (False, False, False, False)
    if mode == "feather":
        inside = ndimage.distance_transform_edt(placed.ids > 0)
        fade = np.clip(inside / max(blend["feather_px"], 1e-6), 0.0, 1.0).astype(np.float32)
        return region * (1.0 - alpha * fade)[..., None] + colour * fade[..., None]
    if mode == "blur":
        sigma = blend["sigma_px"]
        if any(cut):
            alpha_b, colour_b = _blur_beyond_cuts(alpha, sigma, cut), _blur_beyond_cuts(colour, sigma, cut)
        else:
            alpha_b = ndimage.gaussian_filter(alpha, sigma, mode="constant")
            colour_b = ndimage.gaussian_filter(colour, (sigma, sigma, 0), mode="constant")
        return region * (1.0 - alpha_b)[..., None] + colour_b
    labelled = placed.ids > 0
    # a labelled pixel no sample covered (a spoke thinner than a pixel) has no colour: the photo shows there
    covered = labelled & (alpha > 1e-6)
    straight = colour / np.maximum(alpha, 1e-6)[..., None]
    hard = np.where(covered[..., None], straight, region)
    if mode == "hard":
        return hard
    domain = ndimage.binary_dilation(labelled, iterations=POISSON_MARGIN_PX)
    left, top, right, bottom = cut
    if seamless_poisson:    # the photo's pixels beyond the crop bound it; open where the frame has none
        wide, (grow_top, _, grow_left, _) = around if around is not None else (region, (0, 0, 0, 0))
        inner = (slice(grow_top, grow_top + labelled.shape[0]), slice(grow_left, grow_left + labelled.shape[1]))
        source = np.array(wide)
        source[inner] = hard
        grown, regions = np.zeros(wide.shape[:2], bool), np.zeros(wide.shape[:2], bool)
        grown[inner], regions[inner] = domain, covered     # the paste's gradients and the photo's, none between
        return poisson_blend(wide, source, grown, regions)[inner].astype(np.float32)
    # the photo's values on the crop's own edges; open where the frame cuts it
    if not top:
        domain[0] = False
    if not bottom:
        domain[-1] = False
    if not left:
        domain[:, 0] = False
    if not right:
        domain[:, -1] = False
    return poisson_blend(region, hard, domain).astype(np.float32)


def sharpen(rgb: np.ndarray, placed: PlacedCutout, amount: float, sigma: float) -> None:
    """Unsharp-mask ``rgb`` (H, W, 3) uint8 sRGB in place over ``placed``'s labelled pixels (module docstring,
    step 4)."""
    height, width = rgb.shape[:2]
    rows, cols = placed.slices
    reach = int(np.ceil(4.0 * sigma))
    y0, y1 = max(0, rows.start - reach), min(height, rows.stop + reach)
    x0, x1 = max(0, cols.start - reach), min(width, cols.stop + reach)
    values = rgb[y0:y1, x0:x1].astype(np.float32) / np.float32(255.0)
    blurred = ndimage.gaussian_filter(values, (sigma, sigma, 0), mode="reflect", truncate=4.0)
    sharp = np.round(np.clip(values + np.float32(amount) * (values - blurred), 0.0, 1.0) * 255.0).astype(np.uint8)
    inner = sharp[rows.start - y0:rows.stop - y0, cols.start - x0:cols.stop - x0]
    labelled = placed.ids > 0
    rgb[rows, cols] = np.where(labelled[..., None], inner, rgb[rows, cols])


def _prim_path(order: int, entry: BankEntry, index: int) -> str:
    """A pasted instance's path: its paste, cut-out and instance (no USD prim: it names where it came from)."""
    role = next(i.role for i in entry.instances if i.index == index)
    return f"/pastes/p{order}/{entry.id}/{role}{index}"


def _class_id(class_map: ClassMap, name: str) -> int:
    """The id of a pasted instance's class; the bank's reader has checked that its class map names it."""
    found = class_map.resolve(name)
    if found is None:
        raise ValueError(f"class '{name}' of a cut-out is not in the class map it was read with")
    return found.id


def compose(photo: np.ndarray, pastes: list[PasteInput], class_map: ClassMap, settings: MatchSettings,
            open_cuts: bool = True, seamless_poisson: bool = True) -> Composite:
    """Paint ``pastes`` (sorted by their placement's ``order``) over ``photo`` (H, W, 3) uint8 sRGB; ``open_cuts``
    and ``seamless_poisson`` as :func:`_blend` takes them."""
    height, width = photo.shape[:2]
    placed = [place(p.pixels, p.entry, p.placement.anchor_px, p.placement.scale, (width, height)) for p in pastes]
    tones = [tone_gains(photo, pc, p.placement.box, settings) if pc is not None else (1.0, 1.0)
             for p, pc in zip(pastes, placed)]
    placed = [retone(pc, *tone) if pc is not None else None for pc, tone in zip(placed, tones)]
    gains = [paste_gains(photo, pc, p.placement.box, settings) if pc is not None else (1.0, [1.0, 1.0, 1.0])
             for p, pc in zip(pastes, placed)]
    sigmas = [sharpness_sigma(photo, pc, p.placement.box, settings) if pc is not None else 0.0
              for p, pc in zip(pastes, placed)]
    rgb = photo.copy()
    light = np.ones((height, width), np.float32)
    for p, pc in zip(pastes, placed):
        if pc is not None:
            light[pc.slices] *= 1.0 - p.placement.shadow_strength * (1.0 - pc.shadow)
    shaded = np.flatnonzero((light < 1.0).any(axis=1)), np.flatnonzero((light < 1.0).any(axis=0))
    if shaded[0].size:
        rows, cols = slice(shaded[0][0], shaded[0][-1] + 1), slice(shaded[1][0], shaded[1][-1] + 1)
        rgb[rows, cols] = encode(LINEAR_LUT[rgb[rows, cols]] * light[rows, cols, None])
    class_ids = np.zeros((height, width), np.uint8)
    instance_ids = np.zeros((height, width), np.uint16)
    instances, amodal, truncation, keypoints, records = [], {}, {}, {}, []
    next_id = 1
    for p, pc, (exposure, balance), sigma, (contrast, saturation) in zip(pastes, placed, gains, sigmas, tones):
        entry, order = p.entry, p.placement.order
        ids = {inst.index: next_id + k for k, inst in enumerate(entry.instances)}
        next_id += len(entry.instances)
        paths = {index: _prim_path(order, entry, index) for index in ids}
        class_of = {inst.index: _class_id(class_map, inst.class_name) for inst in entry.instances}
        for inst in entry.instances:
            instances.append(Instance(ids[inst.index], paths[inst.index], class_of[inst.index],
                                      inst.class_name, True, tuple((name, paths[target])
                                                                   for name, target in inst.relations)))
            if inst.keypoints is not None:
                points = np.array(inst.keypoints, np.float64).reshape(-1, 3)
                ax, ay = entry.anchor
                points[:, 0] = p.placement.anchor_px[0] + p.placement.scale * (points[:, 0] - ax)
                points[:, 1] = p.placement.anchor_px[1] + p.placement.scale * (points[:, 1] - ay)
                keypoints[ids[inst.index]] = points
        records.append({"order": order, "instance_ids": sorted(ids.values()), "exposure_gain": exposure,
                        "white_balance_gains": balance, "in_frame": pc is not None})
        if settings.sharpness_strength > 0:
            records[-1]["sharpness_sigma_px"] = sigma
        if settings.contrast_strength > 0:
            records[-1]["contrast_gain"] = contrast
        if settings.saturation_strength > 0:
            records[-1]["saturation_gain"] = saturation
        if pc is None:
            for index, gid in ids.items():
                amodal[gid], truncation[gid] = np.zeros(0, np.int64), 1.0
            continue
        rows, cols = pc.slices
        colour = soften(pc.premultiplied, sigma) * np.float32(exposure) * np.asarray(balance, np.float32)
        # the region and the frame pixels beyond each of its edges (at most one), for Poisson's boundary
        grow = (min(1, rows.start), min(1, height - rows.stop), min(1, cols.start), min(1, width - cols.stop))
        wide = LINEAR_LUT[rgb[rows.start - grow[0]:rows.stop + grow[1], cols.start - grow[2]:cols.stop + grow[3]]]
        region = wide[grow[0]:wide.shape[0] - grow[1], grow[2]:wide.shape[1] - grow[3]]
        rgb[rows, cols] = encode(_blend(region, pc, colour, p.placement.blend, open_cuts, seamless_poisson,
                                        (wide, grow)))
        if p.placement.sharpen is not None:
            sharpen(rgb, pc, p.placement.sharpen["amount"], p.placement.sharpen["sigma_px"])
        table = np.zeros(256, np.uint16)
        classes = np.zeros(256, np.uint8)
        for index, gid in ids.items():
            table[index] = gid
            classes[index] = class_of[index]
        labelled = pc.ids > 0
        instance_ids[rows, cols] = np.where(labelled, table[pc.ids], instance_ids[rows, cols])
        class_ids[rows, cols] = np.where(labelled, classes[pc.ids], class_ids[rows, cols])
        x0, y0 = pc.region[:2]
        for index, gid in ids.items():
            r, c = np.nonzero(pc.amodal & np.uint16(1 << (index - 1)))
            amodal[gid] = np.sort((r + y0) * width + (c + x0))
            total = amodal[gid].size + pc.outside[index]
            truncation[gid] = pc.outside[index] / total if total else 0.0
    return Composite(rgb, class_ids, instance_ids, instances, amodal, truncation, keypoints, records)


def composite_depth(ground: np.ndarray, composite: Composite, distances: list[float]) -> np.ndarray:
    """(H, W) float32 z-depth for effects that read depth: ``ground`` (the photo's ground plane, 0 = infinity) with
    each paste's visible pixels at its anchor's distance (``distances``, one per paste in order)."""
    depth = ground.copy()
    for paste, distance in zip(composite.pastes, distances):
        ids = paste["instance_ids"]
        mask = (composite.instance_ids >= ids[0]) & (composite.instance_ids <= ids[-1])
        depth[mask] = distance
    return depth
