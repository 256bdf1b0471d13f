"""The background writer: jobs in order, a bounded queue, and failures raised where results are collected."""

import threading
import time

import pytest

from synthua_usd.pipeline.background import BackgroundWriter


def test_results_come_back_in_order_and_the_queue_is_bounded():
    started, release = [], threading.Event()

    def job(i):
        started.append(i)
        release.wait(5)
        return i * 10

    with BackgroundWriter(max_pending=2) as writer:
        assert writer.submit(job, 0) == [] and writer.submit(job, 1) == []
        assert writer.pending == 2
        # A third job waits for the oldest: release them and it collects job 0 on the way.
        threading.Timer(0.2, release.set).start()
        t0 = time.perf_counter()
        done = writer.submit(job, 2)
        assert time.perf_counter() - t0 >= 0.15 and done[0] == 0
        assert done + writer.drain() == [0, 10, 20]
        assert writer.pending == 0 and started == [0, 1, 2]


def test_one_job_runs_while_the_caller_goes_on():
    events = []

    def job():
        events.append("write start")
        time.sleep(0.3)
        events.append("write end")

    with BackgroundWriter() as writer:
        writer.submit(job)
        events.append("caller goes on")
        writer.drain()
    assert events.index("caller goes on") < events.index("write end")


def test_a_failed_job_raises_where_its_result_is_collected():
    def job(i):
        if i == 1:
            raise OSError(28, "No space left on device", "out/x.png")
        return i

    with BackgroundWriter() as writer:
        assert writer.submit(job, 0) == []
        assert writer.submit(job, 1) == [0]
        with pytest.raises(OSError, match="No space left"):
            writer.drain()


def test_close_waits_for_running_jobs_and_swallows_their_errors():
    done = []

    def slow():
        time.sleep(0.2)
        done.append(1)
        raise RuntimeError("late")

    writer = BackgroundWriter()
    writer.submit(slow)
    writer.close()
    assert done == [1]
    with pytest.raises(ValueError, match="max_pending should be >= 1"):
        BackgroundWriter(max_pending=0)
