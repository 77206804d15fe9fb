"""Classical fourth-order Runge-Kutta integration of a shear building with any story law.

The law's compiled functions (:class:`cphysfno_core.plugin.LawFunctions`) are inlined into a
kernel made for them (:func:`rk4_kernel`, one per law, compiled on first use in a
process). Each record is integrated on its own in float64, records spread over the cores
in threads; after each Runge-Kutta step the law's ``settle`` corrects the state of every
story. The ground acceleration is linear between its samples.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache

import numba
import numpy as np
from cphysfno_core.plugin import LawFunctions
from cphysfno_core.signals import run_in_slices

from .chain import StoryChain

FAST = {"nogil": True, "error_model": "numpy"}
"""Compile options of a kernel made for a law: no disk cache (it cannot hold a kernel made
for functions passed in) and IEEE arithmetic (no fast-math: a law's corners, such as a
force clamped onto a branch, must see exactly the numbers it computes)."""


def integrate_chain(
    chain: StoryChain,
    functions: LawFunctions,
    n_states: int,
    ground_acceleration: np.ndarray,
    dt: float,
    substeps: int,
    scheme: Callable[[LawFunctions, int], Callable],
    initial_state: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Response of a building at rest at t = 0 to ground accelerations.

    Args:
        chain: the (projected) building.
        functions: the story law's compiled functions.
        n_states: state variables per story.
        ground_acceleration: ``[n, T]`` a_g in m/s^2, sampled every ``dt`` s.
        dt: sample spacing in s.
        substeps: integration steps per sample interval.
        scheme: the factory of the compiled integrator, ``(functions, n_states) ->
            kernel`` (:func:`rk4_kernel` or
            :func:`~.central_difference.central_difference_kernel`); ``substeps`` are its
            steps per sample interval.
        initial_state: ``[d, n_states]`` law state at rest (default zeros).

    Returns:
        Floor displacements, story drifts (m) and story shears (N), each ``[n, T, d]``,
        and ``[n]`` whether each record stayed finite.
    """
    ag = np.ascontiguousarray(ground_acceleration, dtype=np.float64)
    n_records, n_steps = ag.shape
    d = chain.drift.shape[0]
    if initial_state is None:
        initial_state = np.zeros((d, n_states))
    displacement, drift, shear = (np.empty((n_records, n_steps, d)) for _ in range(3))
    finite = np.empty(n_records, dtype=np.bool_)
    kernel = scheme(functions, n_states)
    arrays = tuple(np.ascontiguousarray(a, dtype=np.float64) for a in chain)
    start = np.ascontiguousarray(initial_state, dtype=np.float64).reshape(d, n_states)

    def run(rows: slice) -> None:
        kernel(
            ag[rows],
            arrays,
            start,
            dt / substeps,
            substeps,
            displacement[rows],
            drift[rows],
            shear[rows],
            finite[rows],
        )

    run_in_slices(run, n_records, 1)
    return displacement, drift, shear, finite


@numba.njit(inline="always", **FAST)
def story_value(shapes, y, s, offset):
    """Row ``s`` of ``shapes [d, r]`` times ``y[offset : offset + r]``: a story's drift
    (m) or drift rate (m/s), or a floor's displacement, from the generalised coordinates."""
    value = 0.0
    for j in range(shapes.shape[1]):
        value += shapes[s, j] * y[offset + j]
    return value


@cache
def rk4_kernel(functions: LawFunctions, n_states: int):
    """The compiled integrator of a building whose stories follow ``functions``:
    ``kernel(ag, chain, start, h, substeps, disp_out, drift_out, shear_out, finite_out)``
    with ``chain`` the arrays of a :class:`~.chain.StoryChain` in its order, ``h`` the
    step (s), ``substeps`` steps a sample, the outputs as :func:`integrate_chain` returns
    them."""
    force, rate, settle = functions
    width = max(n_states, 1)

    @numba.njit(inline="always", **FAST)
    def rates(
        y, ag_now, damping, coupling, force_map, drift_map, part, coef, out, story_rate, shear
    ):
        r, d = part.shape[0], drift_map.shape[0]
        for s in range(d):
            v = story_value(drift_map, y, s, 0)
            v_dot = story_value(drift_map, y, s, r)
            state = y[2 * r + s * width : 2 * r + (s + 1) * width]
            shear[s] = force(coef[s], v, state)
            rate(coef[s], v, v_dot, state, story_rate)
            for m in range(width):
                out[2 * r + s * width + m] = story_rate[m]
        for j in range(r):
            out[j] = y[r + j]
            acc = -part[j] * ag_now
            for m in range(r):
                acc -= damping[j, m] * y[r + m] + coupling[j, m] * y[m]
            for s in range(d):
                acc -= force_map[j, s] * shear[s]
            out[r + j] = acc

    @numba.njit(inline="always", **FAST)
    def sample(y, k, drift_map, floors, coef, disp_out, drift_out, shear_out):
        r, d = floors.shape[1], floors.shape[0]
        for s in range(d):
            v = story_value(drift_map, y, s, 0)
            disp_out[k, s] = story_value(floors, y, s, 0)
            drift_out[k, s] = v
            shear_out[k, s] = force(coef[s], v, y[2 * r + s * width : 2 * r + (s + 1) * width])

    @numba.njit(**FAST)
    def kernel(ag, chain, start, h, substeps, disp_out, drift_out, shear_out, finite_out):
        damping, coupling, force_map, drift_map, part, floors, coef = chain
        n_records, n_steps = ag.shape
        r, d = part.shape[0], drift_map.shape[0]
        size = 2 * r + d * width
        y = np.empty(size)
        stage = np.empty(size)
        total = np.empty(size)
        k_rate = np.empty(size)
        story_rate = np.zeros(width)
        shear = np.empty(d)
        for rec in range(n_records):
            y[:] = 0.0
            for s in range(d):
                for m in range(width):
                    y[2 * r + s * width + m] = start[s, m]
            sample(y, 0, drift_map, floors, coef, disp_out[rec], drift_out[rec], shear_out[rec])
            for k in range(n_steps - 1):
                a0 = ag[rec, k]
                slope = (ag[rec, k + 1] - a0) / substeps
                for sub in range(substeps):
                    a_start = a0 + slope * sub
                    total[:] = 0.0
                    stage[:] = y
                    for i in range(4):
                        fraction = (0.0, 0.5, 0.5, 1.0)[i]
                        weight = (1.0, 2.0, 2.0, 1.0)[i] / 6.0
                        rates(
                            stage,
                            a_start + slope * fraction,
                            damping,
                            coupling,
                            force_map,
                            drift_map,
                            part,
                            coef,
                            k_rate,
                            story_rate,
                            shear,
                        )
                        advance = (0.5, 0.5, 1.0, 0.0)[i] * h
                        for m in range(size):
                            total[m] += weight * k_rate[m]
                            stage[m] = y[m] + advance * k_rate[m]
                    for m in range(size):
                        y[m] += h * total[m]
                    for s in range(d):
                        v = story_value(drift_map, y, s, 0)
                        settle(coef[s], v, y[2 * r + s * width : 2 * r + (s + 1) * width])
                sample(
                    y,
                    k + 1,
                    drift_map,
                    floors,
                    coef,
                    disp_out[rec],
                    drift_out[rec],
                    shear_out[rec],
                )
            finite = True
            for m in range(size):
                finite &= np.isfinite(y[m])
            finite_out[rec] = finite

    return kernel


@cache
def law_evaluator(functions: LawFunctions, n_states: int):
    """A compiled ``evaluate(coef [d, n_c], v [n, d], v_dot [n, d], s [n, d, w])`` that
    returns the story shears ``[n, d]`` (N) and state rates ``[n, d, w]``, ``w`` being
    ``max(n_states, 1)``."""
    force, rate, _ = functions
    width = max(n_states, 1)

    @numba.njit(nogil=True, error_model="numpy")
    def evaluate(coef, v, v_dot, state):
        n, d = v.shape
        shear = np.empty((n, d))
        rates = np.zeros((n, d, width))
        out = np.zeros(width)
        for i in range(n):
            for s in range(d):
                shear[i, s] = force(coef[s], v[i, s], state[i, s])
                out[:] = 0.0
                rate(coef[s], v[i, s], v_dot[i, s], state[i, s], out)
                rates[i, s] = out
        return shear, rates

    return evaluate


@cache
def story_test_kernel(functions: LawFunctions, n_states: int):
    """A compiled ``drive(coef [d, n_c], drift [p, d], largest_step [d]) -> shear [p, d]``:
    every story driven from rest along its own drift history, linear between the samples,
    the law's rate integrated over each increment in classical Runge-Kutta steps of at most
    ``largest_step`` (m, in the increment's own pseudo-time; a law is rate-independent) with
    ``settle`` after each; the story shears (N) at the samples."""
    force, rate, settle = functions
    width = max(n_states, 1)

    @numba.njit(**FAST)
    def drive(coef, drift, largest_step):
        p, d = drift.shape
        shear = np.empty((p, d))
        state = np.zeros(width)
        stage = np.empty(width)
        total = np.empty(width)
        out = np.zeros(width)
        for s in range(d):
            state[:] = 0.0
            shear[0, s] = force(coef[s], drift[0, s], state)
            for k in range(p - 1):
                speed = drift[k + 1, s] - drift[k, s]
                substeps = 1
                if largest_step[s] > 0.0:
                    substeps = max(1, int(np.ceil(abs(speed) / largest_step[s])))
                h = 1.0 / substeps
                for sub in range(substeps):
                    v0 = drift[k, s] + speed * h * sub
                    total[:] = 0.0
                    stage[:] = state
                    for i in range(4):
                        fraction = (0.0, 0.5, 0.5, 1.0)[i]
                        weight = (1.0, 2.0, 2.0, 1.0)[i] / 6.0
                        out[:] = 0.0
                        rate(coef[s], v0 + speed * h * fraction, speed, stage, out)
                        advance = (0.5, 0.5, 1.0, 0.0)[i] * h
                        for m in range(width):
                            total[m] += weight * out[m]
                            stage[m] = state[m] + advance * out[m]
                    for m in range(width):
                        state[m] += h * total[m]
                    settle(coef[s], v0 + speed * h, state)
                shear[k + 1, s] = force(coef[s], drift[k + 1, s], state)
        return shear

    return drive
