"""Time-history analysis of the SAC frame under one ground-motion record.

:func:`analyse_record` is module level so that a :func:`functools.partial` of it, with the
model and solver settings bound, is picklable and runs in the worker processes of
:func:`cphysfno_opensees.runner.run_records`.
"""

from __future__ import annotations

import dataclasses
import gc
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from threadpoolctl import threadpool_limits

from cphysfno_core.plugin import Rayleigh

from ..convergence import ConvergenceParams
from ..loader import import_opensees
from ..transient import Abandoned, AnalysisFailed, integrate
from .elastic import elastic_frame, set_state
from .interior import InteriorSections
from .model import FrameConfig, build_frame
from .phases import TRY_EVERY, ElasticLeaps, ElasticStart, elastic_start


@dataclass(frozen=True)
class SolverConfig:
    """How the equations are solved at every step (Newmark average acceleration, the rigid
    diaphragms' ties eliminated by the Transformation handler).

    The defaults are the fastest settings measured that keep the answer within 1e-3
    (relative L2) of a tight reference: the elastic phases come from the condensed model
    (``elastic_phases``), so OpenSees takes the yielding steps, for which full Newton is
    1.4 times faster than a tangent factorised once (modified Newton, the faster choice
    when OpenSees took every step); a step is accepted once the unbalanced nodal forces
    are below ``tolerance``. A step that does not converge climbs the ladder
    ``convergence`` of :func:`~cphysfno_opensees.transient.integrate`, after which the
    algorithm and the test are set anew.

    Attributes:
        system: OpenSees linear solver (``ops.system``).
        numberer: DOF numberer (``ops.numberer``). ``"Plain"`` numbers the equations in
            node-tag order, which follows the height and keeps the band narrow; ``"RCM"``
            orders the element graph, which does not see the rigid diaphragms' ties.
        test: convergence test (``ops.test``): ``"NormUnbalance"`` (N and N m) or
            ``"NormDispIncr"`` (m and rad).
        tolerance: its tolerance.
        max_iterations: iterations per step before the convergence ladder takes over.
        algorithm: solution algorithm and its options (``ops.algorithm`` arguments).
        convergence: the convergence ladder.
        elastic_phases: fibre model: take the phases in which every fibre stays within
            ``ELASTIC_SHARE`` of its elastic range from the exact condensed linear model
            (:mod:`~cphysfno_opensees.sac9.phases`) and run OpenSees only between them:
            from rest to the first step at which a fibre nears yield (a record that never
            gets there needs no OpenSees analysis), and, every ``TRY_EVERY`` steps of
            OpenSees, across whatever elastic phase lies ahead.
    """

    system: Literal["ProfileSPD", "BandSPD", "BandGeneral", "UmfPack"] = "ProfileSPD"
    numberer: Literal["Plain", "RCM"] = "Plain"
    test: Literal["NormUnbalance", "NormDispIncr"] = "NormUnbalance"
    tolerance: float = 100.0
    max_iterations: int = 50
    algorithm: tuple[str, ...] = ("Newton",)
    convergence: ConvergenceParams = field(default_factory=ConvergenceParams)
    elastic_phases: bool = True

    @property
    def test_command(self) -> tuple[str, float, int]:
        """The ``ops.test`` arguments."""
        return (self.test, self.tolerance, self.max_iterations)


INTERIOR_DRIFT_LIMIT = 0.015
"""Story drift ratio up to which elastic interior sections are trusted without a check:
at every step at which a story drifts further, the stresses of their outermost fibres are
checked, and a record that would yield one is analysed again with fibre sections at every
integration point. In the pushover the interior sections first yield at a story drift
ratio of 2.1 %; on the 400 records of the Example 3 CPU set, not below 1.84 %."""


def analyse_record(
    frame_config: FrameConfig,
    solver: SolverConfig,
    damping: Rayleigh,
    acceleration: np.ndarray,
    dt: float,
) -> np.ndarray:
    """Floor displacements of the frame under one record, from rest.

    The ground acceleration is linear between samples and the equations are integrated
    with Newmark's average acceleration rule at ``dt``, one step per sample, through
    :func:`cphysfno_opensees.transient.integrate` (which retries a step that does not
    converge). With ``solver.elastic_phases`` (fibre model), the elastic phases come from
    the exact condensed linear model (:mod:`~cphysfno_opensees.sac9.phases`): the steps
    before the first fibre nears yield, and those after a yield in which no fibre does. A
    model with elastic interior sections that one of them would yield under (checked at
    every step at which a story drift ratio passes :data:`INTERIOR_DRIFT_LIMIT`) is
    analysed again with fibres everywhere; its first analysis stops at that step.

    Args:
        frame_config: the model.
        solver: the solver settings.
        damping: Rayleigh coefficients on the mass and the initial stiffness.
        acceleration: ``[T]`` ground acceleration in m/s^2.
        dt: its time step in s.

    Returns:
        ``[T, 9]`` horizontal displacements of levels 2 ... roof relative to the ground, m.

    Raises:
        AnalysisFailed: a step that nothing could complete.
    """
    # The analysis is one thread; the condensed model's small matrix products would only
    # wait on BLAS threads competing with the OpenSees libraries' own (measured: 30 % of
    # the time of a yielding record).
    with threadpool_limits(limits=1):
        start = None
        if solver.elastic_phases and frame_config.model == "fibre":
            start = elastic_start(frame_config, damping, acceleration, dt)
            if start.step == len(acceleration) - 1:
                return start.displacement
        if not frame_config.elastic_interior:
            return transient_response(frame_config, solver, damping, acceleration, dt, start=start)[
                0
            ]
        try:
            return transient_response(
                frame_config, solver, damping, acceleration, dt, guard_interior=True, start=start
            )[0]
        except Abandoned:
            pass
        fibres = dataclasses.replace(frame_config, elastic_interior=False)
        return transient_response(fibres, solver, damping, acceleration, dt, start=start)[0]


def peak_drift_ratio(u: np.ndarray, heights: np.ndarray) -> float:
    """Largest absolute story drift over story height of floor displacements ``u [T, n]``
    (m) at elevations ``heights [n]`` (m above the ground)."""
    drift = np.diff(u, axis=1, prepend=0.0)
    story = np.diff(heights, prepend=0.0)
    return float(np.max(np.abs(drift) / story))


def transient_response(
    frame_config: FrameConfig,
    solver: SolverConfig,
    damping: Rayleigh,
    acceleration: np.ndarray,
    dt: float,
    guard_interior: bool = False,
    start: ElasticStart | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """One OpenSees analysis of the model as configured (no fallback), as
    :func:`analyse_record` describes it.

    Args:
        guard_interior: at every step at which a story drift ratio passes
            :data:`INTERIOR_DRIFT_LIMIT`, check the outermost fibres of the elastic
            interior sections and stop with :class:`~cphysfno_opensees.transient.Abandoned`
            at the first that reaches its yield stress.
        start: the linear model's response up to a step and its state there, from which
            the analysis continues; None: from rest at the first step.

    Returns:
        ``[T, 9]`` floor displacements (m) and the ``[9]`` floor elevations above the
        ground (m).
    """
    leaps = solver.elastic_phases and frame_config.model == "fibre"
    # Before the model is built: the condensed model is made from analyses of its own.
    model = elastic_frame(frame_config, damping) if leaps else None
    ops = import_opensees()
    frame = build_frame(ops, frame_config)
    ops.rayleigh(damping.mass_factor, 0.0, damping.stiffness_factor, 0.0)
    series, pattern = 1, 1
    ops.timeSeries("Path", series, "-dt", dt, "-values", *np.asarray(acceleration, dtype=float))
    ops.pattern("UniformExcitation", pattern, 1, "-accel", series)
    first = 0
    if start is not None:
        first = start.step
        ops.setTime(first * dt)
        set_state(ops, start.model, start.state)
    start_analysis(ops, solver)
    floors = frame.floors
    leap = None
    if model is not None:
        leap = ElasticLeaps(
            ops, model, lambda: start_analysis(ops, solver), acceleration, dt, first, floors
        )

    interior = InteriorSections.of(frame, frame_config) if guard_interior else None
    drift_limits = INTERIOR_DRIFT_LIMIT * np.diff(frame.heights, prepend=0.0)

    def read() -> list[float]:
        row = [ops.nodeDisp(node, 1) for node in floors]
        if interior is not None:
            below = [0.0, *row[:-1]]
            past = any(abs(u - v) > h for u, v, h in zip(row, below, drift_limits, strict=True))
            if past and interior.past_yield(ops, 1.0):
                raise Abandoned(ops.getTime())
        return row

    # The loop makes no reference cycles; the collector would only walk the heap of the
    # worker (torch included) every few hundred steps, about a sixth of the run time.
    collecting = gc.isenabled()
    gc.disable()
    try:
        u = integrate(
            ops,
            len(acceleration) - 1 - first,
            dt,
            read,
            algorithm=solver.algorithm,
            test=solver.test_command,
            convergence=solver.convergence,
            leap=leap,
            check_every=TRY_EVERY,
        )
    except AnalysisFailed as failure:
        if start is not None and failure.history is not None:
            failure.history = np.concatenate([start.displacement, failure.history[1:]])
        raise
    finally:
        if collecting:
            gc.enable()
        ops.wipe()
    if start is not None:
        u = np.concatenate([start.displacement, u[1:]])
    return u, frame.heights


def start_analysis(ops: Any, solver: SolverConfig) -> None:
    """The transient analysis of the defined model: :func:`configure_solver`, Newmark's
    average acceleration rule."""
    configure_solver(ops, solver)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def configure_solver(ops: Any, solver: SolverConfig) -> None:
    """Constraints, numberer, system, test and algorithm of an analysis."""
    ops.constraints("Transformation")
    ops.numberer(solver.numberer)
    ops.system(solver.system)
    ops.test(*solver.test_command)
    ops.algorithm(*solver.algorithm)
