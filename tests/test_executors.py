"""Local worker processes: a failed task stops the others instead of waiting for them."""

import os
import signal
import threading
import time

import pytest
from worker_tasks import fail_or_finish_late

from cphysfno_core.config.experiment import DataConfig
from cphysfno_core.data.executors import run_tasks


def test_a_failed_task_terminates_the_tasks_still_running(toys_in_workers, tmp_path):
    settings = DataConfig(executor="processes", workers=2)
    started = time.perf_counter()
    with pytest.raises(RuntimeError, match="task 0 failed"):
        run_tasks(
            fail_or_finish_late,
            [0, 1],
            lambda key: (key, str(tmp_path)),
            settings,
            lambda key, result: None,
        )
    assert time.perf_counter() - started < 7.0  # not waiting for task 1's 8 s
    time.sleep(max(0.0, 10.0 - (time.perf_counter() - started)))
    assert not (tmp_path / "finished-1").exists()


def test_an_interrupted_run_terminates_its_workers(toys_in_workers, tmp_path):
    settings = DataConfig(executor="processes", workers=2)
    # Python's own Ctrl-C handler, also where the test runner was started with SIGINT
    # ignored (in the background of a non-interactive shell).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    ctrl_c = threading.Timer(2.0, os.kill, (os.getpid(), signal.SIGINT))
    ctrl_c.start()
    started = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            run_tasks(
                fail_or_finish_late,
                [1, 2],
                lambda key: (key, str(tmp_path)),
                settings,
                lambda key, result: None,
            )
    finally:
        signal.signal(signal.SIGINT, previous)
    assert time.perf_counter() - started < 7.0
    time.sleep(max(0.0, 10.0 - (time.perf_counter() - started)))
    assert not list(tmp_path.glob("finished-*"))


@pytest.mark.parametrize("cpus", [1, 2])
def test_the_default_workers_are_the_cpus_this_process_may_run_on(monkeypatch, cpus):
    monkeypatch.setattr("cphysfno_core.data.executors.usable_cpus", lambda: cpus)
    pids = {}
    run_tasks(os.getpid, [0, 1], lambda key: (), DataConfig(), pids.__setitem__)
    # one CPU: the chunks run in this process; two: in two worker processes
    in_this_process = [pid == os.getpid() for pid in pids.values()]
    assert in_this_process == [cpus == 1] * 2
