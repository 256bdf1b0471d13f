"""Texture files inside USDZ packages (zip archives, members stored), nested ones included."""

import io
import zipfile

import pytest

from synthua_usd.core.texture_files import TextureFileError, packaged_bytes, split_packaged, unreadable


def _zip(members: dict) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_STORED) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return buffer.getvalue()


def test_members_of_packages_and_nested_packages(tmp_path):
    package = tmp_path / "car.usdz"
    package.write_bytes(_zip({"car.usdc": b"usd", "tex/body.png": b"png bytes",
                              "wheel.usdz": _zip({"rim.png": b"rim bytes"})}))
    assert split_packaged(f"{package}[wheel.usdz[rim.png]]") == (str(package), "wheel.usdz[rim.png]")
    assert packaged_bytes(f"{package}[tex/body.png]") == b"png bytes"
    assert packaged_bytes(f"{package}[wheel.usdz[rim.png]]") == b"rim bytes"
    with pytest.raises(TextureFileError, match="the package has no member 'tex/roof.png'"):
        packaged_bytes(f"{package}[tex/roof.png]")
    assert unreadable(f"{package}[tex/body.png]") == "Not a PNG file"  # OpenImageIO's reason, on the copy
    assert unreadable(str(tmp_path / "gone.png")) == "not found"
