"""Image files: colour management checked against colour-science, id maps raw, atomic writes."""

import warnings

import numpy as np
import pytest

from synthua_usd.core import images


def test_display_conversion_is_the_srgb_transfer_function():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour
    lin = np.linspace(0.0, 1.0, 64 * 3, dtype=np.float32).reshape(8, 8, 3)
    expected = np.round(np.clip(colour.cctf_encoding(lin, function="sRGB"), 0, 1) * 255)
    got = images.linear_to_display(lin).astype(float)
    assert np.abs(got - expected).max() <= 1.0


def test_display_conversion_clips_highlights():
    out = images.linear_to_display(np.full((2, 2, 3), 4.0, np.float32))
    assert (out == 255).all()


def test_exr_roundtrip_is_tagged_linear(tmp_path):
    rgb = np.random.default_rng(0).random((6, 5, 3), dtype=np.float32) * 3
    images.write_linear_exr(tmp_path / "rgb.exr", rgb)
    pixels, spec = images.read_image(tmp_path / "rgb.exr")
    assert np.array_equal(pixels, rgb)
    assert spec.getattribute("oiio:ColorSpace") == "lin_rec709_scene"


@pytest.mark.parametrize("dtype,top", [(np.uint8, 255), (np.uint16, 65535)])
def test_id_png_roundtrip_is_raw(tmp_path, dtype, top):
    ids = np.random.default_rng(1).integers(0, top, (7, 9)).astype(dtype)
    images.write_id_png(tmp_path / "ids.png", ids)
    pixels, spec = images.read_image(tmp_path / "ids.png")
    assert pixels.shape == (7, 9, 1) and pixels.dtype == dtype
    assert np.array_equal(pixels[..., 0], ids)


def test_depth_exr_carries_its_definition(tmp_path):
    depth = np.arange(12, dtype=np.float32).reshape(3, 4)
    images.write_depth_exr(tmp_path / "d.exr", depth, "z-depth in metres")
    pixels, spec = images.read_image(tmp_path / "d.exr")
    assert np.array_equal(pixels[..., 0], depth)
    assert spec.channelnames == ("Z",) and spec.getattribute("synthua:depth") == "z-depth in metres"


def test_failed_write_leaves_no_file(tmp_path, monkeypatch):
    target = tmp_path / "rgb.exr"
    target.write_bytes(b"previous")

    class Broken:
        @staticmethod
        def create(path):
            return None

    monkeypatch.setattr(images.oiio, "ImageOutput", Broken)
    with pytest.raises(OSError, match="OpenImageIO could not write it"):
        images.write_linear_exr(target, np.zeros((2, 2, 3), np.float32))
    assert target.read_bytes() == b"previous"
    assert [p.name for p in tmp_path.iterdir()] == ["rgb.exr"]


def test_exr_files_depend_only_on_their_pixels(tmp_path, monkeypatch):
    """No capture date in EXR headers: the same pixels written at two moments give the same bytes."""
    import time as _time

    from synthua_usd.core import images as _images

    pixels = np.random.default_rng(0).random((6, 8, 3)).astype(np.float32)
    _images.write_linear_exr(tmp_path / "a.exr", pixels)
    _images.write_depth_exr(tmp_path / "a_z.exr", pixels[..., 0], "z")
    real = _time.time
    monkeypatch.setattr(_time, "time", lambda: real() + 86400.0)
    _time.sleep(1.05)
    _images.write_linear_exr(tmp_path / "b.exr", pixels)
    _images.write_depth_exr(tmp_path / "b_z.exr", pixels[..., 0], "z")
    assert (tmp_path / "a.exr").read_bytes() == (tmp_path / "b.exr").read_bytes()
    assert (tmp_path / "a_z.exr").read_bytes() == (tmp_path / "b_z.exr").read_bytes()


def test_a_fast_png_holds_the_same_pixels(tmp_path):
    from synthua_usd.core.images import FAST_PNG, read_image, write_color_png, write_id_png

    rgb = np.random.default_rng(3).integers(0, 256, (12, 16, 3), dtype=np.uint8)
    ids = np.random.default_rng(4).integers(0, 2**16, (12, 16), dtype=np.uint16)
    write_color_png(tmp_path / "slow.png", rgb)
    write_color_png(tmp_path / "fast.png", rgb, compression=FAST_PNG)
    write_id_png(tmp_path / "ids.png", ids, compression=FAST_PNG)
    np.testing.assert_array_equal(read_image(tmp_path / "fast.png")[0], read_image(tmp_path / "slow.png")[0])
    np.testing.assert_array_equal(read_image(tmp_path / "ids.png")[0][..., 0], ids)
