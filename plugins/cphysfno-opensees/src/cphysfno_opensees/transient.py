"""Step an OpenSees transient analysis, recovering from steps that do not converge.

A step that fails with the caller's solution algorithm is tried again with a ladder of
algorithms, then with the step split into 2, 4 and 8 substeps (each substep again trying
the whole ladder); after every step the caller's algorithm is restored. OpenSees reverts
the domain to its last committed state when a step fails, so a retry starts from where the
failed attempt did.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

LADDER: tuple[tuple[Any, ...], ...] = (
    ("Newton",),
    ("NewtonLineSearch",),
    ("KrylovNewton",),
    ("ModifiedNewton",),
)
"""Algorithms tried, in order, on a step that did not converge (``ops.algorithm`` args)."""

SPLITS = (2, 4, 8)
"""Substeps a failed step is split into, in order, once the ladder fails at the full step."""


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
    abandon: Callable[[np.ndarray], bool] | None = None,
    check_every: int = 100,
    leap: Callable[[int], np.ndarray | None] | None = None,
) -> np.ndarray:
    """Run an already-defined transient analysis for ``n_steps`` steps of ``dt`` s.

    The caller sets up the model, the ground-motion pattern, constraints, numberer,
    system, test, integrator and ``ops.analysis("Transient")``. A step that fails is
    retried with :data:`LADDER` (Newton, NewtonLineSearch, KrylovNewton, ModifiedNewton;
    the caller's own algorithm is skipped at the full step, where it has just failed), then
    with the step split into 2, 4 and 8 substeps, each substep trying the whole ladder.
    The caller's algorithm is set again after a recovered step.

    Args:
        ops: the ``openseespy.opensees`` module (from
            :func:`cphysfno_opensees.loader.import_opensees`).
        n_steps: number of steps.
        dt: step in s.
        read: returns the ``n_out`` quantities to record (e.g. displacements in m).
        algorithm: the ``ops.algorithm`` arguments the caller set (OpenSees cannot be
            asked), restored after a recovered step.
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
        AnalysisFailed: a step that nothing on the ladder could complete, with the time at
            its start, what was tried and the rows recorded before it (``history``).
        Abandoned: ``abandon`` returned True.
    """
    algorithm = tuple(algorithm)
    first = np.asarray(read(), dtype=np.float64)
    out = np.empty((n_steps + 1, first.size))
    out[0] = first
    k = checked = 0
    while k < n_steps:
        k += 1
        if ops.analyze(1, dt) != 0:
            try:
                _recover(ops, dt, algorithm)
            except AnalysisFailed as failure:
                failure.history = out[:k].copy()
                raise
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


def _recover(ops: Any, dt: float, algorithm: tuple[Any, ...]) -> None:
    """Complete a step of ``dt`` that failed with ``algorithm``, or raise AnalysisFailed."""
    start = ops.getTime()
    remaining = dt
    try:
        for substeps in (1, *SPLITS):
            h = dt / substeps
            rungs = [r for r in LADDER if r != algorithm] if substeps == 1 else list(LADDER)
            while remaining > 0.5 * h:
                if not _step_with_ladder(ops, h, rungs):
                    break
                remaining -= h
            if remaining <= 0.5 * dt / SPLITS[-1]:
                return
    finally:
        ops.algorithm(*algorithm)
    names = ", ".join(r[0] for r in LADDER)
    raise AnalysisFailed(
        start,
        f"{names} at dt = {dt:g} s and at dt/{', dt/'.join(str(s) for s in SPLITS)}",
    )


def _step_with_ladder(ops: Any, h: float, rungs: list[tuple[Any, ...]]) -> bool:
    """One step of ``h`` s with the first algorithm of ``rungs`` that converges."""
    for rung in rungs:
        ops.algorithm(*rung)
        if ops.analyze(1, h) == 0:
            return True
    return False
