"""Photos read as backgrounds: cut to the output size at their centre (pixels compared with the photo's own), EXIF
read (35 mm focal length, orientation), and what cannot serve refused in one line."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest
from PIL import Image
from PIL.ExifTags import IFD

from synthua_usd.backends.photos import cover_region, photo_header, read_photo
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
