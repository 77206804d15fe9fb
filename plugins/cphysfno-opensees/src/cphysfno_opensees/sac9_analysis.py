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
from threadpoolctl import threadpool_limits

from .loader import import_opensees
from .sac9_elastic import (
    ElasticFrame,
    FloorState,
    InteriorSections,
    elastic_frame,
    elastic_response,
    fibre_centres,
    first_step_beyond,
    newmark_floors,
    set_state,
)
from .sac9_model import FrameConfig, build_frame
from .transient import Abandoned, integrate


@dataclass(frozen=True)
class SolverConfig:
    """How the equations are solved at every step (Newmark average acceleration, the rigid
    diaphragms' ties eliminated by the Transformation handler).

    The defaults are the fastest settings measured that keep the answer within 1e-3
    (relative L2) of a tight reference: the elastic phases come from the condensed model
    (``elastic_phases``), so OpenSees takes the yielding steps, for which full Newton is
    1.4 times faster than a tangent factorised once (modified Newton, the faster choice
    when OpenSees took every step); a step is accepted once the unbalanced nodal forces
    are below ``tolerance``. After a step that the retry ladder of
    :func:`~cphysfno_opensees.transient.integrate` completed, the algorithm is set anew.

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
        elastic_phases: fibre model: take the phases in which every fibre stays within
            :data:`ELASTIC_SHARE` of its elastic range from the exact condensed linear
            model (:mod:`~cphysfno_opensees.sac9_elastic`) and run OpenSees only between
            them: from rest to the first step at which a fibre nears yield (a record that
            never gets there needs no OpenSees analysis), and, every :data:`CHECK_EVERY` steps of
            OpenSees, across whatever elastic phase lies ahead.
    """

    system: Literal["ProfileSPD", "BandSPD", "BandGeneral", "UmfPack"] = "ProfileSPD"
    numberer: Literal["Plain", "RCM"] = "Plain"
    test: Literal["NormUnbalance", "NormDispIncr"] = "NormUnbalance"
    tolerance: float = 100.0
    max_iterations: int = 50
    algorithm: tuple[str, ...] = ("Newton",)
    elastic_phases: bool = True


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


ELASTIC_SHARE = 0.99
"""Share of its elastic range up to which a fibre's stress is taken from the condensed
linear model when :attr:`SolverConfig.elastic_phases` is on (its stresses agree with the
OpenSees model's to about 1e-3 of the largest: the second-order P-Delta moments of the
columns' axial forces)."""

SHORTEST_LEAP = 50
"""Fewest steps of an elastic phase worth taking from the condensed model after a yield."""

CHECK_EVERY = 25
"""Steps of OpenSees between the drift-limit checks and between attempts to take an elastic
phase from the condensed model."""

LEAP_WINDOW = 256
"""Steps of an elastic phase computed at a time."""

SETTLING_STEPS = 10
"""Steps before the end of an elastic phase at which OpenSees takes over again, so that the
massless rotations, set from the condensed model, settle before any fibre nears yield."""

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
    converge). With ``solver.elastic_phases`` (fibre model), the steps before the first
    fibre reaches :data:`ELASTIC_SHARE` of its yield stress come from the exact condensed
    linear model and OpenSees starts from its state there (:func:`elastic_start`), and the
    later elastic phases are taken from it too (:class:`ElasticLeaps`). A model with
    elastic interior sections that one of them would yield under (checked at every step
    at which a story drift ratio passes :data:`INTERIOR_DRIFT_LIMIT`) is analysed again
    with fibres everywhere; its first analysis stops at that step.

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
        return _analyse_record(frame_config, solver, damping, acceleration, dt)


def _analyse_record(
    frame_config: FrameConfig,
    solver: SolverConfig,
    damping: Rayleigh,
    acceleration: np.ndarray,
    dt: float,
) -> np.ndarray:
    start = None
    if solver.elastic_phases and frame_config.model == "fibre":
        start = elastic_start(frame_config, damping, acceleration, dt)
        if start.step == len(acceleration) - 1:
            return start.displacement
    if not frame_config.elastic_interior:
        return transient_response(frame_config, solver, damping, acceleration, dt, start=start)[0]
    try:
        return transient_response(
            frame_config, solver, damping, acceleration, dt, guard_interior=True, start=start
        )[0]
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
    first = first_step_beyond(model, u, ELASTIC_SHARE)
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
    model = elastic_frame(frame_config, damping.mass, damping.stiffness) if leaps else None
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
    start_analysis(ops, solver)
    floors = frame.floors
    leap = None
    if model is not None:
        leap = ElasticLeaps(ops, model, solver, acceleration, dt, first, floors)

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
            leap=leap,
            check_every=CHECK_EVERY,
        )
    finally:
        if collecting:
            gc.enable()
        ops.wipe()
    if start is not None:
        u = np.concatenate([start.displacement, u[1:]])
    return u, frame.heights


class ElasticLeaps:
    """Carries an OpenSees analysis of the fibre frame across the elastic phases after a
    yield with the condensed linear model (the ``leap`` of
    :func:`~cphysfno_opensees.transient.integrate`).

    While every fibre stays elastic, the floors obey the condensed model exactly, offset by
    the restoring force at the last OpenSees step: ``M u'' + C u' + K (u - u_k) = P(t) -
    P_k + M u''_k + C u'_k`` (the massless DOFs' equilibrium, damping included, keeps the
    offset constant). From the fibres' elastic centres now (:func:`fibre_centres`), the
    model finds the step at which a fibre would leave :data:`ELASTIC_SHARE` of its elastic
    range; if that is at least :data:`SHORTEST_LEAP` steps ahead, every node is set to the
    state :data:`SETTLING_STEPS` before it (floors exact, the massless DOFs from the
    condensed model, which OpenSees corrects at its next step) and the analysis continues
    from there; if not, the next try waits until OpenSees has passed that step.

    Args:
        ops: the OpenSees module, with the analysis running.
        model: the condensed model of the analysed frame.
        solver: the solver settings, to start the analysis again after a leap.
        acceleration: ``[T]`` the whole record, m/s^2.
        dt: time step, s.
        first: the step of the record at which the analysis started.
        floors: the floors' node tags.
    """

    def __init__(
        self,
        ops: Any,
        model: ElasticFrame,
        solver: SolverConfig,
        acceleration: np.ndarray,
        dt: float,
        first: int,
        floors: list[int],
    ) -> None:
        self.ops, self.model, self.solver = ops, model, solver
        self.acceleration = np.asarray(acceleration, dtype=float)
        self.dt, self.first, self.floors = dt, first, floors
        self.next_try = first

    def __call__(self, steps_done: int) -> np.ndarray | None:
        ops, model = self.ops, self.model
        step = self.first + steps_done
        if step < self.next_try:
            return None
        if len(self.acceleration) - 1 - step < SHORTEST_LEAP + SETTLING_STEPS:
            return None
        centres = fibre_centres(ops, model)
        if np.any(np.abs(centres) >= ELASTIC_SHARE * model.yield_stress):
            return None
        u = np.array([ops.nodeDisp(node, 1) for node in self.floors])
        v = np.array([ops.nodeVel(node, 1) for node in self.floors])
        a = np.array([ops.nodeAccel(node, 1) for node in self.floors])
        du, dv, da = self._elastic_phase(step, FloorState(0.0 * u, v, a), centres)
        last = len(du) - 1
        if last < SHORTEST_LEAP:
            # A fibre nears yield within a few steps: OpenSees must take it there first.
            self.next_try = step + last + SETTLING_STEPS
            return None
        base = {node: np.asarray(ops.nodeDisp(node)) for node in model.node_map}
        set_state(ops, model, FloorState(du[last], dv[last], da[last]), base=base)
        ops.setTime((step + last) * self.dt)
        ops.wipeAnalysis()
        start_analysis(ops, self.solver)
        return u + du[1 : last + 1]

    def _elastic_phase(
        self, step: int, state: FloorState, centres: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The floors' displacement increments, velocities and accelerations from ``step``
        (row 0) to :data:`SETTLING_STEPS` before a fibre leaves :data:`ELASTIC_SHARE` of
        its elastic range, or to the end of the record; computed a window at a time."""
        model, record = self.model, self.acceleration
        offset = model.masses * state.acceleration + model.damping @ state.velocity
        columns: tuple[list[np.ndarray], ...] = ([], [], [])
        done = step
        while True:
            ground = record[done : done + LEAP_WINDOW + 1] - record[step]
            window = newmark_floors(model, offset - np.outer(ground, model.masses), self.dt, state)
            beyond = first_step_beyond(model, window[0], ELASTIC_SHARE, centres)
            keep = len(window[0]) if beyond is None else beyond
            for column, part in zip(columns, window, strict=True):
                column.append(part[(0 if done == step else 1) : keep])
            done += len(window[0]) - 1
            if beyond is not None or done >= len(record) - 1:
                break
            state = FloorState(*(part[-1] for part in window))
        du, dv, da = (np.concatenate(column) for column in columns)
        if beyond is not None:
            keep = max(len(du) - SETTLING_STEPS, 1)
            du, dv, da = du[:keep], dv[:keep], da[:keep]
        return du, dv, da


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
    ops.test(solver.test, solver.tolerance, solver.max_iterations)
    ops.algorithm(*solver.algorithm)
