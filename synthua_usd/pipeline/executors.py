"""Run shards of work on worker processes that each build an expensive state once: the scale-out of a job.

A *shard* is a sequence of items that one worker processes in order. A worker builds its state once with
``init()`` (a render session: one scene load) and then runs ``work(state, item)`` for every item of every
shard it is given; each result goes back to the parent, as soon as it is ready, through
``on_result(ItemResult)``. The parent writes dataset-level files from those results.

Two executors run the same protocol:

- ``local``: a pool of worker processes started with the ``spawn`` method (a fresh interpreter: Mitsuba,
  Dr.Jit and usd-core are imported inside the worker, never inherited from a parent that loaded them).
  One worker still runs in its own process, so a crash of native code ends that worker, not the command.
- ``ray``: one Ray actor per worker on a Ray cluster (``address``) or on a Ray instance started here.

Guarantees:

- an item's result is delivered exactly once; a shard's results arrive in the shard's order (shards run
  side by side, so results of different shards interleave: each :class:`ItemResult` names its shard
  and index, and the caller orders by them);
- an error raised by ``init`` or ``work`` stops the run (the other workers are ended) and is raised in the
  parent: :class:`~synthua_usd.core.errors.SynthuaError` subclasses (``InputError``, ``StageError``,
  ``OutputError``...), ``OSError`` and ``MemoryError`` as the same type with the same message; anything
  else as :class:`WorkerError`, whose ``__cause__`` carries the worker's traceback;
- a worker that dies (native crash, out-of-memory kill, a lost Ray node) takes its state with it: its
  shard continues at the first item not delivered on another worker, an idle one (state built, nothing left
  to do) or else a new one with a fresh state; after ``retries`` such losses of one shard the run stops with
  :class:`WorkerLostError`;
- with ``more``, when every shard given so far is done, ``more()`` is asked for the next ones (a round that
  depends on the results so far: replacements for rejected images); they run on the same workers, whose
  states are built, numbered after the earlier shards; an empty answer ends the run;
- on any exit, KeyboardInterrupt included, every worker is ended before :func:`run_shards` returns.

Which worker runs which shard, and what a worker's state did before, varies from run to run: a caller
wanting identical output makes each result depend on its item only (a render session's frame depends on
its snapshot, camera and condition, not on the frames before it).
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import multiprocessing
import os
import pickle
import signal
import sys
import time
from collections import deque
from dataclasses import dataclass
from multiprocessing.connection import wait
from typing import Any, Callable, Sequence, TypeVar

from synthua_usd.pipeline.worker_protocol import (ExecutorConfig, ItemResult, R, RunSummary,
                                                 WorkerLostError, call_work, failure, lost_message, peak_rss_mib,
                                                 raise_failure, worker_name)

log = logging.getLogger(__name__)

T = TypeVar("T")
S = TypeVar("S")

#: Seconds a stopped worker gets to exit before it is terminated, then killed.
STOP_GRACE_S = 5.0


def run_shards(shards: Sequence[Sequence[T]], init: Callable[[], S], work: Callable[[S, T], R],
               on_result: Callable[[ItemResult[R]], None], config: ExecutorConfig = ExecutorConfig(),
               more: Callable[[], Sequence[Sequence[T]]] | None = None) -> RunSummary:
    """Run every item of every shard (see the module's docstring for the guarantees).

    ``init`` and ``work`` must be picklable: top-level functions, bound with :func:`functools.partial`.
    ``on_result`` runs in the calling thread, between reads from the workers: keep it short (hand heavy
    writing to a thread) or the workers wait on it. Progress: count the calls to ``on_result``.
    """
    shards = [list(s) for s in shards]
    for name, fn in (("init", init), ("work", work)):
        try:
            pickle.dumps(fn)
        except Exception as exc:  # noqa: BLE001 - any pickling failure means the same thing
            raise TypeError(f"run_shards: {name}={fn!r} cannot be sent to a worker ({exc}); expected a "
                            f"top-level function, bound with functools.partial") from exc
    summary = RunSummary(shards=len(shards))
    t0 = time.perf_counter()
    if more is not None and not any(shards):  # nothing to start with: the first round may still come
        shards = [list(s) for s in more()]
        summary.shards = len(shards)
    if any(shards):
        if config.kind == "local":
            _LocalPool(shards, init, work, on_result, config, summary, more).run()
        else:
            from synthua_usd.pipeline.ray_executor import run_on_ray

            run_on_ray(shards, init, work, on_result, config, summary, more)
    summary.seconds = time.perf_counter() - t0
    return summary


def cut_shards(items: Sequence[T], group_of: Callable[[T], Any], workers: int, most: int) -> list[list[T]]:
    """``items`` (in the order a worker should take them) cut into shards for ``workers`` workers: about
    ``len(items) / workers`` items a shard, at most ``most``, so that every worker has work and a lost one costs
    little; consecutive items of one group (``group_of``: the scene they share) stay in one shard where the size
    allows, since a worker builds a group's scene once for all its items (a randomised seed's scene: seconds),
    and a group larger than a shard is cut into near-equal pieces."""
    items = list(items)
    if not items:
        return []
    size = max(1, min(most, -(-len(items) // max(1, workers))))
    groups: list[list[T]] = []
    for item in items:
        if groups and group_of(groups[-1][-1]) == group_of(item):
            groups[-1].append(item)
        else:
            groups.append([item])
    shards: list[list[T]] = []
    for group in groups:
        pieces = -(-len(group) // size)
        if pieces > 1:
            bounds = [round(k * len(group) / pieces) for k in range(pieces + 1)]
            shards.extend(group[a:b] for a, b in zip(bounds, bounds[1:]))
        elif shards and len(shards[-1]) + len(group) <= size:
            shards[-1].extend(group)
        else:
            shards.append(list(group))
    return shards


# ---- local: a pool of spawned processes -------------------------------------------------------------------

def _local_worker(conn, init: Callable, work: Callable) -> None:
    """A local worker's life: build the state, then run the shards the parent sends until it sends None."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C reaches the whole process group: the parent decides
    _end_with_parent()
    try:
        state = init()
    except BaseException as exc:  # noqa: BLE001 - reported to the parent
        conn.send(failure(exc))
        return
    conn.send(("ready", worker_name(), peak_rss_mib()))
    while True:
        try:
            task = conn.recv()
        except EOFError:  # the parent is gone
            return
        if task is None:
            return
        for item in task:
            envelope = call_work(work, state, item)
            try:
                conn.send(envelope)
            except OSError:  # the parent is gone
                return
            except Exception as exc:  # noqa: BLE001 - the value cannot be pickled: say so (nothing was sent)
                envelope = failure(exc)
                conn.send(envelope)
            if envelope[0] == "error":
                return


def _end_with_parent() -> None:
    """Ask Linux to end this process when its parent dies (no orphans if the parent is killed -9)."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # 1: PR_SET_PDEATHSIG
            if os.getppid() == 1:  # the parent died before the request took effect
                os._exit(1)


@dataclass(eq=False)
class _Slot:
    """One worker process of the pool and the shard it runs."""

    process: Any
    conn: Any
    #: "starting" (building its state), "busy" (running ``shard``), "idle" (waiting for a shard that a lost
    #: worker may leave) or "stopped" (exited, or told to).
    status: str = "starting"
    name: str = ""
    peak: float | None = None
    shard: int | None = None
    next_index: int = 0
    end_index: int = 0


class _LocalPool:
    def __init__(self, shards, init, work, on_result, config: ExecutorConfig, summary: RunSummary,
                 more: Callable[[], Sequence[Sequence[T]]] | None = None) -> None:
        self.init, self.work, self.on_result, self.more = init, work, on_result, more
        self.summary = summary
        self.retries, self.workers = config.retries, config.workers
        self.context = multiprocessing.get_context("spawn")
        self.shards: list[list] = []
        self.queue: deque = deque()  # (shard, first item not yet delivered)
        self.attempts: dict[int, int] = {}
        self.slots: list[_Slot] = []
        self._add(shards)

    def _add(self, shards) -> None:
        """Queue ``shards`` after those already given; idle workers take them, new ones start for the rest."""
        first = len(self.shards)
        self.shards.extend(list(s) for s in shards)
        self.attempts.update((first + i, 0) for i in range(len(shards)))
        self.queue.extend((first + i, 0) for i, s in enumerate(shards) if s)
        for slot in self.slots:
            if slot.status == "idle" and self.queue:
                self._dispatch(slot)
        waiting = sum(1 for s in self.slots if s.status == "starting")
        live = sum(1 for s in self.slots if s.status != "stopped")
        for _ in range(min(len(self.queue) - waiting, self.workers - live)):
            self.slots.append(self._start())

    def run(self) -> None:
        try:
            while True:
                while any(s.status == "busy" for s in self.slots) or self.queue:
                    for conn in wait([s.conn for s in self.slots if s.status != "stopped"]):
                        slot = next(s for s in self.slots if s.conn is conn)
                        try:
                            message = conn.recv()
                        except (EOFError, OSError):
                            self._lost(slot)
                            continue
                        self._handle(slot, message)
                shards = [] if self.more is None else [list(s) for s in self.more()]
                if not any(shards):
                    return
                self.summary.shards += len(shards)
                self._add(shards)
        finally:
            self._stop_all()

    def _start(self) -> _Slot:
        parent_end, child_end = self.context.Pipe()
        process = self.context.Process(target=_local_worker, args=(child_end, self.init, self.work),
                                       name="synthua-worker", daemon=True)
        process.start()
        child_end.close()  # the worker holds the only other end: its death reads as end of file here
        return _Slot(process, parent_end)

    def _handle(self, slot: _Slot, message: tuple) -> None:
        if message[0] == "error":
            where = f"worker {slot.name or slot.process.pid}" + (
                f", item {slot.next_index} of shard {slot.shard}" if slot.status == "busy" else ", building its state")
            raise_failure(message, where)
        if message[0] == "ready":
            slot.name, slot.peak = message[1], message[2]
            self.summary.peak_rss_mib[slot.name] = slot.peak
        else:
            _, value, slot.peak, seconds = message
            self.summary.peak_rss_mib[slot.name] = slot.peak
            self.on_result(ItemResult(slot.shard, slot.next_index, value, slot.name, slot.peak, seconds))
            self.summary.items += 1
            slot.next_index += 1
            if slot.next_index < slot.end_index:
                return
        self._dispatch(slot)

    def _dispatch(self, slot: _Slot) -> None:
        if self.queue:
            shard, start = self.queue.popleft()
            slot.status, slot.shard, slot.next_index, slot.end_index = "busy", shard, start, len(self.shards[shard])
            slot.conn.send(self.shards[shard][start:])
        else:  # kept until the end: a shard a lost worker leaves goes to a worker whose state is built
            slot.status, slot.shard = "idle", None

    def _lost(self, slot: _Slot) -> None:
        slot.process.join(STOP_GRACE_S)
        code = slot.process.exitcode
        how = (f"was killed by {signal.Signals(-code).name}" if code is not None and code < 0
               else f"exited with status {code}" if code is not None else "stopped answering")
        name = slot.name or f"pid {slot.process.pid}"
        slot.conn.close()
        status, slot.status = slot.status, "stopped"
        if status == "idle":  # nothing was lost with it
            log.warning("worker %s, idle: the worker %s", name, how)
            return
        if status == "starting":
            raise WorkerLostError(lost_message(f"worker {name}, building its state", how, 1, slot.peak, code))
        self.attempts[slot.shard] += 1
        self.summary.workers_lost += 1
        where = f"worker {name}, item {slot.next_index} of shard {slot.shard}"
        if self.attempts[slot.shard] > self.retries:
            raise WorkerLostError(lost_message(where, how, self.attempts[slot.shard], slot.peak, code))
        log.warning("%s: the worker %s; continuing the shard on another worker", where, how)
        self.queue.appendleft((slot.shard, slot.next_index))
        idle = next((s for s in self.slots if s.status == "idle"), None)
        if idle is not None:
            self._dispatch(idle)
        else:
            self.slots.append(self._start())

    def _stop_all(self) -> None:
        """End every worker: idle ones are told to stop and get :data:`STOP_GRACE_S` s, then SIGTERM, then
        SIGKILL; busy or starting ones (interrupted, or another failed) are terminated at once."""
        for slot in self.slots:
            if slot.status == "idle":
                with contextlib.suppress(OSError):
                    slot.conn.send(None)
            elif slot.status != "stopped":
                slot.process.terminate()
        deadline = time.monotonic() + STOP_GRACE_S
        for slot in self.slots:
            slot.process.join(max(0.0, deadline - time.monotonic()))
            if slot.process.is_alive():
                slot.process.terminate()
                slot.process.join(1.0)
            if slot.process.is_alive():
                slot.process.kill()
                slot.process.join()
            slot.conn.close()
