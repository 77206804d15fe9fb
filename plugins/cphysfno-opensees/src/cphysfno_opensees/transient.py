"""Step an OpenSees transient analysis, recovering from steps that do not converge.

A step that fails with the caller's algorithm and test climbs the convergence ladder of
:class:`~cphysfno_opensees.convergence.ConvergenceParams` (substeps, other algorithms, a
looser test); after a recovered step the caller's algorithm and test are set again.
OpenSees reverts the domain to its last committed state when a step fails, so a retry
starts from where the failed attempt did. The steps each rung completed are counted in
the :class:`Recovery` of :func:`counting`.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .convergence import ConvergenceParams, Rung

LADDER = ConvergenceParams()
"""The default convergence ladder."""


@dataclass
class Recovery:
    """The steps that needed the convergence ladder, counted by the rung that completed
    them.

    Attributes:
        steps: rung -> steps it completed.
    """

    steps: Counter[Rung] = field(default_factory=Counter)

    @property
    def hardest(self) -> str | None:
        """The highest rung any step needed, in words; None where none needed one."""
        return max(self.steps, key=lambda rung: rung.rank).words if self.steps else None


_RECOVERY: ContextVar[Recovery | None] = ContextVar("recovery", default=None)


@contextmanager
def counting() -> Iterator[Recovery]:
    """A :class:`Recovery` that counts the recovered steps of every :func:`integrate`
    called within the block (e.g. those of one record's analysis)."""
    recovery = Recovery()
    token = _RECOVERY.set(recovery)
    try:
        yield recovery
    finally:
        _RECOVERY.reset(token)


class Abandoned(Exception):
    """The caller's ``abandon`` test of :func:`integrate` ended the analysis early.

    Attributes:
        time_s: analysis time in s when it was abandoned.
    """

    def __init__(self, time_s: float) -> None:
        self.time_s = float(time_s)
        super().__init__(f"abandoned at t = {self.time_s:.2f} s")


class AnalysisFailed(RuntimeError):
    """An OpenSees transient analysis that did not converge: the structure collapsed (or
    its model could not follow it further).

    Attributes:
        time_s: analysis time in s at the start of the step that failed.
        tried: what was tried on that step, in words.
        history: ``[k, n_out]`` the rows recorded before the step that failed, in the
            units of the analysis's outputs, where the analysis knows them; else None.
    """

    def __init__(self, time_s: float, tried: str, history: np.ndarray | None = None) -> None:
        self.time_s = float(time_s)
        self.tried = tried
        self.history = history
        super().__init__(f"did not converge at t = {self.time_s:.2f} s after {tried}")

    def __reduce__(self):
        return type(self), (self.time_s, self.tried, self.history)


def integrate(
    ops: Any,
    n_steps: int,
    dt: float,
    read: Callable[[], Sequence[float]],
    *,
    algorithm: Sequence[Any] = ("Newton",),
    test: Sequence[Any] | None = None,
    convergence: ConvergenceParams = LADDER,
    abandon: Callable[[np.ndarray], bool] | None = None,
    check_every: int = 100,
    leap: Callable[[int], np.ndarray | None] | None = None,
) -> np.ndarray:
    """Run an already-defined transient analysis for ``n_steps`` steps of ``dt`` s.

    The caller sets up the model, the ground-motion pattern, constraints, numberer,
    system, test, integrator and ``ops.analysis("Transient")``. A step that fails climbs
    the rungs of ``convergence`` (:meth:`ConvergenceParams.rungs`: the caller's
    algorithm over substeps ``dt/2``, ``dt/4``, ``dt/10``; the other algorithms at ``dt``
    and over those substeps; all again with a looser test), each rung taking the step on
    from where the one before it stopped, until one completes it. The caller's algorithm
    and test are set again after a recovered step, and the step is counted under the rung
    that completed it in the :class:`Recovery` of an enclosing :func:`counting`.

    Args:
        ops: the ``openseespy.opensees`` module (from
            :func:`cphysfno_opensees.loader.import_opensees`).
        n_steps: number of steps.
        dt: step in s.
        read: returns the ``n_out`` quantities to record (e.g. displacements in m).
        algorithm: the ``ops.algorithm`` arguments the caller set (OpenSees cannot be
            asked), restored after a recovered step.
        test: the ``ops.test`` arguments the caller set (``("NormDispIncr", 1e-8, 25)``),
            loosened by the last rungs and restored after them; None: the ladder has no
            looser-test rungs.
        convergence: the ladder.
        abandon: called every ``check_every`` steps with the ``[check_every, n_out]`` rows
            read since its last call; True stops the analysis with :class:`Abandoned`
            (for a caller that will not use the rest, e.g. a model that has left the range
            it is trusted in).
        check_every: steps between calls of ``abandon`` and of ``leap``.
        leap: called every ``check_every`` steps with the number ``k`` of steps done; it
            may advance the model itself by ``m`` steps (e.g. through a phase it can
            compute more cheaply) and return the ``[m, n_out]`` rows of those steps, or
            return None to go on step by step.

    Returns:
        ``[n_steps + 1, n_out]``: row 0 is ``read()`` before the first step, row ``k``
        after step ``k``.

    Raises:
        AnalysisFailed: a step that no rung could complete, with the time at its start,
            what was tried and the rows recorded before it (``history``).
        Abandoned: ``abandon`` returned True.
    """
    algorithm = tuple(algorithm)
    test = None if test is None else tuple(test)
    rungs = convergence.rungs(algorithm, test)
    first = np.asarray(read(), dtype=np.float64)
    out = np.empty((n_steps + 1, first.size))
    out[0] = first
    k = checked = 0
    while k < n_steps:
        k += 1
        if ops.analyze(1, dt) != 0:
            start = ops.getTime()
            rung = _recover(ops, dt, rungs, algorithm, test)
            if rung is None:
                tried = convergence.described(algorithm, test, dt)
                raise AnalysisFailed(start, tried, out[:k].copy())
            recovery = _RECOVERY.get()
            if recovery is not None:
                recovery.steps[rung] += 1
        out[k] = read()
        if k % check_every:
            continue
        if abandon is not None:
            if abandon(out[checked + 1 : k + 1]):
                raise Abandoned(ops.getTime())
            checked = k
        if leap is not None and k < n_steps:
            rows = leap(k)
            if rows is not None:
                out[k + 1 : k + 1 + len(rows)] = rows
                k += len(rows)
    return out


def _recover(
    ops: Any,
    dt: float,
    rungs: Sequence[Rung],
    algorithm: tuple[Any, ...],
    test: tuple[Any, ...] | None,
) -> Rung | None:
    """Complete a step of ``dt`` s that failed with the caller's ``algorithm`` and
    ``test`` by climbing ``rungs``; the rung that completed it, or None (the domain then
    stands where the last completed substep left it), the caller's settings set again."""
    remaining = dt
    loosened = False
    try:
        for rung in rungs:
            ops.algorithm(*rung.algorithm)
            if rung.test is not None:
                ops.test(*rung.test)
                loosened = True
            remaining = _advance(ops, dt, remaining, rung.substeps)
            if remaining == 0.0:
                return rung
    finally:
        ops.algorithm(*algorithm)
        if loosened and test is not None:
            ops.test(*test)
    return None


def _advance(ops: Any, dt: float, remaining: float, substeps: int) -> float:
    """Steps of ``dt / substeps`` s (the last one shorter where less is left) over the
    ``remaining`` s of a step of ``dt``, until one fails; the seconds still left, 0.0
    once the step is complete."""
    h = dt / substeps
    while remaining > 1e-9 * dt:
        step = min(h, remaining)
        if ops.analyze(1, step) != 0:
            return remaining
        remaining -= step
    return 0.0
