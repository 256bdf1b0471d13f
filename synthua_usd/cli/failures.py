"""The one place where failures become messages: every expected failure is one line

    synthua: error: <file, prim or field>: <what was found>; <what was expected>

with exit status 2; anything unexpected is one short line with exit status 3 (``--debug`` shows the
traceback). Warnings from libraries (Python ``warnings``, and the diagnostics OpenUSD's C++ code prints
straight to the process's stderr) are turned into one-line ``synthua: warning:`` messages, shown when the
command succeeds; when it fails the error line says what went wrong, and warnings about the same values
(numpy's "invalid value encountered" on the NaN being refused) would only come before it: they are
dropped (``--debug`` keeps them).
"""

from __future__ import annotations

import contextlib
import errno
import faulthandler
import logging
import os
import re
import sys
import tempfile
import traceback
from typing import Callable, Iterator

import click

from synthua_usd.core.errors import SynthuaError, echo, escape_controls

EXIT_OK, EXIT_FINDINGS, EXIT_INPUT, EXIT_INTERNAL = 0, 1, 2, 3

log = logging.getLogger("synthua")

def one_line(text: str) -> str:
    """``text`` with newlines and other control characters escaped, so a message stays one line."""
    return escape_controls(str(text).strip())


class OneLineFormatter(logging.Formatter):
    """``synthua: warning: message`` with the message kept on one line."""

    def format(self, record: logging.LogRecord) -> str:
        # Only synthua says "error": it prints its one error line itself. What other libraries log at error
        # level is, for the user, a warning before synthua's own verdict.
        level = record.levelname.lower()
        if level in ("error", "critical") and not record.name.startswith("synthua"):
            level = "warning"
        return f"synthua: {level}: {one_line(record.getMessage())}"


def configure_logging(verbose: int) -> None:
    """Log lines at warning level and above, info with ``-v``, debug with ``-vv``. The level is the handler's as well
    as the root logger's: a library that lowers its own logger's level (trimesh's, while synthua collects the texture
    images it could not load) still prints nothing below it."""
    level = max(logging.WARNING - 10 * verbose, logging.DEBUG)
    handler = logging.StreamHandler()
    handler.setFormatter(OneLineFormatter())
    handler.setLevel(level)
    logging.basicConfig(level=level, handlers=[handler], force=True)
    logging.captureWarnings(True)  # numpy's and others' warnings become log records, one line each


_OS_EXPECTED = {
    errno.ENOSPC: "free space on the disk",
    errno.EDQUOT: "free space within the disk quota",
    errno.EACCES: "a path the user may read or write",
    errno.EPERM: "a path the user may read or write",
    errno.EROFS: "a writable file system",
    errno.ENAMETOOLONG: "names of at most 255 bytes",
    errno.EISDIR: "a file, not a folder",
    errno.ENOTDIR: "folders on the way to it, not files",
    errno.EEXIST: "a path that does not exist yet",
    errno.ENOENT: "an existing file or folder",
    errno.EFBIG: "a file within the size limit",
    errno.ELOOP: "a path without a symbolic-link loop",
}


def describe(exc: BaseException) -> tuple[str, int]:
    """The one-line message and exit status for a failure."""
    if isinstance(exc, SynthuaError):
        return str(exc), EXIT_INPUT
    if isinstance(exc, OSError):
        where = exc.filename if exc.filename is not None else "output"
        found = exc.strerror or str(exc) or type(exc).__name__
        expected = _OS_EXPECTED.get(exc.errno, "a usable path")
        return f"{echo(where)}: {found.lower()}; expected {expected}", EXIT_INPUT
    if isinstance(exc, RecursionError):
        return "input: nested too deeply to read (recursion limit); expected a document of reasonable depth", EXIT_INPUT
    if isinstance(exc, MemoryError):
        return "input: needs more memory than this machine has; expected a smaller size or count", EXIT_INPUT
    if isinstance(exc, UnicodeDecodeError):
        return (f"input: byte 0x{exc.object[exc.start]:02x} at offset {exc.start} is not UTF-8; expected UTF-8 text",
                EXIT_INPUT)
    if isinstance(exc, OverflowError):
        return f"input: a number is too large ({echo(exc)}); expected values in the stated ranges", EXIT_INPUT
    return (f"internal error: {type(exc).__name__}: {echo(exc)} (a bug: run again with --debug for the traceback "
            f"and report it)", EXIT_INTERNAL)


def click_message(exc: click.ClickException) -> str:
    """click's usage errors (three lines: usage, hint, error) as one line naming the option."""
    message = exc.format_message().rstrip(".")
    m = re.match(r"Invalid value for '?([^':]+)'?: (.*)", message, re.S)
    if m:
        message = f"{m.group(1)}: {m.group(2).rstrip('.')}"
    if isinstance(exc, click.UsageError) and exc.ctx is not None:
        return f"{exc.ctx.command_path}: {message}; see `{exc.ctx.command_path} --help`"
    return message


def guarded(fn: Callable[[], int], debug: bool) -> int:
    """Run ``fn`` and turn any failure into one line on stderr and an exit status."""
    try:
        # On failure the error line says what went wrong; OpenUSD's own warnings and Python's about the same
        # problem would only repeat it (--debug shows them).
        with native_stderr_as_warnings(keep_on_failure=debug), python_warnings_held(keep_on_failure=debug):
            return fn()
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except click.ClickException as exc:
        click.echo(f"synthua: error: {one_line(click_message(exc))}", err=True)
        return EXIT_INPUT
    except click.Abort:
        click.echo("synthua: error: aborted", err=True)
        return EXIT_INPUT
    except KeyboardInterrupt:
        click.echo("synthua: error: interrupted; earlier results are as they were", err=True)
        return 130
    except BaseException as exc:  # noqa: BLE001 - the one place every failure is reported
        if isinstance(exc, SystemExit):
            raise
        if debug:
            traceback.print_exc()
        message, status = describe(exc)
        click.echo(f"synthua: error: {one_line(message)}", err=True)
        return status


def tool_main(run: Callable[[list[str] | None], int], argv: list[str] | None = None) -> int:
    """A ``tools/`` script's ``main``: ``run(argv)``, any failure one line on stderr as the synthua command's; bad
    input exits 2, anything else 3 after its traceback (a bug: a tool has no --debug to ask for it)."""
    try:
        return run(argv)
    except Exception as exc:  # noqa: BLE001 - bad input and failures end in one line, as the synthua command's
        message, status = describe(exc)
        if status != EXIT_INPUT:
            traceback.print_exc()
        print(f"synthua: error: {one_line(message)}", file=sys.stderr)
        return status


class _Held(logging.Filter):
    """Holds back every record it sees (they are handled later, or dropped)."""

    def __init__(self) -> None:
        super().__init__()
        self.records: list[logging.LogRecord] = []

    def filter(self, record: logging.LogRecord) -> bool:
        self.records.append(record)
        return False


@contextlib.contextmanager
def python_warnings_held(keep_on_failure: bool = True) -> Iterator[None]:
    """Hold back Python warnings (which ``logging.captureWarnings`` routes to the ``py.warnings`` logger) while
    the block runs; log them afterwards when it succeeded (or ``keep_on_failure``), else drop them."""
    logger = logging.getLogger("py.warnings")
    held = _Held()
    logger.addFilter(held)
    failed = True
    try:
        yield
        failed = False
    finally:
        logger.removeFilter(held)
        if keep_on_failure or not failed:
            for record in held.records:
                logger.handle(record)


#: How much of the native diagnostics is read back and how many lines are printed.
NATIVE_LIMIT = 64 * 1024
NATIVE_LINES = 20

_DIAGNOSTIC = re.compile(r"^(?:Warning|Error|Coding Error|Fatal Error|Status):?\s*(?:in \S+ at line \d+ of \S+ -- )?")
_STAGE_SUFFIX = re.compile(r"\s*\(instantiating stage on stage @[^@]*@ <0x[0-9a-f]+>\)$")


@contextlib.contextmanager
def native_stderr_as_warnings(keep_on_failure: bool = True) -> Iterator[None]:
    """Collect what native code (OpenUSD's diagnostics) writes to file descriptor 2 and log it as
    one-line warnings afterwards. Python's own ``sys.stderr`` keeps writing to the terminal. Does
    nothing when stderr is not file descriptor 2 (e.g. under pytest's capture)."""
    try:
        real = sys.stderr.fileno() == 2
    except (AttributeError, OSError, ValueError):
        real = False
    if not real:
        yield
        return
    sys.stderr.flush()
    saved = os.dup(2)
    original = sys.stderr
    replacement = None
    failed = True
    with tempfile.TemporaryFile() as sink:
        try:
            os.dup2(sink.fileno(), 2)
            replacement = os.fdopen(os.dup(saved), "w", buffering=1, encoding=original.encoding or "utf-8",
                                    errors="backslashreplace")
            sys.stderr = replacement
            _rebind_log_handlers(original, replacement)
            # A native crash (segfault, abort) still reaches the terminal, not the captured file.
            faulthandler.enable(replacement)
            yield
            failed = False
        finally:
            if replacement is not None:
                replacement.flush()
            os.dup2(saved, 2)
            os.close(saved)
            sys.stderr = original
            if replacement is not None:
                faulthandler.disable()
                _rebind_log_handlers(replacement, original)
                replacement.close()
            if keep_on_failure or not failed:
                size = sink.seek(0, os.SEEK_END)
                sink.seek(0)
                lines = _diagnostics(sink.read(NATIVE_LIMIT).decode("utf-8", "backslashreplace"))
                for line in lines[:NATIVE_LINES]:
                    log.warning("usd: %s", line)
                if len(lines) > NATIVE_LINES or size > NATIVE_LIMIT:
                    log.warning("usd: ... and more diagnostics (%d bytes in all, the first %d lines shown)", size, NATIVE_LINES)


def _rebind_log_handlers(old, new) -> None:
    for handler in logging.getLogger().handlers:
        if isinstance(handler, logging.StreamHandler) and handler.stream is old:
            handler.setStream(new)


def _diagnostics(text: str) -> list[str]:
    """Native diagnostic blocks (a header line and its continuation lines) as single lines."""
    out: list[str] = []
    for line in text.splitlines():
        if not line.strip():
            continue
        if line[:1].isspace() and out:
            out[-1] += " " + line.strip()
        else:
            out.append(_DIAGNOSTIC.sub("", line.strip()) or line.strip())
    return [_STAGE_SUFFIX.sub("", line) for line in out]
