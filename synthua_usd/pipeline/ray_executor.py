"""The ``ray`` executor of :func:`synthua_usd.pipeline.executors.run_shards`: one Ray actor per worker.

Each actor builds its state once (``init``) and runs ``work`` for the items sent to it; Ray runs one
caller's calls on one actor in the order they were sent, so a shard's items run in order. Two items per
actor are in flight at a time: the actor starts the next while the parent fetches the last, and results
do not pile up in Ray's object store when the parent is slower than the workers. Actor methods return the
same plain envelopes as the local pool's workers (:func:`~synthua_usd.pipeline.worker_protocol.call_work`), so
errors reach the parent the same way; a Ray error on a call means the actor (its process or its node) is
gone, and the shard continues on another actor (an idle one, else a new one).

Ray is imported here only, when asked for: it is an optional dependency (``pip install 'synthua-usd[ray]'``).
"""

from __future__ import annotations

import logging
import re
from collections import deque
from dataclasses import dataclass, field
from typing import Any, Callable

from synthua_usd import __version__
from synthua_usd.core.errors import InputError, echo
from synthua_usd.pipeline.worker_protocol import (ExecutorConfig, ItemResult, RunSummary, WorkerError, WorkerLostError,
                                                 call_work, failure, lost_message, peak_rss_mib, raise_failure,
                                                 worker_name)

log = logging.getLogger(__name__)

#: Calls sent ahead to one actor.
IN_FLIGHT = 2

#: Seconds one ``ray.wait`` blocks: between two waits Python sees KeyboardInterrupt.
WAIT_S = 0.5

#: Colour codes Ray puts in its error messages.
_ANSI = re.compile(r"\x1b\[[0-9;]*m")


class ShardActor:
    """The state of one Ray worker: built once, used for every item sent to it."""

    def __init__(self, init: Callable, work: Callable) -> None:
        self.work = work
        self.state = None
        self.error = None
        try:
            self.state = init()
        except BaseException as exc:  # noqa: BLE001 - reported by ready()
            self.error = failure(exc)

    def ready(self) -> tuple:
        """``("ready", host:pid, peak RSS MiB)``, or the failure of ``init``."""
        return self.error or ("ready", worker_name(), peak_rss_mib())

    def run(self, item: Any) -> tuple:
        return self.error or call_work(self.work, self.state, item)


@dataclass(eq=False)
class _Actor:
    handle: Any
    ready_ref: Any
    name: str = ""
    peak: float | None = None
    shard: int | None = None
    next_index: int = 0  # the next item to deliver
    sent_index: int = 0  # the next item to send
    in_flight: deque = field(default_factory=deque)


def connect(ray, config: ExecutorConfig) -> None:
    """Join the cluster at ``config.address``, or start a Ray instance of this process's own ("local": never
    one that ``ray start`` left running here). A cluster that cannot be joined is a one-line InputError."""
    options = {"address": config.address or "local", "runtime_env": config.ray_runtime_env, "log_to_driver": False}
    if config.address is None:
        options["include_dashboard"] = False
    elif config.address != "auto":
        check_reachable(config.address)
    try:
        ray.init(**options)
    except ConnectionError as exc:
        lines = [line for line in _ANSI.sub("", str(exc)).splitlines() if line.strip()]
        found = echo(lines[0] if lines else type(exc).__name__)
        raise InputError(f"--address {echo(config.address)}: cannot join the Ray cluster ({found});"
                         f" expected a running cluster (`ray start --head` on that host) reachable from here; with "
                         f"token authentication, RAY_AUTH_MODE=token and the cluster's token (~/.ray/auth_token or "
                         f"RAY_AUTH_TOKEN) on this machine") from exc


#: Seconds to wait for a TCP connection to a Ray head before saying it cannot be reached (Ray itself retries
#: for minutes without a word).
CONNECT_TIMEOUT_S = 10.0


def check_reachable(address: str) -> None:
    """Refuse a ``HOST:PORT`` nothing answers on, in seconds rather than Ray's minutes of retries."""
    import socket

    host, _, port = address.rpartition(":")
    if not host or not port.isdigit():
        raise InputError(f"--address {echo(address)}: not HOST:PORT; expected the Ray head's address, e.g. "
                         f"10.0.0.5:6379")
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=CONNECT_TIMEOUT_S):
            pass
    except OSError as exc:
        raise InputError(f"--address {echo(address)}: nothing answers there ({echo(exc.strerror or exc)}); "
                         f"expected a running Ray head (`ray start --head --port {port}` on {echo(host)})") from None


def run_on_ray(shards: list[list], init: Callable, work: Callable, on_result: Callable[[ItemResult], None],
               config: ExecutorConfig, summary: RunSummary, more: Callable[[], list] | None = None) -> None:
    """Run ``shards`` on ``config.workers`` actors (see :func:`~synthua_usd.pipeline.executors.run_shards`)."""
    import ray

    started = not ray.is_initialized()
    if started:
        connect(ray, config)
    elif config.address is not None:
        log.warning("--address %s: Ray is already connected in this process; using that connection", config.address)
    actor_class = ray.remote(ShardActor).options(num_cpus=config.cpus_per_worker, max_restarts=0,
                                                 max_task_retries=0)
    queue = deque((i, 0) for i, s in enumerate(shards) if s)
    attempts = {i: 0 for i in range(len(shards))}
    actors: list[_Actor] = []

    def start() -> _Actor:
        handle = actor_class.remote(init, work)
        return _Actor(handle, handle.ready.remote())

    def feed(actor: _Actor) -> None:
        shard = shards[actor.shard]
        while len(actor.in_flight) < IN_FLIGHT and actor.sent_index < len(shard):
            actor.in_flight.append(actor.handle.run.remote(shard[actor.sent_index]))
            actor.sent_index += 1

    def dispatch(actor: _Actor) -> None:
        actor.shard = None
        if queue:
            actor.shard, actor.next_index = queue.popleft()
            actor.sent_index = actor.next_index
            feed(actor)

    def lost(actor: _Actor, exc: Exception) -> None:
        lines = [line for line in _ANSI.sub("", str(exc)).splitlines() if line.strip()]
        ray.kill(actor.handle, no_restart=True)
        if getattr(exc, "actor_init_failed", False):  # Ray could not even build the actor: a setup problem
            raise InputError(f"--executor ray: a worker could not start on the cluster ({echo(lines[-1])}); expected "
                             f"synthua-usd {__version__} and the job's modules importable on every Ray node (the same "
                             f"install at the same path)") from exc
        how = f"was lost ({type(exc).__name__}: {echo(lines[0] if lines else '')})"
        name = actor.name or "(starting)"
        if actor.shard is None:
            raise WorkerLostError(lost_message(f"Ray actor {name}, building its state", how, 1, actor.peak)) from exc
        attempts[actor.shard] += 1
        summary.workers_lost += 1
        where = f"Ray actor {name}, item {actor.next_index} of shard {actor.shard}"
        if attempts[actor.shard] > config.retries:
            raise WorkerLostError(lost_message(where, how, attempts[actor.shard], actor.peak)) from exc
        log.warning("%s: the actor %s; continuing the shard on another actor", where, how)
        queue.appendleft((actor.shard, actor.next_index))
        actors.remove(actor)
        idle = next((a for a in actors if a.ready_ref is None and a.shard is None), None)
        if idle is not None:  # an actor whose state is built and that has nothing to do takes it
            dispatch(idle)
        else:
            actors.append(start())

    def add(more_shards) -> None:  # a next round: idle actors take it, new ones start for the rest
        first = len(shards)
        shards.extend(list(s) for s in more_shards)
        attempts.update((first + i, 0) for i in range(len(more_shards)))
        queue.extend((first + i, 0) for i, s in enumerate(more_shards) if s)
        for actor in actors:
            if actor.ready_ref is None and actor.shard is None and queue:
                dispatch(actor)
        waiting = sum(1 for a in actors if a.ready_ref is not None)
        actors.extend(start() for _ in range(min(len(queue) - waiting, config.workers - len(actors))))

    try:
        actors.extend(start() for _ in range(min(config.workers, len(queue))))
        while True:
            _drain(ray, actors, queue, shards, on_result, summary, dispatch, feed, lost)
            following = [] if more is None else [list(s) for s in more()]
            if not any(following):
                break
            summary.shards += len(following)
            add(following)
    finally:
        for actor in actors:
            try:
                ray.kill(actor.handle, no_restart=True)
            except Exception as exc:  # noqa: BLE001 - ending the others matters more
                log.debug("could not kill Ray actor %s: %s", actor.name, exc)
        if started:
            ray.shutdown()


def _drain(ray, actors: list, queue: deque, shards: list[list], on_result: Callable[[ItemResult], None],
           summary: RunSummary, dispatch: Callable, feed: Callable, lost: Callable) -> None:
    """Run until every queued shard is done: deliver each answer, keep each actor fed."""
    while queue or any(a.shard is not None for a in actors):
        heads = {(a.ready_ref if a.ready_ref is not None else a.in_flight[0]): a
                 for a in actors if a.ready_ref is not None or a.in_flight}
        if not heads:  # every actor idle and the queue empty: cannot happen while the loop runs
            raise WorkerError("ray executor: no actor is working but shards remain (a bug)")
        done = []
        while not done:  # a wait without a timeout blocks in Ray's C++ code, deaf to Ctrl-C
            done, _ = ray.wait(list(heads), num_returns=1, timeout=WAIT_S)
        actor = heads[done[0]]
        try:
            envelope = ray.get(done[0])
        except ray.exceptions.RayTaskError as exc:  # the actor's answer itself failed (it cannot be sent)
            first = _ANSI.sub("", str(exc)).strip().splitlines()[:1]
            raise WorkerError(f"Ray actor {actor.name}: {type(exc).__name__}: {echo(''.join(first))}") from exc
        except ray.exceptions.RayError as exc:
            lost(actor, exc)
            continue
        if actor.ready_ref is not None:
            actor.ready_ref = None
            if envelope[0] == "error":
                raise_failure(envelope, "Ray actor, building its state")
            _, actor.name, actor.peak = envelope
            summary.peak_rss_mib[actor.name] = actor.peak
            dispatch(actor)
            continue
        actor.in_flight.popleft()
        if envelope[0] == "error":
            raise_failure(envelope, f"Ray actor {actor.name}, item {actor.next_index} of shard {actor.shard}")
        _, value, actor.peak, seconds = envelope
        summary.peak_rss_mib[actor.name] = actor.peak
        on_result(ItemResult(actor.shard, actor.next_index, value, actor.name, actor.peak, seconds))
        summary.items += 1
        actor.next_index += 1
        if actor.next_index < len(shards[actor.shard]):
            feed(actor)
        else:
            dispatch(actor)
