"""Camera effects on a finished 8-bit sRGB image: what a real camera adds between the scene and the file, applied
after rendering to the display image (labels untouched, geometry unchanged). The draw of one image is plain data,
:class:`synthua_usd.randomisation.effects.EffectsDraw`; :func:`apply_effects` applies it. No renderer here.

The 8-bit values are decoded to linear light (the sRGB curve, :mod:`synthua_usd.model.srgb`), the effects run in
float64 in the order a camera meets them (:data:`synthua_usd.randomisation.config.EFFECTS`), the result is clipped
to [0, 1], encoded and rounded to 8 bits, and JPEG, if drawn, is last:

* **defocus**: a thin lens focused at z-depth S (``focus_m``) blurs a point at z-depth d to a disc of radius
  r(d) = r∞ · |1 − S/d| pixels (the circle of confusion of a lens far longer than its focal length;
  r∞ = ``radius_width_share`` x the image width, the radius of a point at infinity). Depth 0 (nothing hit) or
  not finite is infinity; r is capped at :data:`MAX_DEFOCUS_FACTOR` x r∞ (a point nearer than S/5 blurs as one at
  S/5). Each pixel takes the image blurred by a uniform disc of its own r, interpolated linearly between discs of
  radii in steps of r_max / :data:`DEFOCUS_LEVELS` (at least 0.25 px). A gather blur, a cheap approximation: each
  pixel averages its neighbours within its own disc whatever their depth, so a blurred object in front of a sharp
  background does not spread over it, and a blurred background gathers a little of a sharp object in front of it.
* **motion blur**: the image convolved with a line of ``length_width_share`` x the width pixels, centred, at
  ``angle_deg`` from +x towards +y (down): the camera moving straight at constant speed during the exposure.
* **vignetting**: each pixel scaled by the cos⁴ law, g(ρ) = (1 + kρ²)⁻², ρ the distance of the pixel's centre
  from the image's centre over the half-diagonal; k = (1 − c)^(−1/2) − 1 so that g(1) = 1 − c, c the
  ``corner_loss``.
* **exposure**: every value times 2^``ev``.
* **noise**: each value x becomes g · Poisson(x / g) + N(0, σ²), per pixel and channel (shot noise of a sensor
  with gain g = ``shot_gain`` per photo-electron, then read noise σ = ``read_sigma``; mean x, variance g·x + σ²),
  from a generator seeded by the draw's ``seed``.
* **white balance**: red times ``red_gain``, blue times ``blue_gain``.
* **JPEG**: the 8-bit image encoded by Pillow at ``quality`` with 4:2:0 chroma subsampling (what cameras and phones
  write) and decoded again.

Borders: blurs replicate the outermost pixels. The same draw on the same image gives the same bytes.
"""

from __future__ import annotations

import io
import math

import numpy as np

from synthua_usd.model.srgb import decode_srgb8, encode_srgb8
from synthua_usd.randomisation.effects import EffectsDraw

#: A point nearer than S / (1 + this) blurs as one at that depth: bounds the disc (and the gather blur's error).
MAX_DEFOCUS_FACTOR = 4.0
#: Most blurred copies a defocus interpolates between (besides the sharp image).
DEFOCUS_LEVELS = 8
#: Finest step between the radii of those copies, pixels.
DEFOCUS_STEP_PX = 0.25
#: Samples per pixel side when a disc kernel's pixel weights are measured by area.
_SUPERSAMPLE = 16
#: JPEG chroma subsampling (Pillow's 2: 4:2:0).
JPEG_SUBSAMPLING = 2


def disc_kernel(radius_px: float) -> np.ndarray:
    """(n, n) float64 weights, n odd, summing to 1: the share of each pixel covered by a disc of ``radius_px``
    centred on the middle pixel's centre (each pixel's area sampled at 16 x 16 points). A disc too small to reach a
    sample beyond the middle pixel is the identity, [[1.0]]."""
    half = int(math.floor(max(radius_px, 0.0) + 0.5))   # pixel half + 1's nearest samples lie beyond the disc
    offsets = (np.arange(_SUPERSAMPLE) + 0.5) / _SUPERSAMPLE - 0.5
    axis = (np.arange(-half, half + 1)[:, None] + offsets[None, :]).ravel()    # sample coordinates
    inside = (axis[:, None] ** 2 + axis[None, :] ** 2) <= radius_px ** 2
    n = 2 * half + 1
    kernel = inside.reshape(n, _SUPERSAMPLE, n, _SUPERSAMPLE).sum(axis=(1, 3)).astype(np.float64)
    if kernel.sum() == 0:
        kernel[half, half] = 1.0
    return kernel / kernel.sum()


def line_kernel(length_px: float, angle_deg: float) -> np.ndarray:
    """(n, n) float64 weights, n odd, summing to 1: a segment of ``length_px`` centred on the middle pixel's
    centre, at ``angle_deg`` from +x towards +y (rows down), sampled at 16 points a pixel of its length and each
    point shared bilinearly among the four pixels around it. Length 0 is the identity."""
    length = max(float(length_px), 0.0)
    half = int(math.ceil(length / 2)) + 1
    n = 2 * half + 1
    kernel = np.zeros((n, n), np.float64)
    count = max(2, int(math.ceil(length * 16)))
    t = ((np.arange(count) + 0.5) / count - 0.5) * length
    angle = math.radians(angle_deg)
    x, y = half + t * math.cos(angle), half + t * math.sin(angle)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = x - x0, y - y0
    for dx, dy, w in ((0, 0, (1 - fx) * (1 - fy)), (1, 0, fx * (1 - fy)), (0, 1, (1 - fx) * fy), (1, 1, fx * fy)):
        np.add.at(kernel, (y0 + dy, x0 + dx), w)
    return kernel / kernel.sum()


class _Spectrum:
    """The 2-D FFT of an (H, W, C) float64 image, its border replicated ``half`` pixels deep (then to sizes the FFT
    is fast at): convolving with any odd kernel of at most (2 half + 1)² is then one product and one inverse FFT.
    The circular convolution of the padded image equals the linear one on the image's own pixels, which never reach
    across the padding's far side."""

    def __init__(self, image: np.ndarray, half: int) -> None:
        from scipy import fft

        self.height, self.width = image.shape[:2]
        self.half = half
        padded = np.pad(image, ((half, half), (half, half), (0, 0)), mode="edge")
        self.shape = tuple(fft.next_fast_len(n, real=True) for n in padded.shape[:2])
        self.spectrum = fft.rfft2(padded, s=self.shape, axes=(0, 1))

    def convolved(self, kernel: np.ndarray) -> np.ndarray:
        """The image convolved with ``kernel`` ((n, n), n odd, n <= 2 half + 1), clipped at 0 (the FFTs' rounding
        leaves values of about -1e-17 where the image is black)."""
        from scipy import fft

        r = kernel.shape[0] // 2
        placed = np.zeros(self.shape, np.float64)
        rows, cols = np.arange(-r, r + 1) % self.shape[0], np.arange(-r, r + 1) % self.shape[1]
        placed[np.ix_(rows, cols)] = kernel                     # the kernel's centre at the origin
        product = self.spectrum * fft.rfft2(placed)[..., None]
        out = fft.irfft2(product, s=self.shape, axes=(0, 1))
        h = self.half
        return np.maximum(out[h:h + self.height, h:h + self.width], 0.0)


def convolve(image: np.ndarray, kernel: np.ndarray) -> np.ndarray:
    """(H, W, C) float64 ``image`` convolved with the odd-sized (n, n) ``kernel``, the border replicated; the
    same shape. Through FFTs (scipy.fft), clipped at 0."""
    if kernel.shape == (1, 1):
        return image * kernel[0, 0]
    return _Spectrum(image, kernel.shape[0] // 2).convolved(kernel)


def defocus_radii(depth_m: np.ndarray, focus_m: float, radius_inf_px: float) -> np.ndarray:
    """(H, W) float64 radii in pixels of the circles of confusion of ``depth_m`` (z-depth, metres; 0 or not finite:
    infinity) for a lens focused at ``focus_m`` whose disc at infinity has ``radius_inf_px``."""
    d = np.asarray(depth_m, np.float64)
    far = ~np.isfinite(d) | (d <= 0)
    ratio = np.where(far, 0.0, focus_m / np.where(far, 1.0, d))
    return radius_inf_px * np.minimum(np.abs(1.0 - ratio), MAX_DEFOCUS_FACTOR)


def defocus(image: np.ndarray, radii_px: np.ndarray) -> np.ndarray:
    """(H, W, C) float64 ``image`` with each pixel blurred by a disc of its radius in ``radii_px`` (H, W): the image
    blurred at radii 0, s, 2s, ... (s = max(r_max / DEFOCUS_LEVELS, DEFOCUS_STEP_PX)), each pixel interpolated
    linearly between the two radii around its own."""
    top = float(radii_px.max()) if radii_px.size else 0.0
    if top <= 0:
        return image
    step = max(top / DEFOCUS_LEVELS, DEFOCUS_STEP_PX)
    position = radii_px / step
    lower = np.floor(position).astype(int)
    above = position - lower
    levels = int(lower.max()) + 2
    kernels = [disc_kernel(level * step) for level in range(levels)]
    spectrum = _Spectrum(image, max(k.shape[0] for k in kernels) // 2)
    out = np.zeros_like(image)
    for level, kernel in enumerate(kernels):
        weight = np.where(lower == level, 1.0 - above, 0.0) + np.where(lower + 1 == level, above, 0.0)
        if weight.any():
            blurred = image if kernel.shape == (1, 1) else spectrum.convolved(kernel)
            out += weight[..., None] * blurred
    return out


def vignetting_gain(height: int, width: int, corner_loss: float) -> np.ndarray:
    """(H, W) float64 gains of the cos⁴ law, 1 at the centre and 1 - ``corner_loss`` at ρ = 1 (the corners)."""
    k = (1.0 - corner_loss) ** -0.5 - 1.0
    y = (np.arange(height) + 0.5 - height / 2)[:, None]
    x = (np.arange(width) + 0.5 - width / 2)[None, :]
    rho2 = (x ** 2 + y ** 2) / ((width / 2) ** 2 + (height / 2) ** 2)
    return (1.0 + k * rho2) ** -2


def add_noise(linear: np.ndarray, shot_gain: float, read_sigma: float, seed: int) -> np.ndarray:
    """``linear`` values x -> g · Poisson(x / g) + N(0, σ²) (g = ``shot_gain``, σ = ``read_sigma``; g = 0 leaves
    shot noise out), from ``numpy.random.default_rng(seed)``: Poisson counts first, then the Gaussian field."""
    rng = np.random.default_rng(int(seed))
    x = np.maximum(linear, 0.0)
    out = rng.poisson(x / shot_gain) * shot_gain if shot_gain > 0 else x.copy()
    if read_sigma > 0:
        out = out + rng.normal(0.0, read_sigma, size=x.shape)
    return out


def jpeg_round_trip(rgb8: np.ndarray, quality: int) -> np.ndarray:
    """(H, W, 3) uint8 encoded as JPEG by Pillow at ``quality`` (4:2:0) and decoded again."""
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb8), "RGB").save(buffer, "JPEG", quality=int(quality),
                                                            subsampling=JPEG_SUBSAMPLING)
    buffer.seek(0)
    with Image.open(buffer) as decoded:
        return np.asarray(decoded.convert("RGB"), np.uint8).copy()


def apply_effects(rgb_uint8: np.ndarray, draw: EffectsDraw, depth: np.ndarray | None = None) -> np.ndarray:
    """(H, W, 3) uint8 sRGB with the effects of ``draw`` applied (see the module's docstring); ``depth`` (H, W)
    z-depth in metres (0: nothing hit) is needed by defocus only. A draw without effects returns the image as
    given; ``ValueError`` for a defocus without a depth of the image's size."""
    rgb8 = np.asarray(rgb_uint8)
    if rgb8.dtype != np.uint8 or rgb8.ndim != 3 or rgb8.shape[2] != 3:
        raise ValueError(f"rgb_uint8: {rgb8.dtype} {rgb8.shape}; expected (H, W, 3) uint8")
    height, width = rgb8.shape[:2]
    linear_effects = [name for name in draw.applied if name != "jpeg"]
    if linear_effects:
        x = decode_srgb8(rgb8)
        if draw.defocus is not None:
            if depth is None or np.shape(depth) != (height, width):
                raise ValueError(f"depth: {None if depth is None else np.shape(depth)}; defocus needs a z-depth map "
                                 f"of the image's size ({height}, {width})")
            radii = defocus_radii(depth, draw.defocus.focus_m, draw.defocus.radius_width_share * width)
            x = defocus(x, radii)
        if draw.motion_blur is not None:
            x = convolve(x, line_kernel(draw.motion_blur.length_width_share * width, draw.motion_blur.angle_deg))
        if draw.vignetting is not None:
            x = x * vignetting_gain(height, width, draw.vignetting.corner_loss)[..., None]
        if draw.exposure is not None:
            x = x * 2.0 ** draw.exposure.ev
        if draw.noise is not None:
            x = add_noise(x, draw.noise.shot_gain, draw.noise.read_sigma, draw.noise.seed)
        if draw.white_balance is not None:
            x = x * np.array([draw.white_balance.red_gain, 1.0, draw.white_balance.blue_gain])
        rgb8 = encode_srgb8(x)
    if draw.jpeg is not None:
        rgb8 = jpeg_round_trip(rgb8, draw.jpeg.quality)
    return rgb8
