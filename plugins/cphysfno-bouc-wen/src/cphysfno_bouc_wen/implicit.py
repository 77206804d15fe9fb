"""Three-stage Gauss-Legendre implicit Runge-Kutta integration on an arbitrary (coarse) grid.

The scheme is A-stable and of order 6: steps far longer than the shortest natural period
stay stable, and steps as short as the motion's own sample spacing reproduce the explicit
solution. The reduced model (:mod:`.reduced`) is linear but for the Bouc-Wen rates, so the
stage equations are solved exactly for the coordinates and their rates given the stage
increments ``X`` of the Bouc-Wen displacements (matrices that depend only on the step,
computed once), which leaves ``3 d`` unknowns for Newton's method:

    F(X) = X - dt (A kron I) g(V0 + Q X, h + X) = 0,

``V0 + Q X`` being the stage drift rates. A compiled kernel runs each record on its own
(records spread over the cores in threads): a small dense Newton system per iteration, the
step along the Newton direction halved until the residual decreases. A record whose
iterations do not converge repeats that step as 2, 4, 8, ... equal sub-steps.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from cphysfno_core import CphysfnoError
from cphysfno_core.signals import run_in_slices

from .native import JIT, hysteretic_power, whole_power
from .reduced import ReducedModel

_R15 = math.sqrt(15.0)
NODES = np.array([0.5 - _R15 / 10.0, 0.5, 0.5 + _R15 / 10.0])
COEFFICIENTS = np.array(
    [
        [5.0 / 36.0, 2.0 / 9.0 - _R15 / 15.0, 5.0 / 36.0 - _R15 / 30.0],
        [5.0 / 36.0 + _R15 / 24.0, 2.0 / 9.0, 5.0 / 36.0 - _R15 / 24.0],
        [5.0 / 36.0 + _R15 / 30.0, 2.0 / 9.0 + _R15 / 15.0, 5.0 / 36.0],
    ]
)
WEIGHTS = np.array([5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0])
UPDATE = WEIGHTS @ np.linalg.inv(COEFFICIENTS)
BACKTRACKS = 6


class StepFailure(CphysfnoError):
    """Newton's method failed on a record even on the shortest allowed step.

    Attributes:
        record: index of the record in the batch.
        time: start of the failed step, s.
    """

    def __init__(self, record: int, time: float, step: float) -> None:
        super().__init__(
            f"implicit integration did not converge for record {record} at t = {time:.4f} s "
            f"even with the step cut to {step:.3g} s: the record is likely too strong for "
            f"this structure or its parameters are degenerate; check that record"
        )
        self.record = record
        self.time = time


def integrate_gauss(
    model: ReducedModel,
    ground_acceleration: np.ndarray,
    dt: float,
    scale: float,
    tolerance: float = 1e-10,
    max_iterations: int = 20,
    max_halvings: int = 8,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Response of a building at rest at t = 0 to ground accelerations linear between samples.

    Args:
        model: the (reduced) building.
        ground_acceleration: ``[n, T]`` a_g in m/s^2, sampled every ``dt``.
        dt: step in s (one step per sample interval).
        scale: typical magnitude of the Bouc-Wen displacements h (m); Newton has converged
            when every component of its correction is below ``tolerance`` times this.
        tolerance: relative size of the last Newton correction.
        max_iterations: Newton iterations before a step counts as failed.
        max_halvings: how many times a failed step may be halved.

    Returns:
        Floor displacements ``[n, T, d]`` (m), story drifts ``[n, T, d]`` (m) and story
        shears ``[n, T, d]`` (N) at the samples.

    Raises:
        StepFailure: naming the record (its index in the batch) and the time where a step
            failed even after ``max_halvings`` halvings.
    """
    ag = np.ascontiguousarray(ground_acceleration, dtype=np.float64)
    n_records, n_steps = ag.shape
    d = model.n_stories
    displacement = np.empty((n_records, n_steps, d))
    drift = np.empty((n_records, n_steps, d))
    shear = np.empty((n_records, n_steps, d))
    failed_at = np.empty(n_records, dtype=np.int64)
    maps = _stage_maps(model, dt * 0.5 ** np.arange(max_halvings + 1))
    power = float(model.exponent) - 1.0
    bouc_wen = (model.a, model.delta, model.zeta, power, whole_power(power))
    newton = (float(scale) * tolerance, int(max_iterations))
    fixed = (model.floors, model.drift, model.story_stiffness, model.alpha)

    def kernel(rows: slice) -> None:
        outputs = (displacement[rows], drift[rows], shear[rows], failed_at[rows])
        _gauss_kernel(ag[rows], maps, fixed, bouc_wen, newton, outputs)

    run_in_slices(kernel, n_records, 1)
    failed = np.flatnonzero(failed_at >= 0)
    if failed.size:
        record = int(failed[0])
        step = dt * 0.5**max_halvings
        raise StepFailure(record, failed_at[record] * dt, step)
    return displacement, drift, shear


def _stage_maps(model: ReducedModel, steps: np.ndarray) -> tuple[np.ndarray, ...]:
    """Linear maps of the stage equations for each step length in ``steps`` ``[L]`` (s).

    With ``Z`` the stage increments of the coordinate rates ``s = q'`` and ``X`` those of
    h, the linear stage equations give ``Z = Z0 + Qs X`` with
    ``Z0 = Gq q + Gs s + Gh h + Ga a``, ``a`` the ground accelerations at the nodes.

    Returns:
        ``[L, 3r, 2r + d + 3]`` ``[Gq Gs Gh Ga]``, ``[L, 3r, 3d]`` ``Qs``, the same two
        mapped to stage drift rates (``D`` applied per stage, plus ``D s`` itself), and
        ``[L]`` the step lengths.
    """
    r, d = model.n_coordinates, model.n_stories
    nodes = NODES[:, None]
    kappa = np.diag(model.stiffness)
    drift_per_stage = np.kron(np.eye(3), model.drift)
    state_maps, increment_maps, drift_state_maps, drift_increment_maps = [], [], [], []
    for step in steps:
        system = (
            np.eye(3 * r)
            + step**2 * np.kron(COEFFICIENTS @ COEFFICIENTS, kappa)
            + step * np.kron(COEFFICIENTS, model.damping)
        )
        right = np.hstack(
            [
                step * np.kron(nodes, kappa),
                step * np.kron(nodes, model.damping)
                + step**2 * np.kron(COEFFICIENTS @ nodes, kappa),
                step * np.kron(nodes, model.hysteretic),
                step * np.kron(COEFFICIENTS, model.participation[:, None]),
                step * np.kron(COEFFICIENTS, model.hysteretic),
            ]
        )
        solved = -np.linalg.solve(system, right)
        state_map, increment_map = solved[:, : 2 * r + d + 3], solved[:, 2 * r + d + 3 :]
        drift_state_map = drift_per_stage @ state_map
        drift_state_map[:, r : 2 * r] += np.kron(np.ones((3, 1)), model.drift)
        state_maps.append(state_map)
        increment_maps.append(increment_map)
        drift_state_maps.append(drift_state_map)
        drift_increment_maps.append(drift_per_stage @ increment_map)
    return (
        np.array(state_maps),
        np.array(increment_maps),
        np.array(drift_state_maps),
        np.array(drift_increment_maps),
        np.asarray(steps, dtype=np.float64),
    )


class _Scratch(NamedTuple):
    """Work arrays of the Newton solve of one step (``3d`` unknowns, ``3r`` rate
    increments): the unknowns, the residual, the Newton correction, a trial point and its
    residual, the stage drift rates at ``X = 0``, the stage rates and their derivatives by
    ``v'`` and ``h``, the Newton matrix, and the rate increments."""

    unknowns: np.ndarray
    residual: np.ndarray
    correction: np.ndarray
    trial: np.ndarray
    trial_residual: np.ndarray
    base: np.ndarray
    rates: np.ndarray
    by_drift_rate: np.ndarray
    by_hysteretic: np.ndarray
    matrix: np.ndarray
    increments: np.ndarray


@numba.njit(**JIT)
def _gauss_kernel(ag, maps, fixed, bouc_wen, newton, outputs):
    """Integrate each record of ``ag [n, T]`` into ``outputs``: floor displacements, story
    drifts and story shears ``[n, T, d]``, and ``[n]`` the sample index where each record
    failed, or -1."""
    displacement_out, drift_out, shear_out, failed_out = outputs
    steps = maps[4]
    drift_map = fixed[1]
    n_records, n_steps = ag.shape
    r, d = drift_map.shape[1], drift_map.shape[0]
    state = np.zeros(2 * r + d)
    start = np.empty(2 * r + d)
    accel = np.empty(3)
    n = 3 * d
    work = _Scratch(
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty((n, n)),
        np.empty(3 * r),
    )
    for record in range(n_records):
        state[:] = 0.0
        failed_out[record] = -1
        _write_sample(state, record, 0, fixed, displacement_out, drift_out, shear_out)
        for k in range(n_steps - 1):
            a0, a1 = ag[record, k], ag[record, k + 1]
            start[:] = state
            converged = False
            for level in range(steps.shape[0]):
                pieces = 1 << level
                for piece in range(pieces):
                    for i in range(3):
                        accel[i] = a0 + (piece + NODES[i]) / pieces * (a1 - a0)
                    converged = _gauss_step(
                        state, accel, maps, level, drift_map, bouc_wen, newton, work
                    )
                    if not converged:
                        break
                if converged:
                    break
                state[:] = start
            if not converged:
                failed_out[record] = k
                break
            _write_sample(state, record, k + 1, fixed, displacement_out, drift_out, shear_out)


@numba.njit(**JIT)
def _gauss_step(state, accel, maps, level, drift_map, bouc_wen, newton, work):
    """Advance ``state = [q, q', h]`` in place by one step of the length ``maps`` holds at
    ``level``, the ground accelerating by ``accel [3]`` (m/s^2) at the nodes; return whether
    Newton's method converged (``state`` is then the new state)."""
    state_maps, increment_maps, drift_state_maps, drift_increment_maps, steps = maps
    state_map, increment_map = state_maps[level], increment_maps[level]
    drift_state_map, drift_increment_map = drift_state_maps[level], drift_increment_maps[level]
    step = steps[level]
    a, delta, zeta, power, whole_power = bouc_wen
    limit, max_iterations = newton
    r, d = drift_map.shape[1], drift_map.shape[0]
    n_state, n = 2 * r + d, 3 * d
    x, residual, correction = work.unknowns, work.residual, work.correction
    trial_residual = work.trial_residual
    for i in range(n):
        total = 0.0
        for j in range(n_state):
            total += drift_state_map[i, j] * state[j]
        for j in range(3):
            total += drift_state_map[i, n_state + j] * accel[j]
        work.base[i] = total
    for s in range(d):
        drift_rate = 0.0
        for j in range(r):
            drift_rate += drift_map[s, j] * state[r + j]
        rate = _rates(drift_rate, state[2 * r + s], a, delta, zeta, power, whole_power)[0]
        for i in range(3):
            x[i * d + s] = step * NODES[i] * rate
    _residual(x, state, step, drift_increment_map, bouc_wen, work, residual)
    converged = False
    for _ in range(max_iterations):
        _newton_matrix(step, drift_increment_map, work)
        for i in range(n):
            correction[i] = -residual[i]
        if not _solve(work.matrix, correction):
            return False
        small = True
        for i in range(n):
            small &= abs(correction[i]) <= limit
        before = _norm(residual)
        fraction = 1.0
        for i in range(n):
            work.trial[i] = x[i] + correction[i]
        _residual(work.trial, state, step, drift_increment_map, bouc_wen, work, trial_residual)
        for _ in range(BACKTRACKS):
            if _norm(trial_residual) < before or not before > 0.0:
                break
            fraction *= 0.5
            for i in range(n):
                work.trial[i] = x[i] + fraction * correction[i]
            _residual(work.trial, state, step, drift_increment_map, bouc_wen, work, trial_residual)
        x[:] = work.trial
        residual[:] = trial_residual
        if small:
            converged = True
            break
    if not converged:
        return False
    increments = work.increments
    for i in range(3 * r):
        total = 0.0
        for j in range(n_state):
            total += state_map[i, j] * state[j]
        for j in range(3):
            total += state_map[i, n_state + j] * accel[j]
        for j in range(n):
            total += increment_map[i, j] * x[j]
        increments[i] = total
    finite = True
    for j in range(r):
        moved = 0.0
        turned = 0.0
        for i in range(3):
            moved += WEIGHTS[i] * increments[i * r + j]
            turned += UPDATE[i] * increments[i * r + j]
        state[j] += step * (state[r + j] + moved)
        state[r + j] += turned
        finite &= np.isfinite(state[j]) and np.isfinite(state[r + j])
    for s in range(d):
        for i in range(3):
            state[2 * r + s] += UPDATE[i] * x[i * d + s]
        finite &= np.isfinite(state[2 * r + s])
    return finite


@numba.njit(inline="always", **JIT)
def _rates(drift_rate, hysteretic, a, delta, zeta, power, whole_power):
    """Bouc-Wen rate ``h'`` (m/s) of one story and its derivatives by ``v'`` and by ``h``."""
    magnitude = abs(hysteretic)
    scaled = hysteretic_power(magnitude, power, whole_power)
    rate = drift_rate * (a - zeta * scaled * magnitude) - delta * abs(drift_rate) * scaled * (
        hysteretic
    )
    by_drift_rate = (
        a - zeta * scaled * magnitude - delta * np.sign(drift_rate) * scaled * (hysteretic)
    )
    by_hysteretic = (
        -(power + 1.0)
        * scaled
        * (zeta * drift_rate * np.sign(hysteretic) + delta * abs(drift_rate))
    )
    return rate, by_drift_rate, by_hysteretic


@numba.njit(**JIT)
def _residual(x, state, step, drift_increment_map, bouc_wen, work, out):
    """``out = X - step (A kron I) g`` at the stage increments ``x [3d]``; the stage rates
    and their derivatives go to ``work``."""
    a, delta, zeta, power, whole_power = bouc_wen
    n = x.shape[0]
    d = n // 3
    h0 = state.shape[0] - d
    for i in range(n):
        drift_rate = work.base[i]
        for j in range(n):
            drift_rate += drift_increment_map[i, j] * x[j]
        rate, by_drift_rate, by_hysteretic = _rates(
            drift_rate, state[h0 + i % d] + x[i], a, delta, zeta, power, whole_power
        )
        work.rates[i] = rate
        work.by_drift_rate[i] = by_drift_rate
        work.by_hysteretic[i] = by_hysteretic
    for i in range(3):
        for s in range(d):
            total = 0.0
            for j in range(3):
                total += COEFFICIENTS[i, j] * work.rates[j * d + s]
            out[i * d + s] = x[i * d + s] - step * total


@numba.njit(**JIT)
def _newton_matrix(step, drift_increment_map, work):
    """``I - step (A kron I) [diag(g_v) Q + diag(g_h)]`` into ``work.matrix``."""
    matrix = work.matrix
    n = matrix.shape[0]
    d = n // 3
    for i in range(3):
        for s in range(d):
            row = i * d + s
            for col in range(n):
                total = 0.0
                for j in range(3):
                    total += (
                        COEFFICIENTS[i, j]
                        * work.by_drift_rate[j * d + s]
                        * drift_increment_map[j * d + s, col]
                    )
                matrix[row, col] = -step * total
            for j in range(3):
                matrix[row, j * d + s] -= step * COEFFICIENTS[i, j] * work.by_hysteretic[j * d + s]
            matrix[row, row] += 1.0


@numba.njit(**JIT)
def _solve(matrix, rhs):
    """Solve ``matrix x = rhs`` in place (Gaussian elimination with partial pivoting);
    ``rhs`` becomes ``x``. Return False when the matrix is singular or not finite."""
    n = matrix.shape[0]
    for col in range(n):
        pivot = col
        for row in range(col + 1, n):
            if abs(matrix[row, col]) > abs(matrix[pivot, col]):
                pivot = row
        if not abs(matrix[pivot, col]) > 0.0 or not np.isfinite(matrix[pivot, col]):
            return False
        if pivot != col:
            for j in range(col, n):
                matrix[col, j], matrix[pivot, j] = matrix[pivot, j], matrix[col, j]
            rhs[col], rhs[pivot] = rhs[pivot], rhs[col]
        inverse = 1.0 / matrix[col, col]
        for row in range(col + 1, n):
            factor = matrix[row, col] * inverse
            if factor != 0.0:
                for j in range(col + 1, n):
                    matrix[row, j] -= factor * matrix[col, j]
                rhs[row] -= factor * rhs[col]
    for col in range(n - 1, -1, -1):
        total = rhs[col]
        for j in range(col + 1, n):
            total -= matrix[col, j] * rhs[j]
        rhs[col] = total / matrix[col, col]
    finite = True
    for i in range(n):
        finite &= np.isfinite(rhs[i])
    return finite


@numba.njit(inline="always", **JIT)
def _norm(values):
    """Sum of squares of ``values`` (NaN stays NaN)."""
    total = 0.0
    for i in range(values.shape[0]):
        total += values[i] * values[i]
    return total


@numba.njit(inline="always", **JIT)
def _write_sample(state, record, k, fixed, displacement_out, drift_out, shear_out):
    """Write sample ``k`` of ``record``: floor displacements, story drifts and shears."""
    floors, _, story_stiffness, alpha = fixed
    r, d = floors.shape[1], floors.shape[0]
    below = 0.0
    for s in range(d):
        floor = 0.0
        for j in range(r):
            floor += floors[s, j] * state[j]
        displacement_out[record, k, s] = floor
        drift_out[record, k, s] = floor - below
        shear_out[record, k, s] = story_stiffness[s] * (
            alpha * (floor - below) + (1.0 - alpha) * state[2 * r + s]
        )
        below = floor
