"""What a worker and its parent exchange under either executor (:mod:`synthua_usd.pipeline.executors`' local
pool, :mod:`synthua_usd.pipeline.ray_executor`'s actors): the run's settings, an item's result, the run's summary,
the envelopes a worker sends back and how the parent raises a worker's failure. Both executors import it, so
neither needs the other."""

from __future__ import annotations

import contextlib
import importlib
import importlib.util
import logging
import os
import socket
import sys
import time
import traceback
from dataclasses import dataclass, field
from typing import Any, Callable, Generic, TypeVar

from synthua_usd.core.errors import InputError, SynthuaError, echo

log = logging.getLogger(__name__)

R = TypeVar("R")

#: The executors :func:`run_shards` knows.
EXECUTORS = ("local", "ray")

#: The install line given when Ray is asked for and missing.
RAY_INSTALL = "pip install 'synthua-usd[ray]'"


class WorkerError(RuntimeError):
    """An unexpected exception in a worker (a bug); ``__cause__`` holds the worker's traceback as text."""


class WorkerLostError(SynthuaError):
    """A worker process ended without an answer (a crash in native code, an out-of-memory kill, a lost
    node) more often than the retries allow."""


class RemoteTraceback(Exception):
    """The traceback of an exception raised in a worker, chained as the ``__cause__`` of the parent's."""

    def __init__(self, text: str) -> None:
        super().__init__(text)
        self.text = text

    def __str__(self) -> str:
        return self.text


@dataclass(frozen=True)
class ExecutorConfig:
    """Where and how wide shards run.

    ``kind`` is one of :data:`EXECUTORS`; ``workers`` the number of worker processes (Ray actors);
    ``address`` a Ray cluster (``HOST:6379`` or ``auto``; ray only, None: a Ray instance on this machine);
    ``retries`` how many times one shard may lose its worker and continue on another;
    ``cpus_per_worker`` the CPUs Ray reserves for each actor (ray only: a render session uses many threads,
    so on a cluster of large nodes give each actor a node's share); ``ray_runtime_env`` Ray's
    ``runtime_env`` for the job (e.g. ``{"working_dir": "."}`` to ship the scenario files; ray only).
    """

    kind: str = "local"
    workers: int = 1
    address: str | None = None
    retries: int = 1
    cpus_per_worker: float = 1.0
    ray_runtime_env: dict | None = None

    def __post_init__(self) -> None:
        if self.kind not in EXECUTORS:
            raise InputError(f"--executor: {echo(self.kind)!r} is not an executor; expected one of "
                             f"{', '.join(EXECUTORS)}")
        if not isinstance(self.workers, int) or isinstance(self.workers, bool) or self.workers < 1:
            raise InputError(f"--workers: {echo(self.workers)}; expected a whole number >= 1")
        if self.kind != "ray" and (self.address is not None or self.ray_runtime_env is not None):
            raise InputError(f"--address: {echo(self.address)} given with --executor {self.kind}; "
                             f"expected --executor ray (a Ray cluster) or no --address")
        if self.kind == "ray" and importlib.util.find_spec("ray") is None:
            raise InputError(f"--executor ray: the ray package is not installed; expected it installed "
                             f"(run: {RAY_INSTALL})")
        if not isinstance(self.retries, int) or self.retries < 0:
            raise InputError(f"retries: {echo(self.retries)}; expected a whole number >= 0")
        if not self.cpus_per_worker > 0:
            raise InputError(f"cpus_per_worker: {echo(self.cpus_per_worker)}; expected a number > 0")


@dataclass(frozen=True)
class ItemResult(Generic[R]):
    """What ``work`` returned for item ``index`` of shard ``shard``, with the worker that computed it
    (``host:pid``), the worker's peak resident memory so far (MiB) and the seconds ``work`` took."""

    shard: int
    index: int
    value: R
    worker: str
    peak_rss_mib: float
    seconds: float


@dataclass
class RunSummary:
    """Counts of a finished run: items delivered, shards, workers lost and replaced, wall time (s), and
    the peak resident memory (MiB) of each worker (``host:pid``), its state included."""

    items: int = 0
    shards: int = 0
    workers_lost: int = 0
    seconds: float = 0.0
    peak_rss_mib: dict[str, float] = field(default_factory=dict)


def peak_rss_mib() -> float:
    """Peak resident set size of this process so far, MiB: ``VmHWM`` of ``/proc/self/status`` on Linux
    (``getrusage``'s peak is carried over an exec, so a spawned worker would report its parent's), else
    ``getrusage`` (KiB on Linux, bytes on macOS)."""
    import resource

    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (1024 * 1024) if sys.platform == "darwin" else peak / 1024


def worker_name() -> str:
    """``host:pid`` of this process: how results and memory reports name a worker."""
    return f"{socket.gethostname()}:{os.getpid()}"


# ---- what a worker does, under either executor ------------------------------------------------------------

def call_work(work: Callable, state: Any, item: Any) -> tuple:
    """``("ok", value, peak_rss_mib, seconds)`` or the :func:`failure` of ``work(state, item)``."""
    t0 = time.perf_counter()
    try:
        value = work(state, item)
    except BaseException as exc:  # noqa: BLE001 - reported to the parent, which decides
        return failure(exc)
    return ("ok", value, peak_rss_mib(), time.perf_counter() - t0)


def failure(exc: BaseException) -> tuple:
    """``("error", kind, module, qualname, message, errno, filename, traceback text)`` of ``exc``: plain
    data the parent turns back into an exception (:func:`raise_failure`), whatever the class pickles to."""
    cls = type(exc)
    kind = "expected" if isinstance(exc, (SynthuaError, MemoryError)) else "os" if isinstance(exc, OSError) else "other"
    message = exc.strerror if kind == "os" and exc.strerror else str(exc)
    return ("error", kind, cls.__module__, cls.__qualname__, message, getattr(exc, "errno", None),
            getattr(exc, "filename", None), "".join(traceback.format_exception(exc)))


def raise_failure(envelope: tuple, where: str) -> None:
    """Raise in the parent the exception a worker reported as ``envelope`` (see :func:`failure`)."""
    _, kind, module, qualname, message, errno_, filename, tb = envelope
    log.debug("%s failed:\n%s", where, tb)
    cause = RemoteTraceback(tb)
    if kind == "os":
        raise OSError(errno_, message, filename) from cause  # OSError(errno, ...) picks the subclass by errno
    if kind == "expected":
        cls = _class(module, qualname)
        if isinstance(cls, type) and issubclass(cls, (SynthuaError, MemoryError)):
            try:
                exc = cls(message)
            except Exception:  # noqa: BLE001 - a subclass with another signature: keep the message
                exc = SynthuaError(message)
            raise exc from cause
        raise SynthuaError(message) from cause
    first = message.splitlines()[0] if message else ""
    raise WorkerError(f"{where}: {qualname}: {echo(first)}") from cause


def _class(module: str, qualname: str):
    with contextlib.suppress(Exception):
        obj = importlib.import_module(module)
        for part in qualname.split("."):
            obj = getattr(obj, part)
        return obj
    return None


def lost_message(where: str, how: str, attempts: int, peak: float | None, exit_status: int | None = None) -> str:
    """The one line of :class:`WorkerLostError`; ``exit_status`` > 0: the worker exited by itself (its own
    error output says why), else it was killed or lost."""
    memory = f"; its peak memory was {peak:.0f} MiB" if peak is not None else ""
    tries = f" on {attempts} workers in turn" if attempts > 1 else ""
    why = ("the worker's error output above says why" if exit_status is not None and exit_status > 0 else
           "a crash in native code, or the system out of memory: try fewer --workers or a smaller image")
    return f"{where}: the worker {how}{tries}{memory}; expected it to finish ({why})"


