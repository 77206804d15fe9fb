"""Time-history analysis of the SAC frame under one ground-motion record.

:func:`analyse_record` is module level so that a :func:`functools.partial` of it, with the
model and solver settings bound, is picklable and runs in the worker processes of
:func:`cphysfno_opensees.runner.run_records`.
"""

from __future__ import annotations

import dataclasses
import gc
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .loader import import_opensees
from .sac9_elastic import (
    ElasticFrame,
    FloorState,
    elastic_frame,
    elastic_response,
    first_yield_step,
    set_state,
)
from .sac9_model import FrameConfig, build_frame
from .transient import Abandoned, integrate


@dataclass(frozen=True)
class SolverConfig:
    """How the equations are solved at every step (Newmark average acceleration, the rigid
    diaphragms' ties eliminated by the Transformation handler).

    The defaults are the fastest settings measured that keep the answer within 1e-3
    (relative L2) of a tight reference: the tangent of the first step (elastic, with the
    leaning column's P-Delta) is factorised once and reused (modified Newton), so an
    elastic step costs one state determination and one back-substitution, and the step
    is accepted once the unbalanced nodal forces are below ``tolerance``. After a step
    that the retry ladder of :func:`~cphysfno_opensees.transient.integrate` completed,
    the algorithm is set anew and factorises the tangent of the next step.

    Attributes:
        system: OpenSees linear solver (``ops.system``).
        numberer: DOF numberer (``ops.numberer``). ``"Plain"`` numbers the equations in
            node-tag order, which follows the height and keeps the band narrow; ``"RCM"``
            orders the element graph, which does not see the rigid diaphragms' ties.
        test: convergence test (``ops.test``): ``"NormUnbalance"`` (N and N m) or
            ``"NormDispIncr"`` (m and rad).
        tolerance: its tolerance.
        max_iterations: iterations per step before the retry ladder takes over.
        algorithm: solution algorithm and its options (``ops.algorithm`` arguments).
        elastic_start: take the response of the fibre model up to the first step at which
            a fibre reaches :data:`ELASTIC_SHARE` of its yield stress from the exact
            condensed linear model (:mod:`~cphysfno_opensees.sac9_elastic`) and start
            OpenSees from its state there; a record that never gets that far needs no
            OpenSees analysis.
    """

    system: Literal["ProfileSPD", "BandSPD", "BandGeneral", "UmfPack"] = "ProfileSPD"
    numberer: Literal["Plain", "RCM"] = "Plain"
    test: Literal["NormUnbalance", "NormDispIncr"] = "NormUnbalance"
    tolerance: float = 100.0
    max_iterations: int = 50
    algorithm: tuple[str, ...] = ("ModifiedNewton", "-FactorOnce")
    elastic_start: bool = True


@dataclass(frozen=True)
class Rayleigh:
    """``C = mass M + stiffness K_initial`` (coefficients in 1/s and s)."""

    mass: float
    stiffness: float

    @classmethod
    def matching(cls, omega_a: float, omega_b: float, ratio: float) -> Rayleigh:
        """The coefficients that give ``ratio`` of critical damping at ``omega_a`` and
        ``omega_b`` (rad/s)."""
        total = omega_a + omega_b
        return cls(2.0 * ratio * omega_a * omega_b / total, 2.0 * ratio / total)


ELASTIC_SHARE = 0.95
"""Share of the yield stress up to which a fibre's stress is taken from the condensed linear
model when :attr:`SolverConfig.elastic_start` is on (its stresses agree with the OpenSees
model's to about 1e-5, the second-order P-Delta effect of the columns' axial forces)."""

INTERIOR_DRIFT_LIMIT = 0.015
"""Largest peak story drift ratio up to which elastic interior sections are trusted: a
record that drives a story further is analysed again with fibre sections at every
integration point. In the pushover the interior sections first yield at a story drift
ratio of 2.1 %."""


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
    converge). With ``solver.elastic_start`` (fibre model), the steps before the first
    fibre reaches :data:`ELASTIC_SHARE` of its yield stress come from the exact condensed
    linear model and OpenSees starts from its state there (:func:`elastic_start`). A model
    with elastic interior sections whose peak story drift ratio passes
    :data:`INTERIOR_DRIFT_LIMIT` is analysed again with fibres everywhere; its first
    analysis stops within 100 steps of the drift passing the limit.

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
    start = None
    if solver.elastic_start and frame_config.model == "fibre":
        start = elastic_start(frame_config, damping, acceleration, dt)
        if start.step == len(acceleration) - 1:
            return start.displacement
    if not frame_config.elastic_interior:
        return transient_response(frame_config, solver, damping, acceleration, dt, start=start)[0]
    try:
        u, heights = transient_response(
            frame_config,
            solver,
            damping,
            acceleration,
            dt,
            drift_limit=INTERIOR_DRIFT_LIMIT,
            start=start,
        )
        if peak_drift_ratio(u, heights) <= INTERIOR_DRIFT_LIMIT:
            return u
    except Abandoned:
        pass
    fibres = dataclasses.replace(frame_config, elastic_interior=False)
    return transient_response(fibres, solver, damping, acceleration, dt, start=start)[0]


@dataclass(frozen=True)
class ElasticStart:
    """Where OpenSees takes over from the condensed linear model.

    Attributes:
        step: the last step taken from the linear model.
        displacement: ``[step + 1, 9]`` its floor displacements up to there, m.
        state: its Newmark state of the floors at ``step``.
        model: the condensed model.
    """

    step: int
    displacement: np.ndarray
    state: FloorState
    model: ElasticFrame


def elastic_start(
    frame_config: FrameConfig, damping: Rayleigh, acceleration: np.ndarray, dt: float
) -> ElasticStart:
    """The response of the condensed linear model of the (fibre) frame up to the step
    before a fibre first reaches :data:`ELASTIC_SHARE` of its yield stress, or to the end
    of the record if none does (then ``step`` is the last step).

    Args:
        frame_config: the fibre model (either interior).
        damping: Rayleigh coefficients.
        acceleration: ``[T]`` ground acceleration, m/s^2.
        dt: time step, s.
    """
    model = elastic_frame(frame_config, damping.mass, damping.stiffness)
    u, v, a = elastic_response(model, np.asarray(acceleration, dtype=float), dt)
    first = first_yield_step(model, u, ELASTIC_SHARE)
    step = len(u) - 1 if first is None else max(first - 1, 0)
    state = FloorState(u[step], v[step], a[step])
    return ElasticStart(step, u[: step + 1], state, model)


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
    drift_limit: float | None = None,
    start: ElasticStart | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """One OpenSees analysis of the model as configured (no fallback), as
    :func:`analyse_record` describes it.

    Args:
        drift_limit: with a story drift ratio above it in any block of 100 steps, the
            analysis stops with :class:`~cphysfno_opensees.transient.Abandoned`; None: run
            to the end.
        start: the linear model's response up to a step and its state there, from which
            the analysis continues; None: from rest at the first step.

    Returns:
        ``[T, 9]`` floor displacements (m) and the ``[9]`` floor elevations above the
        ground (m).
    """
    ops = import_opensees()
    frame = build_frame(ops, frame_config)
    ops.rayleigh(damping.mass, 0.0, damping.stiffness, 0.0)
    series, pattern = 1, 1
    ops.timeSeries("Path", series, "-dt", dt, "-values", *np.asarray(acceleration, dtype=float))
    ops.pattern("UniformExcitation", pattern, 1, "-accel", series)
    first = 0
    if start is not None:
        first = start.step
        ops.setTime(first * dt)
        set_state(ops, start.model, start.state)
    configure_solver(ops, solver)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    floors = frame.floors

    def read() -> list[float]:
        return [ops.nodeDisp(node, 1) for node in floors]

    def past_limit(rows: np.ndarray) -> bool:
        return peak_drift_ratio(rows, frame.heights) > drift_limit

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
            abandon=None if drift_limit is None else past_limit,
        )
    finally:
        if collecting:
            gc.enable()
        ops.wipe()
    if start is not None:
        u = np.concatenate([start.displacement, u[1:]])
    return u, frame.heights


def configure_solver(ops: Any, solver: SolverConfig) -> None:
    """Constraints, numberer, system, test and algorithm of an analysis."""
    ops.constraints("Transformation")
    ops.numberer(solver.numberer)
    ops.system(solver.system)
    ops.test(solver.test, solver.tolerance, solver.max_iterations)
    ops.algorithm(*solver.algorithm)
