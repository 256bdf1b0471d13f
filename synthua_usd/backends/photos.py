"""Photos read as backgrounds: their header (size, EXIF focal length, orientation) and their pixels cut to the
written size, through Pillow (which reads EXIF, and HEIC when its plugin pillow-heif is installed).

The written image *covers* the output size: the photo is scaled by ``max(W / w, H / h)`` (never above 1: a photo
smaller than the output is refused) and its centre cut out, ``region`` in photo pixels. A photo with an EXIF
orientation other than 1 is turned upright first (as viewers and Ultralytics' loader do); its size and boxes are
then the upright photo's. Colours are taken as 8-bit sRGB (an embedded ICC profile is not applied); a 16-bit photo
is scaled to 8 bits (x / 257), one of 32-bit integer or floating-point pixels refused. An EXIF orientation or 35 mm
focal length that is no such value (damaged, out of range) is taken as absent. A photo whose shown pixels are grey
(:func:`is_monochrome`: a greyscale file, a night CCTV frame, a grey JPEG stored as RGB) is *monochrome*: a composite
into it is made grey after its camera effects (:func:`to_monochrome`), since colour pastes in a grey photo are a
difference a detector can learn. Photos of up to
:data:`MAX_PHOTO_PIXELS` are read (Pillow's own guard against decompression bombs stops at about 179 megapixels,
below a 200-megapixel phone's).
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import math
import numbers
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image, ImageOps, UnidentifiedImageError
from PIL.ExifTags import Base, IFD

from synthua_usd.core.errors import InputError
from synthua_usd.core.input_files import shown

#: Suffixes of HEIC/HEIF photos (phones' default), read only with pillow-heif installed.
HEIC_SUFFIXES = (".heic", ".heif")
#: Pillow's orientation tag.
_ORIENTATION = 0x0112
#: The most pixels a photo may have: a 200-megapixel phone's 16320 x 12240 with room to spare.
MAX_PHOTO_PIXELS = 250_000_000
#: A photo is monochrome where its channels differ by more than this many 8-bit levels in at most
#: :data:`MONOCHROME_SHARE` of its shown pixels (JPEG's rounding moves a grey photo's channels by a level or two; a
#: camera's coloured time stamp may lie over a grey frame; a colour photo's sensor noise alone moves most pixels more).
MONOCHROME_CHROMA = 2
MONOCHROME_SHARE = 0.01
#: Rec. 601 luma weights, JPEG's Y and Pillow's "L": a monochrome composite's grey.
_LUMA = np.array([0.299, 0.587, 0.114])
#: EXIF 35 mm equivalent focal lengths taken as stated (mm), a fisheye's to a superzoom's; others are taken as absent.
FOCAL_35MM_RANGE = (8.0, 3000.0)


def heic_decoder() -> bool:
    """Whether a HEIC decoder (pillow-heif) is installed; registers it with Pillow when it is."""
    try:
        import pillow_heif  # noqa: PLC0415 - optional
    except ImportError:
        return False
    pillow_heif.register_heif_opener()
    return True


#: Pillow's guard against decompression bombs is a global: photos move it under this lock.
_PILLOW_GUARD = threading.Lock()


@contextlib.contextmanager
def _opened(path: Path, data: bytes | None = None) -> Iterator[Image.Image]:
    """The photo at ``path`` (its bytes ``data`` where read) open, and held to :data:`MAX_PHOTO_PIXELS` instead of
    Pillow's guard (about 179 megapixels, checked again by its TIFF reader while decoding) until it is closed."""
    path = Path(path)
    if path.suffix.lower() in HEIC_SUFFIXES and not heic_decoder():
        raise InputError(f"{shown(path)}: a HEIC image, and no HEIC decoder is installed; expected a JPEG, PNG, TIFF, "
                         f"BMP or WebP photo, or `pip install pillow-heif` to read HEIC")
    with _PILLOW_GUARD:
        limit, Image.MAX_IMAGE_PIXELS = Image.MAX_IMAGE_PIXELS, None
        try:
            try:
                image = Image.open(io.BytesIO(data) if data is not None else path)
            except (UnidentifiedImageError, OSError, ValueError, SyntaxError) as exc:
                raise InputError(f"{shown(path)}: not an image Pillow can read ({type(exc).__name__}); expected a "
                                 f"photo (JPEG, PNG, TIFF, BMP, WebP)") from None
            with image:
                width, height = image.size
                if width * height > MAX_PHOTO_PIXELS:
                    raise InputError(f"{shown(path)}: {width}x{height} pixels ({width * height / 1e6:.0f} megapixels); "
                                     f"expected a photo of at most {MAX_PHOTO_PIXELS / 1e6:.0f} megapixels")
                yield image
        finally:
            Image.MAX_IMAGE_PIXELS = limit


def _damaged(path: Path, exc: Exception) -> InputError:
    return InputError(f"{shown(path)}: truncated or damaged ({str(exc)[:60]}); expected a complete image")


@dataclass(frozen=True)
class PhotoHeader:
    """A photo's upright size (pixels), its EXIF FocalLengthIn35mmFilm (mm; None when absent or 0) and EXIF
    orientation (1: stored upright)."""

    width: int
    height: int
    focal_35mm: float | None
    orientation: int


def _number(value) -> float | None:
    """An EXIF value as a finite number (an int, float or rational; a rational 0/0, text or a tuple: None)."""
    if not isinstance(value, numbers.Real):
        return None
    try:
        number = float(value)
    except (ValueError, OverflowError, ZeroDivisionError):
        return None
    return number if math.isfinite(number) else None


def _header(path: Path, image: Image.Image) -> PhotoHeader:
    try:    # a PNG's EXIF may follow its pixels: reading it decodes them
        exif = image.getexif()
        orientation, focal = _number(exif.get(_ORIENTATION)), _number(exif.get_ifd(IFD.Exif).get(
            Base.FocalLengthIn35mmFilm))
    except (OSError, ValueError, SyntaxError) as exc:
        raise _damaged(path, exc) from None
    orientation = int(orientation) if orientation is not None and orientation in range(1, 9) else 1
    width, height = image.size
    if orientation in (5, 6, 7, 8):  # turned a quarter: the upright photo's sides swap
        width, height = height, width
    focal = focal if focal is not None and FOCAL_35MM_RANGE[0] <= focal <= FOCAL_35MM_RANGE[1] else None
    return PhotoHeader(width, height, focal, orientation)


def photo_header(path: str | Path) -> PhotoHeader:
    """The header of the photo at ``path`` (no pixels decoded where the format allows)."""
    path = Path(path)
    with _opened(path) as image:
        return _header(path, image)


def _rgb(path: Path, image: Image.Image) -> Image.Image:
    """8-bit RGB of a decoded photo: 16-bit grey scaled (x / 257, rounded: never a half), 32-bit integer and
    floating-point pixels refused (their range is the writer's choice)."""
    if image.mode.startswith("I;16"):
        values = np.asarray(image).astype(np.uint32)
        return Image.fromarray(((values + 128) // 257).astype(np.uint8), "L").convert("RGB")
    if image.mode in ("I", "F"):
        kind = "32-bit integer" if image.mode == "I" else "floating-point"
        raise InputError(f"{shown(path)}: {kind} pixels; expected an 8- or 16-bit photo")
    return image.convert("RGB")


def cover_region(size: tuple[int, int], output: tuple[int, int] | None,
                 path: Path) -> tuple[tuple[float, float, float, float], float]:
    """The photo ``region`` (x0, y0, x1, y1, photo pixels) that covers ``output`` (W, H) at the centre, and the
    ``scale`` (written px per photo px, <= 1); ``output`` None: the whole photo at scale 1. A photo smaller than the
    output raises :class:`InputError`."""
    width, height = size
    if output is None:
        return (0.0, 0.0, float(width), float(height)), 1.0
    out_w, out_h = output
    if width < out_w or height < out_h:
        raise InputError(f"{shown(path)}: {width}x{height} pixels; expected at least the output size {out_w}x{out_h} "
                         f"(photos are scaled down, never up: set output smaller, or null for each photo's own size)")
    scale = max(out_w / width, out_h / height)
    cut_w, cut_h = out_w / scale, out_h / scale
    x0, y0 = (width - cut_w) / 2.0, (height - cut_h) / 2.0
    return (x0, y0, x0 + cut_w, y0 + cut_h), scale


def is_monochrome(pixels: np.ndarray) -> bool:
    """Whether 8-bit RGB ``pixels`` (H, W, 3) are grey: max - min over the channels above
    :data:`MONOCHROME_CHROMA` in at most :data:`MONOCHROME_SHARE` of them."""
    chroma = pixels.max(axis=2) - pixels.min(axis=2)
    return int(np.count_nonzero(chroma > MONOCHROME_CHROMA)) <= MONOCHROME_SHARE * chroma.size


def to_monochrome(rgb: np.ndarray) -> np.ndarray:
    """8-bit RGB ``rgb`` (H, W, 3) made grey: every channel its Rec. 601 luma, rounded (a grey pixel is kept)."""
    luma = np.rint(rgb.astype(np.float64) @ _LUMA).clip(0, 255).astype(np.uint8)
    return np.repeat(luma[..., None], 3, axis=2)


@dataclass(frozen=True, eq=False)
class Photo:
    """A photo read for one composite: ``pixels`` (H, W, 3) uint8 at the written size, the file's SHA-256, its
    header, the ``region`` and ``scale`` it was cut with (:func:`cover_region`), and whether the pixels shown are
    grey (:func:`is_monochrome`)."""

    pixels: np.ndarray
    sha256: str
    header: PhotoHeader
    region: tuple[float, float, float, float]
    scale: float
    monochrome: bool


def read_photo(path: str | Path, output: tuple[int, int] | None) -> Photo:
    """Read, turn upright and cut the photo at ``path`` to ``output`` (W, H; None: its own size). A truncated or
    damaged file raises :class:`InputError`."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{shown(path)}: cannot be read ({exc.strerror}); expected a readable photo") from None
    with _opened(path, data) as image:
        header = _header(path, image)
        try:
            image.load()
            upright = ImageOps.exif_transpose(image) if header.orientation != 1 else image
            rgb = _rgb(path, upright)
        except (OSError, ValueError, SyntaxError) as exc:
            raise _damaged(path, exc) from None
    region, scale = cover_region(rgb.size, output, path)
    x0, y0, x1, y1 = region
    size = output or rgb.size
    whole = all(float(v).is_integer() for v in region) and math.isclose(scale, 1.0)
    if whole:
        pixels = np.asarray(rgb, np.uint8)[int(y0):int(y1), int(x0):int(x1)]
    else:
        pixels = np.asarray(rgb.resize(size, Image.Resampling.LANCZOS, box=region), np.uint8)
    pixels = np.ascontiguousarray(pixels)
    return Photo(pixels, hashlib.sha256(data).hexdigest(), header, region, scale, is_monochrome(pixels))
