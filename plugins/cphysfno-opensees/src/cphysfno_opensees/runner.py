"""Run one OpenSees analysis per record in fresh worker processes.

OpenSees keeps global state, leaks memory across ``ops.wipe()`` and can crash the process
on a bad model state, so every record is analysed in a worker process: each worker starts
with no OpenSees model, is retired after a number of records, and is replaced when it
dies; a record whose worker dies is reported as failed and the others go on. A record
whose analysis does not converge collapsed the structure: it comes back with its history
up to the step that failed. What OpenSees prints while a record is analysed comes back
with it instead of reaching the terminal, and so does the hardest rung of the convergence
ladder its analysis needed.

Workers are forked from a fork server (``multiprocessing`` start method ``forkserver``,
where the platform has it, ``spawn`` elsewhere) that has imported this module and so the
core package once: a new worker then starts in milliseconds instead of the seconds a
fresh interpreter needs to import PyTorch. The fork server never builds a model, so a
worker inherits no OpenSees state. The analysis function travels pickled, with the
caller's ``sys.path``, so a function the fork server cannot import yet is still found.
"""

from __future__ import annotations

import logging
import multiprocessing
import pickle
import signal
import sys
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from typing import Any, TypeVar

import numpy as np

from cphysfno_core import CphysfnoError, InputError, PluginError
from cphysfno_core.plugin import check_main_guard

from .messages import recording
from .transient import AnalysisFailed, counting

logger = logging.getLogger(__name__)

Analyse = Callable[[np.ndarray, float], np.ndarray]
T = TypeVar("T")


@dataclass(frozen=True)
class RecordRuns:
    """What :func:`run_records` found for every record.

    Attributes:
        displacement: ``[n, T, n_outputs]`` float64: each record's response; NaN rows for
            a failed record and after the step at which a collapsed one stopped.
        failures: record index -> why it failed (its worker died).
        collapsed: ``[n]`` bool, the records whose analysis did not converge.
        collapse_causes: record index -> what did not converge, for the collapsed ones
            (``"did not converge at t = 12.34 s after ..."``).
        messages: record index -> what OpenSees printed while analysing it, for the
            records it printed anything for.
        recoveries: record index -> the hardest rung of the convergence ladder its
            analysis needed (:attr:`~cphysfno_opensees.transient.Recovery.hardest`), for
            the records that needed one.
    """

    displacement: np.ndarray
    failures: dict[int, str]
    collapsed: np.ndarray
    collapse_causes: dict[int, str]
    messages: dict[int, str]
    recoveries: dict[int, str]


def run_records(
    analyse: Analyse,
    acceleration: np.ndarray,
    dt: float,
    n_outputs: int,
    *,
    workers: int = 1,
    records_per_worker: int = 20,
    description: str = "",
) -> RecordRuns:
    """Run ``analyse(a_g, dt)`` for every record, each in a spawned worker process.

    Args:
        analyse: ``analyse(a_g [T] m/s^2, dt s) -> [T, n_outputs]`` (m), picklable (a
            module-level function or a ``functools.partial`` of one). It raises
            :class:`~cphysfno_opensees.transient.AnalysisFailed` when the analysis does not
            converge: that record collapsed (its rows before the failure are the
            exception's ``history``, where it has one), and the others go on.
        acceleration: ``[n, T]`` ground accelerations in m/s^2.
        dt: time step of the records in s.
        n_outputs: columns ``analyse`` returns per sample (the outputs' displacements,
            and for a structure that records them their accelerations after them).
        workers: worker processes run in parallel.
        records_per_worker: records a worker analyses before it is replaced by a fresh one
            (bounds the memory OpenSees leaks).
        description: what is analysed, for the progress log (logger
            ``cphysfno_opensees.runner``, level INFO).

    Returns:
        :class:`RecordRuns`: the responses, the failed records (a worker died), the
        collapsed ones, what OpenSees printed for each record and the hardest rung of the
        convergence ladder each needed.

    Raises:
        InputError: ``acceleration`` is not ``[n, T]``, or ``workers`` or
            ``records_per_worker`` is below 1.
        PluginError: ``analyse`` raised anything but AnalysisFailed (a bug, not a property
            of the record), or returned the wrong shape; the message holds its traceback.
            Also when called in a daemonic process, which may not start workers (a Dask
            worker started with ``distributed.worker.daemon: true``); the message says how
            to configure the workers.
        MainGuardError: called from the top-level code of a script, which every worker
            would run again (the message says to put it under ``if __name__ ==
            "__main__":``).
    """
    _check_workers_allowed(description)
    acceleration = np.asarray(acceleration, dtype=np.float64)
    if acceleration.ndim != 2:
        raise InputError(f"acceleration must be [n_records, n_steps], got {acceleration.shape}")
    if workers < 1 or records_per_worker < 1:
        raise InputError(
            f"workers and records_per_worker must be >= 1, got {workers} and {records_per_worker}"
        )
    n, n_steps = acceleration.shape
    u = np.full((n, n_steps, n_outputs), np.nan)
    failures: dict[int, str] = {}
    collapsed = np.zeros(n, dtype=bool)
    causes: dict[int, str] = {}
    messages: dict[int, str] = {}
    recoveries: dict[int, str] = {}
    todo = list(range(n - 1, -1, -1))
    pool: list[_Worker] = []
    context = _context()
    blob = pickle.dumps(analyse)
    progress = _Progress(n, description)
    try:
        while todo or pool:
            for worker in pool:
                spent = worker.done >= records_per_worker or not worker.process.is_alive()
                if worker.busy is None and (spent or not todo):
                    worker.stop()
            pool = [w for w in pool if w.busy is not None or w.running]
            while todo and len(pool) < workers:
                pool.append(_Worker.start(context, blob, dt))
            for worker in pool:
                if todo and worker.busy is None:
                    worker.send(todo.pop(), acceleration)
            for index, outcome, said, hardest in _collect(pool):
                if said:
                    messages[index] = said
                if hardest:
                    recoveries[index] = hardest
                if isinstance(outcome, np.ndarray):
                    _check_shape(outcome, (n_steps, n_outputs))
                    u[index] = outcome
                elif isinstance(outcome, _Collapse):
                    collapsed[index], causes[index] = True, outcome.cause
                    if outcome.history is not None:
                        rows = outcome.history[:n_steps]
                        _check_shape(rows, (len(rows), n_outputs))
                        u[index, : len(rows)] = rows
                else:
                    failures[index] = outcome
                progress.tick(index in failures, collapsed[index])
    finally:
        for worker in pool:
            worker.stop()
    return RecordRuns(
        u,
        dict(sorted(failures.items())),
        collapsed,
        dict(sorted(causes.items())),
        messages,
        dict(sorted(recoveries.items())),
    )


def call_in_worker(function: Callable[..., T], *args: Any, description: str = "") -> T:
    """``function(*args)`` run in a fresh worker process (as :func:`run_records` starts
    them), its result returned: OpenSees state, crashes and ``exit`` calls stay there.

    Args:
        function: picklable (module level, or a ``functools.partial`` of such a function),
            as are ``args`` and its result.
        description: what it does, for the messages.

    Raises:
        CphysfnoError: the one ``function`` raised (re-raised here as it was).
        PluginError: ``function`` raised another exception (the message holds its
            traceback), or its process died (the message says how).
        MainGuardError: as for :func:`run_records`.
    """
    _check_workers_allowed(description)
    context = _context()
    parent, child = context.Pipe()
    task = pickle.dumps((function, args))
    process = context.Process(target=_call, args=(child, task, list(sys.path)), daemon=True)
    process.start()
    child.close()
    try:
        wait([parent, process.sentinel])
        outcome = None
        if parent.poll():
            try:
                outcome = parent.recv()
            except (EOFError, OSError):
                outcome = None
        if outcome is None:
            process.join()
            raise PluginError(f"{description or 'a worker'}: {_death_cause(process)}")
        kind, value = outcome
    finally:
        if process.is_alive():
            process.kill()
        process.join()
        parent.close()
    if kind == "result":
        return value
    if kind == "error":
        raise value
    raise PluginError(f"{description or 'a worker'} raised:\n{value}")


def _call(connection: Connection, task: bytes, path: list[str]) -> None:
    """Worker of :func:`call_in_worker`: run the task, send ``(kind, value)`` back."""
    sys.path[:] = path
    try:
        function, args = pickle.loads(task)
        outcome: tuple[str, Any] = ("result", function(*args))
    except CphysfnoError as error:
        outcome = ("error", error)
    except Exception:  # noqa: BLE001 - sent to the parent, which raises it
        outcome = ("bug", traceback.format_exc())
    try:
        connection.send(outcome)
    except Exception:  # noqa: BLE001 - an unpicklable result or error
        connection.send(("bug", traceback.format_exc()))
    connection.close()


def _check_workers_allowed(description: str) -> None:
    """Raise unless this process may start worker processes (see :func:`run_records`)."""
    if multiprocessing.current_process().daemon:
        raise PluginError(
            "OpenSees analyses run in worker processes, which this daemonic process may not "
            "start: run Dask workers with distributed.worker.daemon = False (environment "
            "DASK_DISTRIBUTED__WORKER__DAEMON=False, or `dask worker --no-nanny`); "
            "cphysfno's own LocalCluster already does"
        )
    check_main_guard(f"{description or 'the OpenSees analysis'}")


@dataclass(eq=False)
class _Worker:
    """A worker process analysing records sent over its pipe, one at a time.

    Attributes:
        busy: index of the record it is analysing, or None.
        done: records sent to it so far.
    """

    process: multiprocessing.process.BaseProcess
    connection: Connection
    busy: int | None = None
    done: int = 0

    @classmethod
    def start(cls, context, analyse: bytes, dt: float) -> _Worker:
        parent, child = context.Pipe()
        arguments = (child, analyse, dt, list(sys.path))
        process = context.Process(target=_serve, args=arguments, daemon=True)
        process.start()
        child.close()
        return cls(process, parent)

    @property
    def running(self) -> bool:
        return not self.connection.closed and self.process.is_alive()

    def send(self, index: int, acceleration: np.ndarray) -> None:
        self.connection.send((index, acceleration[index]))
        self.busy = index
        self.done += 1

    def stop(self) -> None:
        """End the process: politely when idle, at once when it is busy."""
        if self.connection.closed:
            return
        if self.busy is None:
            try:
                self.connection.send(None)
            except OSError:
                pass
            self.process.join(timeout=5.0)
        if self.process.is_alive():
            self.process.kill()
        self.process.join()
        self.connection.close()


def _collect(
    pool: list[_Worker],
) -> list[tuple[int, np.ndarray | _Collapse | str, str, str | None]]:
    """Wait until at least one busy worker answers or dies; each such record's outcome,
    what OpenSees printed while it was analysed and the hardest rung of the convergence
    ladder it needed (None: none, or its worker died).

    Each such worker becomes idle (a dead one is then replaced by the caller).
    """
    busy = [w for w in pool if w.busy is not None]
    if not busy:
        return []
    ready = set(wait([w.connection for w in busy] + [w.process.sentinel for w in busy]))
    outcomes = []
    for worker in busy:
        if worker.connection not in ready and worker.process.sentinel not in ready:
            continue
        index, outcome, said, hardest = worker.busy, None, "", None
        if worker.connection.poll():
            try:
                index, outcome, said, hardest = worker.connection.recv()
            except (EOFError, OSError):
                pass
        if outcome is None:
            if worker.process.is_alive():
                continue
            outcome = _death(worker)
        if isinstance(outcome, _Bug):
            raise PluginError(f"analysis of record {index} raised:\n{outcome.text}")
        worker.busy = None
        outcomes.append((index, outcome, said, hardest))
    return outcomes


def _death(worker: _Worker) -> str:
    """Why a record's worker ended without answering, in words."""
    worker.process.join()
    return f"{_death_cause(worker.process)} while analysing this record"


def _death_cause(process: multiprocessing.process.BaseProcess) -> str:
    """How a worker process that has ended without answering ended, in words."""
    code = process.exitcode
    if code is not None and code < 0:
        try:
            cause = f"signal {signal.Signals(-code).name}"
        except ValueError:
            cause = f"signal {-code}"
    else:
        cause = f"exit code {code}"
    return f"the OpenSees worker process died ({cause})"


def _check_shape(values: np.ndarray, shape: tuple[int, int]) -> None:
    if values.shape != shape:
        raise PluginError(f"an analysis returned shape {values.shape}, expected {shape}")


@dataclass(frozen=True)
class _Collapse:
    """An analysis that did not converge: its cause and the rows it recorded before."""

    cause: str
    history: np.ndarray | None


@dataclass(frozen=True)
class _Bug:
    """An exception other than AnalysisFailed, with its traceback, sent to the parent."""

    text: str


def _context() -> multiprocessing.context.BaseContext:
    """The fork server (this module preloaded) where the platform has one, else spawn."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload([__name__])
    return context


def _serve(connection: Connection, analyse: bytes, dt: float, path: list[str]) -> None:
    """Worker loop: analyse each ``(index, a_g)`` received until ``None`` arrives, and
    send back ``(index, outcome, what OpenSees printed, the hardest rung of the
    convergence ladder)``.

    ``analyse`` is the pickled analysis function, unpickled once ``sys.path`` is the
    caller's ``path``.
    """
    sys.path[:] = path
    analyse = pickle.loads(analyse)
    while True:
        try:
            task = connection.recv()
        except EOFError:
            return
        if task is None:
            return
        index, record = task
        with recording() as said, counting() as recovery:
            try:
                outcome: np.ndarray | _Collapse | _Bug = np.asarray(
                    analyse(record, dt), dtype=np.float64
                )
            except AnalysisFailed as failure:
                history = failure.history
                outcome = _Collapse(
                    str(failure), None if history is None else np.asarray(history, np.float64)
                )
            except Exception:  # noqa: BLE001 - sent to the parent, which raises it
                outcome = _Bug(traceback.format_exc())
        connection.send((index, outcome, said.getvalue(), recovery.hardest))


class _Progress:
    """Logs the records done and the seconds per record, about every 30 s."""

    def __init__(self, total: int, description: str) -> None:
        self.total, self.description = total, description or "OpenSees analyses"
        self.done = self.failed = self.collapsed = 0
        self.started = self.logged = time.perf_counter()

    def tick(self, failed: bool, collapsed: bool) -> None:
        self.done += 1
        self.failed += failed
        self.collapsed += collapsed
        now = time.perf_counter()
        if now - self.logged >= 30.0 or self.done == self.total:
            self.logged = now
            logger.info(
                "%s: %d/%d records (%d collapsed, %d failed), %.2f s per record",
                self.description,
                self.done,
                self.total,
                self.collapsed,
                self.failed,
                (now - self.started) / self.done,
            )
