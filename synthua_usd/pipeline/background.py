"""Writing files off the render loop: one mechanism for ``synthua render`` and the dataset workers.

Encoding files costs more than the label pass (measured at 1280×960: a 16-bit PNG about 30 ms, a float EXR
about 50 ms), so a frame's files are written on a background thread while the next frame renders.

:class:`BackgroundWriter` runs one job at a time (a job writes one frame or image: its files, then its
document or record, in that order) on one thread, and gives the jobs a small pool of encoder threads for the
files of one job (OpenImageIO releases the GIL while it encodes). The queue is bounded: :meth:`submit` waits
while ``max_pending`` jobs are still unfinished, so at most ``max_pending`` frames' buffers wait in memory
beside the one being rendered, however long the run. Results come back in submission order; a job that
failed raises its exception from the :meth:`submit` or :meth:`drain` that collects it — the caller's loop
stops there, and a caller writing into an :func:`synthua_usd.core.atomic.output_set` leaves earlier outputs as
they were.
"""

from __future__ import annotations

import logging
from collections import deque
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, Callable

log = logging.getLogger(__name__)

#: Encoder threads per writer: the files of one frame (RGB EXR and PNG, class, semantic, instance, depth).
ENCODERS = 4


class BackgroundWriter:
    """Jobs on a background thread, at most ``max_pending`` unfinished at once; see the module docstring.

    Use as a context manager (or call :meth:`close`): leaving it waits for the jobs still running and never
    raises their errors (collect them with :meth:`drain` first)."""

    def __init__(self, max_pending: int = 1, encoders: int = ENCODERS) -> None:
        if max_pending < 1:
            raise ValueError(f"max_pending should be >= 1, but was {max_pending}")
        self.max_pending = max_pending
        self._thread = ThreadPoolExecutor(max_workers=1, thread_name_prefix="synthua-writer")
        #: Threads for the files of one job, e.g. ``writer.encoders.submit(images.write_id_png, path, ids)``.
        self.encoders = ThreadPoolExecutor(max_workers=encoders, thread_name_prefix="synthua-encode")
        self._pending: deque[Future] = deque()

    def submit(self, fn: Callable[..., Any], *args, **kwargs) -> list:
        """Queue ``fn(*args, **kwargs)``, first waiting while ``max_pending`` jobs are unfinished. Returns the
        results of the jobs collected on the way (the oldest first); raises the first of them that failed."""
        done = self._collect(lambda: len(self._pending) >= self.max_pending)
        self._pending.append(self._thread.submit(fn, *args, **kwargs))
        return done

    def drain(self) -> list:
        """Wait for every queued job; their results, oldest first (raises the first that failed)."""
        return self._collect(lambda: bool(self._pending))

    def _collect(self, wait_while: Callable[[], bool]) -> list:
        done = []
        while self._pending and (wait_while() or self._pending[0].done()):
            done.append(self._pending.popleft().result())
        return done

    @property
    def pending(self) -> int:
        """Jobs queued or running."""
        return len(self._pending)

    def close(self) -> None:
        """Wait for the jobs still running (their errors are dropped: the caller has already failed), then stop
        the threads."""
        for future in self._pending:
            try:
                future.result()
            except Exception as exc:  # noqa: BLE001 - a later failure while the first is being reported
                log.debug("background write failed after an earlier error: %s", exc)
        self._pending.clear()
        self._thread.shutdown(wait=True)
        self.encoders.shutdown(wait=True)

    def __enter__(self) -> "BackgroundWriter":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
