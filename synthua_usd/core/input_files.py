"""Opening the files a user names, so that no input can hang synthua or exhaust its memory.

Only regular files are read: a FIFO blocks forever on open, ``/dev/zero`` never ends, a folder is no
document. Each kind of input has a stated size limit, checked before a byte is read; text must be UTF-8
(a byte-order mark is allowed). Every refusal names the file and says what was expected.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from synthua_usd.core.errors import InputError, escape_controls

MiB = 2**20
#: JSON documents (class maps, rules, CityJSON, GeoJSON) and CSV tables: far above any class map or rules
#: file, and above a city district's CityJSON (Delft's sample is 1.4 MiB); bigger models are tiled.
MAX_DOCUMENT_BYTES = 64 * MiB

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


#: Longest path shown in a message; a longer one keeps its end (the file name) and loses its middle.
PATH_SHOWN = 200


def shown(path: str | Path) -> str:
    """``path`` as a message shows it: control characters escaped, a very long path cut in the middle."""
    text = escape_controls(path)
    return text if len(text) <= PATH_SHOWN else f"{text[:60]}...{text[-(PATH_SHOWN - 63):]}"


def _kind(mode: int) -> str:
    for test, name in _KINDS:
        if test(mode):
            return name
    return "not a regular file"


def _size_text(size: int) -> str:
    return f"{size / MiB:.1f} MiB" if size >= MiB else f"{size} bytes"


def check_input_file(path: str | Path, max_bytes: int, what: str) -> int:
    """The size of ``path`` after checking that it is an existing regular file of at most ``max_bytes``
    (``what`` names the kind of input in the message, e.g. "a JSON document"). Nothing is opened."""
    path = Path(path)
    try:
        info = os.stat(path)  # follows links: a link to /dev/zero is a character device
    except FileNotFoundError:
        raise InputError(f"{shown(path)}: file not found; expected {what}") from None
    except NotADirectoryError:
        raise InputError(f"{shown(path)}: a parent of it is a file; expected {what}") from None
    except OSError as exc:
        raise InputError(f"{shown(path)}: cannot be read ({(exc.strerror or type(exc).__name__).lower()}); "
                         f"expected {what}") from None
    if not stat.S_ISREG(info.st_mode):
        raise InputError(f"{shown(path)}: is {_kind(info.st_mode)}; expected a regular file ({what})")
    if info.st_size > max_bytes:
        raise InputError(f"{shown(path)}: {_size_text(info.st_size)}; expected {what} of at most "
                         f"{max_bytes / MiB:g} MiB")
    return info.st_size


def read_input_bytes(path: str | Path, max_bytes: int, what: str) -> bytes:
    """The bytes of a regular file of at most ``max_bytes``. The file is opened without blocking and
    checked again once open, so a file swapped for a FIFO after the first check cannot hang the read."""
    path = Path(path)
    check_input_file(path, max_bytes, what)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise InputError(f"{shown(path)}: cannot be read ({(exc.strerror or type(exc).__name__).lower()}); "
                         f"expected {what}") from None
    with os.fdopen(fd, "rb") as fh:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise InputError(f"{shown(path)}: is {_kind(os.fstat(fd).st_mode)}; expected a regular file ({what})")
        data = fh.read(max_bytes + 1)
    if len(data) > max_bytes:  # it grew since the check
        raise InputError(f"{shown(path)}: more than {max_bytes / MiB:g} MiB; expected {what} of at most "
                         f"{max_bytes / MiB:g} MiB")
    return data


def read_input_text(path: str | Path, max_bytes: int, what: str) -> str:
    """The UTF-8 text of a regular file of at most ``max_bytes`` (a leading byte-order mark is dropped)."""
    data = read_input_bytes(path, max_bytes, what)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise InputError(f"{shown(path)}: byte 0x{data[exc.start]:02x} at offset {exc.start} (line {line}) is not "
                         f"UTF-8; expected {what} in UTF-8") from None
