"""Where simulation chunks run: in this process, in local worker processes, or on a Dask
cluster. Every executor hands each result to the caller as soon as it is ready, keeps a
bounded number of chunks in flight (memory does not grow with the dataset), and gives the
same results: what a chunk computes depends on its records only, never on its worker.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
from collections.abc import Callable, Sequence
from contextlib import contextmanager
from typing import Any

from ..config.experiment import DataConfig
from ..signals.cpus import usable_cpus
from ..signals.errors import ConfigError, check_main_guard


def _windowed(
    submit: Callable[..., Any],
    wait_any: Callable[[set], tuple[set, set]],
    function: Callable[..., Any],
    keys: Sequence[int],
    arguments_of: Callable[[int], tuple[Any, ...]],
    window: int,
    on_result: Callable[[int, Any], None],
) -> None:
    pending: dict[Any, int] = {}

    def drain(until: int) -> None:
        while len(pending) > until:
            done, _ = wait_any(set(pending))
            for future in done:
                on_result(pending.pop(future), future.result())

    for key in keys:
        pending[submit(function, *arguments_of(key), key=key)] = key
        drain(window - 1)
    drain(0)


@contextmanager
def _dask_client(settings: DataConfig):
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ConfigError(
            "data.executor = 'dask' needs the distributed package: pip install 'dask[distributed]'"
        ) from None
    if settings.address:
        with Client(settings.address) as client:
            yield client
        return
    import dask

    workers = settings.workers or usable_cpus()
    # Non-daemonic workers, so that a structure may run its records in child processes.
    with (
        dask.config.set({"distributed.worker.daemon": False}),
        LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        yield client


def _stop_workers(pool: concurrent.futures.ProcessPoolExecutor) -> None:
    """Terminate the pool's worker processes, so that a failed or interrupted run leaves no
    task running on (the executor's own shutdown would wait for every running task)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()


def run_tasks(
    function: Callable[..., Any],
    keys: Sequence[int],
    arguments_of: Callable[[int], tuple[Any, ...]],
    settings: DataConfig,
    on_result: Callable[[int, Any], None],
) -> None:
    """Run ``function(*arguments_of(key))`` for every key on the executor of ``settings``
    and call ``on_result(key, result)`` in the order results arrive.

    Arguments are built only when their task is submitted, so the inputs of the tasks
    not yet in flight need not exist in memory.

    A task whose Dask worker dies is run again elsewhere (``settings.retries`` times);
    any other failure propagates. When a task fails or the caller is interrupted, local
    worker processes are terminated rather than left to finish their tasks.
    """
    workers = settings.workers or usable_cpus()
    if settings.executor == "serial" or (
        settings.executor == "processes" and (len(keys) <= 1 or workers == 1)
    ):
        for key in keys:
            on_result(key, function(*arguments_of(key)))
        return
    window = 2 * workers
    if settings.executor == "processes":
        check_main_guard("simulating the records on local processes (data.executor)")
        context = multiprocessing.get_context("spawn")
        with concurrent.futures.ProcessPoolExecutor(
            max_workers=min(workers, len(keys)), mp_context=context
        ) as pool:

            def submit(fn, *arguments, key):
                return pool.submit(fn, *arguments)

            def wait_any(futures):
                return concurrent.futures.wait(
                    futures, return_when=concurrent.futures.FIRST_COMPLETED
                )

            try:
                _windowed(submit, wait_any, function, keys, arguments_of, window, on_result)
            except BaseException:
                _stop_workers(pool)
                raise
        return
    from distributed import wait

    with _dask_client(settings) as client:

        def submit(fn, *arguments, key):
            return client.submit(fn, *arguments, pure=False, retries=settings.retries)

        def wait_any(futures):
            return wait(list(futures), return_when="FIRST_COMPLETED")

        _windowed(submit, wait_any, function, keys, arguments_of, window, on_result)
