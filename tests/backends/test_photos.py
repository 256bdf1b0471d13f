"""Photos read as backgrounds: cut to the output size at their centre (pixels compared with the photo's own), EXIF
read (35 mm focal length, orientation), and what cannot serve refused in one line."""

from __future__ import annotations

import hashlib
import struct

import numpy as np
import pytest
from PIL import Image
from PIL.ExifTags import IFD
from PIL.TiffImagePlugin import IFDRational

from synthua_usd.backends.photos import cover_region, is_monochrome, photo_header, read_photo, to_monochrome
from synthua_usd.core.errors import InputError


def _save(path, pixels, orientation=None, focal_35mm=None, **kwargs):
    image = Image.fromarray(pixels)
    exif = image.getexif()
    if orientation is not None:
        exif[0x0112] = orientation
    if focal_35mm is not None:
        exif.get_ifd(IFD.Exif)[41989] = focal_35mm
    image.save(path, exif=exif.tobytes(), **kwargs)
    return path


@pytest.fixture
def pixels():
    return np.random.default_rng(0).integers(0, 256, (40, 60, 3), dtype=np.uint8)


def test_a_photo_is_cut_at_its_centre_without_scaling_when_it_can(tmp_path, pixels):
    path = _save(tmp_path / "a.png", pixels)
    photo = read_photo(path, (60, 30))
    assert photo.region == (0.0, 5.0, 60.0, 35.0) and photo.scale == 1.0
    np.testing.assert_array_equal(photo.pixels, pixels[5:35])
    assert photo.sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    np.testing.assert_array_equal(read_photo(path, None).pixels, pixels)


def test_a_larger_photo_is_scaled_down_to_cover_the_output(tmp_path, pixels):
    path = _save(tmp_path / "a.png", pixels)
    photo = read_photo(path, (30, 16))
    assert photo.scale == pytest.approx(0.5) and photo.pixels.shape == (16, 30, 3)
    assert photo.region == pytest.approx((0.0, 4.0, 60.0, 36.0))
    expected = np.asarray(Image.fromarray(pixels).resize((30, 16), Image.Resampling.LANCZOS, box=(0, 4, 60, 36)))
    np.testing.assert_array_equal(photo.pixels, expected)


def test_exif_focal_length_and_orientation(tmp_path, pixels):
    path = _save(tmp_path / "a.jpg", pixels, orientation=6, focal_35mm=28, quality=95)
    header = photo_header(path)
    assert (header.width, header.height, header.focal_35mm, header.orientation) == (40, 60, 28.0, 6)
    photo = read_photo(path, None)
    assert photo.pixels.shape == (60, 40, 3)          # turned upright: a quarter turn clockwise
    stored = np.asarray(Image.open(path).convert("RGB"))
    np.testing.assert_array_equal(photo.pixels, np.rot90(stored, k=-1))
    assert photo_header(_save(tmp_path / "b.png", pixels)).focal_35mm is None


def test_cover_region_refuses_a_photo_smaller_than_the_output(tmp_path):
    with pytest.raises(InputError, match=r"x\.jpg: 60x40 pixels; expected at least the output size 64x48"):
        cover_region((60, 40), (64, 48), tmp_path / "x.jpg")


def test_truncated_unreadable_and_heic_photos_are_refused(tmp_path, pixels):
    path = _save(tmp_path / "a.jpg", pixels, quality=90)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match=r"a\.jpg: truncated or damaged"):
        read_photo(path, None)
    (tmp_path / "b.png").write_bytes(b"not a picture at all")
    with pytest.raises(InputError, match=r"b\.png: not an image Pillow can read"):
        photo_header(tmp_path / "b.png")
    (tmp_path / "c.heic").write_bytes(b"\0\0\0\x18ftypheic")
    try:
        import pillow_heif  # noqa: F401
    except ImportError:
        with pytest.raises(InputError, match=r"c\.heic: a HEIC image, and no HEIC decoder is installed"):
            photo_header(tmp_path / "c.heic")


def test_a_16_bit_photo_is_scaled_to_8_bits_and_floating_point_pixels_are_refused(tmp_path):
    grey = np.random.default_rng(1).integers(0, 65536, (40, 60), dtype=np.uint16)
    path = tmp_path / "deep.png"
    Image.fromarray(grey).save(path)                              # a 16-bit grey PNG (was clipped to white)
    assert Image.open(path).mode in ("I;16", "I")
    expected = np.floor(grey.astype(np.float64) / 257.0 + 0.5)    # rounded half up: x / 257 is never a half
    np.testing.assert_array_equal(read_photo(path, None).pixels, np.repeat(expected[..., None], 3, axis=2))
    Image.fromarray(grey.astype(np.float32) / 65535.0).save(tmp_path / "float.tif")
    with pytest.raises(InputError, match=r"float\.tif: floating-point pixels; expected an 8- or 16-bit photo"):
        read_photo(tmp_path / "float.tif", None)
    Image.fromarray((grey // 257).astype(np.int32)).save(tmp_path / "int32.tif")       # 0..255 or 0..65535? unsaid
    with pytest.raises(InputError, match=r"int32\.tif: 32-bit integer pixels; expected an 8- or 16-bit photo"):
        read_photo(tmp_path / "int32.tif", None)


def test_a_damaged_png_is_named_when_its_header_is_read(tmp_path, pixels):
    """A PNG's EXIF may follow its pixels, so reading its header decodes them: damage is the photo's, one line."""
    path = tmp_path / "cut.png"
    Image.fromarray(pixels).save(path)
    path.write_bytes(path.read_bytes()[:len(path.read_bytes()) // 2])
    with pytest.raises(InputError, match=r"cut\.png: truncated or damaged .*; expected a complete image"):
        photo_header(path)


def _exif_with(tag: int, kind: int, count: int, data: bytes) -> bytes:
    """EXIF (APP1 payload) of one IFD0 entry written as given, type and all: what Pillow's writer would not make."""
    inline = len(data) <= 4
    entry = struct.pack("<HHI", tag, kind, count) + (data.ljust(4, b"\0") if inline else struct.pack("<I", 26))
    return b"Exif\0\0" + b"II*\0" + struct.pack("<IH", 8, 1) + entry + struct.pack("<I", 0) + (b"" if inline else data)


@pytest.mark.parametrize("kind, count, data", [(2, 4, b"abc\0"),                       # text
                                               (5, 1, struct.pack("<II", 0, 0)),        # the rational 0/0
                                               (8, 1, struct.pack("<h", -3)),           # a signed short
                                               (3, 1, struct.pack("<H", 0)), (3, 1, struct.pack("<H", 9))])
def test_an_orientation_that_is_no_such_value_is_taken_as_upright(tmp_path, pixels, kind, count, data):
    path = tmp_path / "a.jpg"
    Image.fromarray(pixels).save(path, exif=_exif_with(0x0112, kind, count, data), quality=95)
    assert photo_header(path).orientation == 1
    assert read_photo(path, None).pixels.shape == (40, 60, 3)


@pytest.mark.parametrize("value, read", [(28, 28.0), (IFDRational(55, 2), 27.5), (8, 8.0), (3000, 3000.0),
                                         (1, None), (7, None), (65535, None), (0, None), ("28", None)])
def test_a_35mm_focal_length_outside_a_lens_range_is_taken_as_absent(tmp_path, pixels, value, read):
    """EXIF FocalLengthIn35mmFilm from a fisheye's 8 mm to a superzoom's 3,000 mm is used; 1 mm would put the
    camera model 77 degrees down, 65,535 mm (a damaged tag) kilometres away: such values are taken as absent."""
    path = _save(tmp_path / "a.jpg", pixels, focal_35mm=value, quality=95)
    assert photo_header(path).focal_35mm == read


@pytest.mark.parametrize("suffix", [".png", ".jpg", ".tif"])
@pytest.mark.parametrize("output", [None, (30, 16)])
def test_photos_above_pillows_bomb_guard_are_read_up_to_the_stated_limit(tmp_path, pixels, monkeypatch, suffix,
                                                                         output):
    """Pillow refuses images above twice its MAX_IMAGE_PIXELS (about 179 MP, below a 200 MP phone's photo) and warns
    above it, at opening and (TIFF) again while decoding; photos are held to MAX_PHOTO_PIXELS instead, and Pillow's
    setting is left as it was, after a refusal too."""
    import warnings

    from synthua_usd.backends import photos

    path = _save(tmp_path / f"a{suffix}", pixels)
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", 100)          # 2,400 pixels: a "bomb" to Pillow
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert read_photo(path, output).pixels.shape == ((40, 60, 3) if output is None else (16, 30, 3))
    assert Image.MAX_IMAGE_PIXELS == 100
    monkeypatch.setattr(photos, "MAX_PHOTO_PIXELS", 2399)
    for read in (photo_header, lambda p: read_photo(p, output)):
        with pytest.raises(InputError, match=rf"a\{suffix}: 60x40 pixels \(0 megapixels\); expected a photo of at "
                                             rf"most 0 megapixels"):
            read(path)
        assert Image.MAX_IMAGE_PIXELS == 100


def test_grey_photos_are_monochrome_and_colour_ones_are_not(tmp_path, pixels):
    grey = pixels[..., 1]
    Image.fromarray(grey).save(tmp_path / "l.jpg", quality=90)                                  # a greyscale JPEG
    Image.fromarray(grey).save(tmp_path / "l.png")
    Image.fromarray(np.repeat(grey[..., None], 3, axis=2)).save(tmp_path / "rgb.jpg", quality=75)  # grey, stored RGB
    for name in ("l.jpg", "l.png", "rgb.jpg"):
        assert read_photo(tmp_path / name, None).monochrome, name
    assert not read_photo(_save(tmp_path / "c.png", pixels), None).monochrome
    # 1,000 grey pixels: ten coloured ones (a time stamp) are still grey, eleven are not; two levels apart is grey
    tinted = np.full((40, 25, 3), 120, np.uint8)
    tinted[0, :10] = (200, 120, 120)
    assert is_monochrome(tinted)
    tinted[1, 0] = (120, 120, 160)
    assert not is_monochrome(tinted)
    tinted[1, 0] = (121, 120, 119)
    assert is_monochrome(tinted)


def test_to_monochrome_keeps_grey_pixels_and_gives_pillows_luma_to_colour_ones(pixels):
    grey = np.repeat(pixels[..., :1], 3, axis=2)
    np.testing.assert_array_equal(to_monochrome(grey), grey)
    made = to_monochrome(pixels)
    assert np.array_equal(made[..., 0], made[..., 1]) and np.array_equal(made[..., 1], made[..., 2])
    pillow = np.asarray(Image.fromarray(pixels).convert("L")).astype(int)      # Pillow's fixed-point Rec. 601
    assert np.abs(made[..., 0].astype(int) - pillow).max() <= 1
