"""run_shards on the local pool and on a local Ray instance: identical results, errors that keep their type
and message, lost workers replaced (or reported), no processes left behind, Ctrl-C and kill -9 of the parent.

The toy state is a table drawn from a seeded RNG plus a token unique to each state built; an item's value is
the SHA-256 of the table and the item, recomputed here independently of any worker.
"""

from __future__ import annotations

import errno
import functools
import hashlib
import multiprocessing
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from synthua_usd.core.errors import InputError, OutputError, StageError
from synthua_usd.pipeline.executors import STOP_GRACE_S, run_shards
from synthua_usd.pipeline.worker_protocol import (ExecutorConfig, RemoteTraceback, WorkerError, WorkerLostError,
                                                 peak_rss_mib)

HERE = Path(__file__).resolve().parent
SEED = 1234


# ---- the toy: top-level, so spawned workers and Ray actors import it from this module ---------------------

def make_state(seed: int, fail: str | None = None, meet: tuple[str, int] | None = None) -> dict:
    """The toy state; ``meet=(folder, n)``: wait (at most 120 s) until n states are being built, so that every
    worker is up before any runs a shard and each gets one."""
    if meet is not None:
        folder, n = Path(meet[0]), meet[1]
        (folder / str(os.getpid())).write_text("")
        deadline = time.monotonic() + 120  # a loaded machine may take over 30 s to start a second Ray actor
        while len(list(folder.iterdir())) < n and time.monotonic() < deadline:
            time.sleep(0.01)
    if fail == "input":
        raise InputError("scenario.usda: no camera; expected one")
    if fail == "die":
        os.kill(os.getpid(), signal.SIGKILL)
    if fail == "exit":
        os._exit(3)
    table = np.random.default_rng(seed).integers(0, 2**63, 64, dtype=np.int64).tobytes()
    return {"table": table, "token": os.urandom(8).hex()}


def toy_work(state: dict, item):
    """``item`` is an int (a value), or a tuple naming what to do: raise, die, die once, sleep."""
    if isinstance(item, tuple):
        action, arg = item
        if action == "input":
            raise StageError(arg)
        if action == "output":
            raise OutputError(arg)
        if action == "os":
            raise OSError(errno.ENOSPC, "No space left on device", arg)
        if action == "bug":
            raise ValueError(arg)
        if action == "die":
            os.kill(os.getpid(), signal.SIGKILL)
        if action == "die_once":  # die the first time any worker meets this item
            marker = Path(arg)
            if not marker.exists():
                marker.write_text("died")
                os.kill(os.getpid(), signal.SIGKILL)
        if action == "sleep":  # announce this worker, then sleep (interrupt tests)
            (Path(arg) / str(os.getpid())).write_text("")
            time.sleep(60)
        item = 0
    time.sleep(0.02)  # work takes time: a second worker that is ready gets a shard before the first ends all
    return hashlib.sha256(state["table"] + str(item).encode()).digest(), state["token"]


def expected_value(item) -> bytes:
    table = np.random.default_rng(SEED).integers(0, 2**63, 64, dtype=np.int64).tobytes()
    return hashlib.sha256(table + str(0 if isinstance(item, tuple) else item).encode()).digest()


INIT = functools.partial(make_state, SEED)
SHARDS = [list(range(0, 5)), list(range(5, 8)), [8], list(range(9, 14))]


def run(shards, config: ExecutorConfig, init=INIT):
    """{(shard, index): value}, the results in the order they came, and the summary."""
    got, order = {}, []

    def on_result(r):
        assert (r.shard, r.index) not in got, "a result delivered twice"
        got[(r.shard, r.index)] = r.value
        order.append(r)

    summary = run_shards(shards, init, toy_work, on_result, config)
    return got, order, summary


def gone(pid: int, within_s: float = 10.0) -> bool:
    """Whether process ``pid`` no longer runs (or is a zombie) within ``within_s`` seconds."""
    deadline = time.monotonic() + within_s
    while time.monotonic() < deadline:
        try:
            status = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except (FileNotFoundError, ProcessLookupError):
            return True
        if status in ("Z", "X"):
            return True
        time.sleep(0.05)
    return False


def worker_pids(order) -> set[int]:
    return {int(r.worker.rsplit(":", 1)[1]) for r in order}


def check_run(got, order, shards):
    assert set(got) == {(s, i) for s, shard in enumerate(shards) for i in range(len(shard))}
    for (s, i), (digest, _) in got.items():
        assert digest == expected_value(shards[s][i]), (s, i)
    for s in range(len(shards)):  # each shard's results arrive in its order
        assert [r.index for r in order if r.shard == s] == list(range(len(shards[s])))


# ---- local ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("workers", [1, 2])
def test_local_runs_every_item_once_in_shard_order_on_states_built_once(workers, tmp_path):
    init = functools.partial(make_state, SEED, meet=(str(tmp_path), workers))
    got, order, summary = run(SHARDS, ExecutorConfig("local", workers=workers), init=init)
    check_run(got, order, SHARDS)
    pids = worker_pids(order)
    assert len(pids) == workers and os.getpid() not in pids
    # one state per worker, reused for all its shards: one token per worker
    assert len({v[1] for v in got.values()}) == workers
    assert summary.items == 14 and summary.shards == 4 and summary.workers_lost == 0
    assert set(summary.peak_rss_mib) == {r.worker for r in order}
    assert all(10 < mib < 4096 for mib in summary.peak_rss_mib.values())
    assert all(gone(pid, 0.5) for pid in pids)


def rounds_of(*rounds):
    """A ``more`` that hands out ``rounds`` one by one (then nothing), and the shards in the order given."""
    given, left = [], list(rounds)

    def more():
        shards = left.pop(0) if left else []
        given.extend(shards)
        return shards

    return more, given


@pytest.mark.parametrize("kind", ["local", "ray"])
def test_later_rounds_run_on_the_same_workers_and_states(kind, tmp_path, request):
    if kind == "ray":
        request.getfixturevalue("ray_instance")
    more, given = rounds_of([[14, 15], [16]], [], [[17]])  # an empty answer ends the run: [[17]] is never asked
    got, order = {}, []

    def on_result(r):
        assert (r.shard, r.index) not in got, "a result delivered twice"
        got[(r.shard, r.index)] = r.value
        order.append(r)

    init = functools.partial(make_state, SEED, meet=(str(tmp_path), 2))
    summary = run_shards(SHARDS, init, toy_work, on_result, ExecutorConfig(kind, workers=2), more=more)
    shards = SHARDS + given
    assert given == [[14, 15], [16]] and summary.shards == 6 and summary.items == 17
    check_run(got, order, shards)
    # the rounds came after every earlier result, on the two states built for the first round
    assert [r.shard for r in order][-3:].count(4) == 2 and {r.shard for r in order[-3:]} == {4, 5}
    assert len({v[1] for v in got.values()}) == 2
    if kind == "local":
        assert len(worker_pids(order)) == 2


def test_a_first_round_from_more_alone_starts_the_workers():
    more, given = rounds_of([[1, 2]])
    got = {}
    summary = run_shards([], INIT, toy_work, lambda r: got.setdefault((r.shard, r.index), r.value),
                         ExecutorConfig("local"), more=more)
    assert given == [[1, 2]] and summary.items == 2 and summary.shards == 1
    assert got[(0, 1)][0] == expected_value(2)


def test_peak_rss_grows_with_an_allocation():
    before = peak_rss_mib()
    block = np.ones(64 * 2**20 // 8)  # 64 MiB, touched
    assert peak_rss_mib() >= before + 60 or before > 64 + 60, (before, peak_rss_mib(), block[-1])


def test_empty_shards_start_no_worker():
    got, order, summary = run([[], []], ExecutorConfig("local", workers=2))
    assert got == {} and summary.items == 0


@pytest.mark.parametrize("item, cls, message", [
    (("input", "/World/cam: not a Camera; expected a Camera prim"), StageError,
     "/World/cam: not a Camera; expected a Camera prim"),
    (("output", "out/images: not writable; expected a writable folder"), OutputError,
     "out/images: not writable; expected a writable folder"),
], ids=["StageError", "OutputError"])
def test_errors_reach_the_parent_with_their_type_and_message(item, cls, message):
    shards = [[0, 1, item, 3], list(range(4, 9))]
    with pytest.raises(cls) as info:
        run(shards, ExecutorConfig("local", workers=2))
    assert type(info.value) is cls and str(info.value) == message


def test_an_error_in_the_parents_on_result_ends_the_workers():
    seen = []

    def on_result(r):
        seen.append(r)
        raise OutputError("out/annotations: disk full; expected free space")

    with pytest.raises(OutputError, match="^out/annotations: disk full"):
        run_shards(SHARDS, INIT, toy_work, on_result, ExecutorConfig("local", workers=2))
    assert len(seen) == 1 and gone(int(seen[0].worker.rsplit(":", 1)[1]), 0.5)
    assert not [p for p in multiprocessing.active_children() if p.name == "synthua-worker"]


def test_os_errors_keep_errno_and_file():
    with pytest.raises(OSError) as info:
        run([[("os", "out/x.png")]], ExecutorConfig("local"))
    assert info.value.errno == errno.ENOSPC and info.value.filename == "out/x.png"


def test_an_unexpected_exception_is_an_internal_error_with_the_workers_traceback():
    with pytest.raises(WorkerError, match=r"item 1 of shard 0: ValueError: boom") as info:
        run([[0, ("bug", "boom"), 2]], ExecutorConfig("local"))
    cause = info.value.__cause__
    assert isinstance(cause, RemoteTraceback)
    assert "toy_work" in cause.text and "ValueError: boom" in cause.text


def test_an_error_building_the_state_reaches_the_parent():
    with pytest.raises(InputError, match="^scenario.usda: no camera; expected one$"):
        run(SHARDS, ExecutorConfig("local", workers=2), init=functools.partial(make_state, SEED, "input"))


def test_a_killed_worker_is_replaced_and_its_shard_continues_on_a_fresh_state(tmp_path):
    # One worker: no idle one to take the shard over, so a new one starts.
    shards = [[0, 1, ("die_once", str(tmp_path / "died")), 3, 4], [5, 6]]
    got, order, summary = run(shards, ExecutorConfig("local", workers=1))
    check_run(got, order, shards)
    assert summary.workers_lost == 1
    tokens = [got[(0, i)][1] for i in range(5)]
    assert tokens[0] == tokens[1] != tokens[2] == tokens[3]  # items from 2 on ran on a new state
    assert len(worker_pids(order)) == 2 and all(gone(pid, 0.5) for pid in worker_pids(order))


def test_the_shard_of_a_killed_worker_goes_to_an_idle_worker_before_a_new_one(tmp_path):
    (tmp_path / "meet").mkdir()
    init = functools.partial(make_state, SEED, meet=(str(tmp_path / "meet"), 2))
    shards = [[*range(10), ("die_once", str(tmp_path / "died")), 11], [20]]  # shard 1 ends long before item 10
    got, order, summary = run(shards, ExecutorConfig("local", workers=2), init=init)
    check_run(got, order, shards)
    assert summary.workers_lost == 1 and len(worker_pids(order)) == 2  # no third worker started
    assert got[(0, 10)][1] == got[(1, 0)][1] != got[(0, 0)][1]  # the idle worker's state took the rest


def test_a_worker_killed_more_often_than_the_retries_allow_is_a_clear_error():
    with pytest.raises(WorkerLostError) as info:
        run([[0, ("die", None)], [1, 2, 3]], ExecutorConfig("local", workers=2, retries=1))
    message = str(info.value)
    assert "item 1 of shard 0" in message and "SIGKILL" in message and "on 2 workers in turn" in message
    assert "\n" not in message
    assert not [p for p in multiprocessing.active_children() if p.name == "synthua-worker"]


@pytest.mark.parametrize("fail, message", [
    ("die", r"building its state: the worker was killed by SIGKILL; expected it to finish \(a crash in native code"),
    ("exit", r"building its state: the worker exited with status 3; expected it to finish \(the worker's error output"),
], ids=["killed", "exited"])
def test_a_worker_dying_while_building_its_state_is_a_clear_error(fail, message):
    with pytest.raises(WorkerLostError, match=message):
        run(SHARDS, ExecutorConfig("local"), init=functools.partial(make_state, SEED, fail))


def test_functions_that_cannot_reach_a_worker_are_refused_up_front():
    with pytest.raises(TypeError, match="work=.*cannot be sent to a worker"):
        run_shards([[1]], INIT, lambda state, item: item, print, ExecutorConfig("local"))


@pytest.mark.parametrize("kwargs, message", [
    ({"kind": "dask"}, r"^--executor: 'dask' is not an executor; expected one of local, ray$"),
    ({"workers": 0}, r"^--workers: 0; expected a whole number >= 1$"),
    ({"address": "10.0.0.1:6379"}, r"^--address: 10.0.0.1:6379 given with --executor local; expected"),
])
def test_bad_executor_settings_are_one_line_input_errors(kwargs, message):
    with pytest.raises(InputError, match=message):
        ExecutorConfig(**kwargs)


def test_ray_asked_for_but_not_installed_says_how_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # find_spec reports such a module as missing
    with pytest.raises(InputError, match=r"^--executor ray: the ray package is not installed; .*pip install "
                                         r"'synthua-usd\[ray\]'\)$"):
        ExecutorConfig("ray", workers=2)


# ---- the parent interrupted (Ctrl-C) or killed (kill -9): no worker outlives it -----------------------------

PARENT = """
import sys
sys.path.insert(0, {here!r})
from test_executors import INIT, toy_work
from synthua_usd.pipeline.executors import run_shards
from synthua_usd.pipeline.worker_protocol import ExecutorConfig
shards = [[("sleep", {folder!r})], [("sleep", {folder!r})]]
run_shards(shards, INIT, toy_work, print, ExecutorConfig("local", workers=2))
"""


@pytest.mark.parametrize("how", ["ctrl-c", "kill -9"])
def test_no_worker_outlives_its_parent(tmp_path, how):
    script = textwrap.dedent(PARENT.format(here=str(HERE), folder=str(tmp_path)))
    # A foreground program in a terminal has Ctrl-C's default disposition; a test run started as a background job
    # (`cmd &`, nohup) inherits SIGINT ignored, and Python then installs no KeyboardInterrupt handler: restore it.
    parent = subprocess.Popen([sys.executable, "-c", script], start_new_session=True, stderr=subprocess.PIPE,
                              preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 60
        while len(list(tmp_path.iterdir())) < 2 and time.monotonic() < deadline and parent.poll() is None:
            time.sleep(0.05)
        pids = [int(p.name) for p in tmp_path.iterdir()]
        assert len(pids) == 2, parent.stderr.read().decode() if parent.poll() is not None else "workers did not start"
        if how == "ctrl-c":  # the terminal sends SIGINT to the whole foreground process group
            t0 = time.monotonic()
            os.killpg(parent.pid, signal.SIGINT)
            _, err = parent.communicate(timeout=30)
            assert parent.returncode != 0 and b"KeyboardInterrupt" in err
            assert time.monotonic() - t0 < STOP_GRACE_S  # busy workers are ended at once, not waited for
        else:
            parent.kill()
            parent.wait(timeout=30)
        assert all(gone(pid, 10.0) for pid in pids)
    finally:
        if parent.poll() is None:
            os.killpg(parent.pid, signal.SIGKILL)
            parent.wait()


# ---- ray: one local instance on loopback for the whole module --------------------------------------------

@pytest.fixture(scope="module")
def ray_instance():
    import ray

    # Ray's workers import the toy from this folder, as cluster nodes import synthua from the same install.
    ray.init(address="local", num_cpus=2, include_dashboard=False, _node_ip_address="127.0.0.1", log_to_driver=False,
             runtime_env={"env_vars": {"PYTHONPATH": os.pathsep.join([str(HERE), *sys.path])}})
    yield ray
    ray.shutdown()


def test_ray_gives_the_same_results_as_the_local_pool(ray_instance, tmp_path):
    local, _, _ = run(SHARDS, ExecutorConfig("local", workers=2))
    init = functools.partial(make_state, SEED, meet=(str(tmp_path), 2))
    got, order, summary = run(SHARDS, ExecutorConfig("ray", workers=2), init=init)
    check_run(got, order, SHARDS)
    assert {k: v[0] for k, v in got.items()} == {k: v[0] for k, v in local.items()}
    pids = worker_pids(order)
    assert len(pids) == 2 and os.getpid() not in pids and len({v[1] for v in got.values()}) == 2
    assert summary.items == 14 and set(summary.peak_rss_mib) == {r.worker for r in order}
    assert all(gone(pid) for pid in pids)  # the actors are ended with the run


def test_ray_errors_reach_the_parent_with_their_type_and_message(ray_instance):
    with pytest.raises(StageError, match="^/World/cam: not a Camera; expected a Camera prim$"):
        run([[0, ("input", "/World/cam: not a Camera; expected a Camera prim")], [1, 2]],
            ExecutorConfig("ray", workers=2))
    with pytest.raises(WorkerError, match="ValueError: boom") as info:
        run([[("bug", "boom")]], ExecutorConfig("ray"))
    assert "toy_work" in info.value.__cause__.text
    with pytest.raises(InputError, match="^scenario.usda: no camera; expected one$"):
        run(SHARDS, ExecutorConfig("ray"), init=functools.partial(make_state, SEED, "input"))


def test_ray_replaces_a_killed_actor_or_reports_it(ray_instance, tmp_path):
    shards = [[0, 1, ("die_once", str(tmp_path / "died")), 3], [4, 5]]
    got, order, summary = run(shards, ExecutorConfig("ray", workers=2))
    check_run(got, order, shards)
    # Item 2 is sent once item 0 is in: item 0 comes from the first state and item 2 from another. (Which item
    # the retry starts at depends on what was in flight: Ray may lose item 1's answer with the actor.)
    assert summary.workers_lost == 1 and got[(0, 0)][1] != got[(0, 2)][1]
    # The same race names the first item not delivered: item 1, or item 0 when its answer went down with the actor
    # (seen with the suite's parallel workers loading the machine).
    with pytest.raises(WorkerLostError, match=r"item [01] of shard 0: the worker was lost \(.*\) on 2 workers in "
                                              r"turn"):
        run([[0, ("die", None)]], ExecutorConfig("ray", retries=1))


def test_ray_says_so_when_a_worker_cannot_import_the_job(ray_instance, tmp_path, monkeypatch):
    # A module only the driver can import: as when a node lacks synthua or the job's files.
    (tmp_path / "driver_only.py").write_text("def init():\n    return {}\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import driver_only

    with pytest.raises(InputError, match=r"^--executor ray: a worker could not start on the cluster "
                                         r"\(ModuleNotFoundError: No module named 'driver_only'\); expected"):
        run([[1]], ExecutorConfig("ray"), init=driver_only.init)


def test_cut_shards_spreads_a_job_over_the_workers_and_keeps_scenes_whole():
    from synthua_usd.pipeline.executors import cut_shards

    def scene(item):
        return item[0]

    # 16 images of 4 seeds (scenes) for 2 workers: a shard per two seeds, none cut apart (before: one shard of 16,
    # so one of the two workers rendered everything)
    items = [(seed, k) for seed in range(4) for k in range(4)]
    shards = cut_shards(items, scene, workers=2, most=16)
    assert [len(s) for s in shards] == [8, 8] and sum(shards, []) == items
    assert all(len({scene(i) for i in s}) == 2 for s in shards)
    # a scene larger than a shard is cut into near-equal pieces, in order
    big = [(0, k) for k in range(10)] + [(1, 0)]
    assert [len(s) for s in cut_shards(big, scene, workers=2, most=4)] == [3, 4, 4]  # the next scene joins the last piece
    assert sum(cut_shards(big, scene, workers=2, most=4), []) == big
    # one worker: shards of at most `most`, scenes packed while they fit
    uneven = [(0, k) for k in range(5)] + [(1, k) for k in range(5)] + [(2, k) for k in range(3)]
    assert [len(s) for s in cut_shards(uneven, scene, workers=1, most=8)] == [5, 8]
    assert cut_shards([], scene, workers=3, most=8) == []
    # more workers than items: one item a shard
    assert cut_shards([(0, 0), (1, 0)], scene, workers=8, most=16) == [[(0, 0)], [(1, 0)]]
