"""Texture image files as a stage names them once OpenUSD has resolved them: a file, or a member of a USDZ
package.

OpenUSD's asset resolver (Ar) resolves a texture packed inside a ``.usdz`` to a package-relative path,
``/assets/car.usdz[textures/body.png]`` (nested packages: ``a.usdz[b.usdz[c.png]]``). A USDZ package is a
zip archive whose members are stored uncompressed (the USDZ specification), so a member is read with
:mod:`zipfile`. OpenImageIO opens files only: a member is decoded from a temporary copy that keeps its
suffix (OpenImageIO picks the format by it) and is deleted afterwards. :func:`open_image` is the one way
texture images are opened, by the stage reader to check them (:func:`unreadable`) and by the backends to
decode them.
"""

from __future__ import annotations

import contextlib
import io
import tempfile
import zipfile
from pathlib import Path, PurePosixPath
from typing import Iterator

#: The largest packaged texture copied out (bytes): 8192 x 8192 RGBA at 32 bits per channel, uncompressed.
MAX_MEMBER_BYTES = 1 << 30
#: The largest texture read: decoded to float RGBA it takes 1 GiB.
MAX_TEXELS = 8192 * 8192


class TextureFileError(Exception):
    """A texture image that cannot be opened; the message says why (no path: callers name it)."""


def is_packaged(path: str) -> bool:
    """Whether ``path`` is package-relative (``pkg.usdz[member]``)."""
    return path.endswith("]") and "[" in path


def split_packaged(path: str) -> tuple[str, str]:
    """(package, member) of a package-relative path: the outermost package file and the path inside it
    (itself package-relative for nested packages), as ``Ar.SplitPackageRelativePathOuter`` splits it."""
    start = path.index("[")
    return path[:start], path[start + 1:-1]


def _member_bytes(archive: zipfile.ZipFile, member: str, shown: str) -> bytes:
    try:
        info = archive.getinfo(member)
    except KeyError:
        raise TextureFileError(f"the package has no member '{member}' (it holds {len(archive.namelist())} files)") \
            from None
    if info.file_size > MAX_MEMBER_BYTES:
        raise TextureFileError(f"{info.file_size} bytes; expected at most {MAX_MEMBER_BYTES} in {shown}")
    return archive.read(info)


def packaged_bytes(path: str) -> bytes:
    """The bytes of the member a package-relative ``path`` names (nested packages opened in turn)."""
    package, member = split_packaged(path)
    try:
        archive = zipfile.ZipFile(package)
    except (OSError, zipfile.BadZipFile) as exc:
        raise TextureFileError(f"the package {package} cannot be read as a zip archive ({exc})") from None
    with archive:
        while is_packaged(member):
            inner, member = split_packaged(member)
            nested = _member_bytes(archive, inner, package)
            archive.close()
            try:
                archive = zipfile.ZipFile(io.BytesIO(nested))
            except zipfile.BadZipFile as exc:
                raise TextureFileError(f"the nested package {inner} is not a zip archive ({exc})") from None
        return _member_bytes(archive, member, package)


@contextlib.contextmanager
def local_file(path: str) -> Iterator[str]:
    """A filesystem path holding the image ``path`` names: ``path`` itself, or a temporary copy of a packaged
    member (deleted on exit). Raises :class:`TextureFileError`."""
    if not is_packaged(path):
        yield path
        return
    data = packaged_bytes(path)
    with tempfile.TemporaryDirectory(prefix="synthua-texture-") as folder:
        copy = Path(folder) / ("texture" + PurePosixPath(split_packaged(path)[1].rsplit("[", 1)[-1]).suffix)
        copy.write_bytes(data)
        yield str(copy)


@contextlib.contextmanager
def open_image(path: str):
    """An open ``OpenImageIO.ImageInput`` of the texture image ``path`` (a file or a packaged member), closed
    on exit. Raises :class:`TextureFileError` with OpenImageIO's reason when it cannot be opened."""
    import OpenImageIO as oiio

    with local_file(path) as file:
        image = oiio.ImageInput.open(file)
        if image is None:
            reason = oiio.geterror() or "OpenImageIO cannot open it"
            raise TextureFileError(reason.replace(file, PurePosixPath(path).name) if file != path else reason)
        try:
            yield image
        finally:
            image.close()


def unreadable(path: str, max_texels: int = MAX_TEXELS) -> str | None:
    """Why the texture image ``path`` cannot be used (missing, not an image OpenImageIO opens, more than
    ``max_texels`` pixels or no channel), or None when its header reads. Only the header is read."""
    if not is_packaged(path):
        if not Path(path).exists():
            return "not found"
        if not Path(path).is_file():  # a FIFO or a device would block or never end
            return "not a regular file"
    try:
        with open_image(path) as image:
            spec = image.spec()
            if spec.width * spec.height > max_texels or spec.nchannels < 1:
                return (f"{spec.width}x{spec.height} pixels, {spec.nchannels} channels; expected at most "
                        f"{max_texels} pixels and a channel")
    except TextureFileError as exc:
        return str(exc)
    return None
