"""Three-stage Gauss-Legendre implicit Runge-Kutta integration on an arbitrary (coarse) grid.

The scheme is A-stable and of order 6: steps far longer than the shortest natural period
stay stable, and steps as short as the motion's own sample spacing reproduce the explicit
solution. Each step solves the stage equations of all records at once by a damped Newton
method on the full state ``[u, u', h]`` (batched linear solves, the step along the Newton
direction halved until the residual decreases). A record whose iterations still do not
converge repeats that step as two half steps, recursively.
"""

from __future__ import annotations

import math

import numpy as np
from cphysfno_core import CphysfnoError

from .model import ShearBuildingModel, rate_jacobian, rates

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
    model: ShearBuildingModel,
    ground_acceleration: np.ndarray,
    dt: float,
    scale: np.ndarray,
    tolerance: float = 1e-10,
    max_iterations: int = 20,
    max_halvings: int = 8,
) -> np.ndarray:
    """Response of a building at rest at t = 0 to ground accelerations linear between samples.

    Args:
        model: the building.
        ground_acceleration: ``[n, T]`` a_g in m/s^2, sampled every ``dt``.
        dt: step in s (one step per sample interval).
        scale: ``[3d]`` typical magnitudes of ``[u, u', h]`` (m, m/s, m); Newton has
            converged when every component of its correction is below ``tolerance``
            times these.
        tolerance: relative size of the last Newton correction.
        max_iterations: Newton iterations before a step counts as failed.
        max_halvings: how many times a failed step may be halved.

    Returns:
        ``[n, T, 3d]`` states ``[u, u', h]`` (m, m/s, m) at the samples.

    Raises:
        StepFailure: naming the record (its index in the batch) and the time where a step
            failed even after ``max_halvings`` halvings.
    """
    n_records, n_steps = ground_acceleration.shape
    state = np.zeros((n_records, model.state_matrix.shape[0]))
    history = np.zeros((n_records, n_steps, state.shape[1]))
    records = np.arange(n_records)
    settings = (scale, tolerance, max_iterations)
    for k in range(n_steps - 1):
        start, end = ground_acceleration[:, k], ground_acceleration[:, k + 1]
        state = _advance(model, state, start, end, k * dt, dt, settings, max_halvings, records)
        history[:, k + 1] = state
    return history


def _advance(model, state, start, end, time, step, settings, halvings_left, records):
    """One step of every record, halving it for the records whose Newton solve failed."""
    new_state, converged = gauss_step(model, state, start, end, step, *settings)
    if converged.all():
        return new_state
    failed = ~converged
    if halvings_left == 0:
        raise StepFailure(int(records[failed][0]), time, step)
    middle = 0.5 * (start[failed] + end[failed])
    half = 0.5 * step
    rest = (settings, halvings_left - 1, records[failed])
    midway = _advance(model, state[failed], start[failed], middle, time, half, *rest)
    new_state[failed] = _advance(model, midway, middle, end[failed], time + half, half, *rest)
    return new_state


def gauss_step(
    model: ShearBuildingModel,
    state: np.ndarray,
    start: np.ndarray,
    end: np.ndarray,
    step: float,
    scale: np.ndarray,
    tolerance: float,
    max_iterations: int,
) -> tuple[np.ndarray, np.ndarray]:
    """One Gauss-Legendre step of length ``step`` (s) for every record.

    Solves ``Z_i = step * sum_j a_ij f(y + Z_j, a_g(t + c_j step))`` for the stage
    increments ``Z`` and returns ``y + b^T A^-1 Z``.

    Args:
        model: the building.
        state: ``[n, 3d]`` states at the start of the step.
        start, end: ``[n]`` ground accelerations (m/s^2) at both ends of the step.
        step, scale, tolerance, max_iterations: as in :func:`integrate_gauss`.

    Returns:
        ``[n, 3d]`` states at the end of the step and ``[n]`` whether Newton converged.
    """
    n_records = state.shape[0]
    accel = start[:, None] + NODES * (end - start)[:, None]
    slope = rates(model, state, start)
    increments = step * NODES[None, :, None] * slope[:, None, :]
    residual = _residual(model, state, increments, accel, step)
    converged = np.zeros(n_records, dtype=bool)
    active = np.ones(n_records, dtype=bool)
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(max_iterations):
            rows = np.flatnonzero(active)
            if rows.size == 0:
                break
            y, z, a = state[rows], increments[rows], accel[rows]
            correction = _newton_correction(model, y, z, residual[rows], step)
            increments[rows], residual[rows] = _damped(
                model, y, z, residual[rows], correction, a, step, scale
            )
            small = np.all(np.abs(correction) <= tolerance * scale, axis=(1, 2))
            finite = np.all(np.isfinite(correction), axis=(1, 2))
            converged[rows[small]] = True
            active[rows[small | ~finite]] = False
        new_state = state + np.einsum("i,nis->ns", UPDATE, increments)
    converged &= np.all(np.isfinite(new_state), axis=1)
    return new_state, converged


def _residual(model, state, increments, accel, step):
    """``[n, s, 3d]`` residual ``Z - step * A f(y + Z)`` of the stage equations."""
    size = state.shape[1]
    stages = (state[:, None, :] + increments).reshape(-1, size)
    stage_rates = rates(model, stages, accel.reshape(-1)).reshape(increments.shape)
    return increments - step * np.einsum("ij,njs->nis", COEFFICIENTS, stage_rates)


def _newton_correction(model, state, increments, residual, step):
    """Newton correction ``[n, s, 3d]`` of the stage increments (NaN where singular)."""
    n_records, n_stages, size = increments.shape
    stages = (state[:, None, :] + increments).reshape(-1, size)
    tangent = rate_jacobian(model, stages).reshape(n_records, n_stages, size, size)
    blocks = np.einsum("ij,njab->niajb", -step * COEFFICIENTS, tangent)
    matrix = blocks.reshape(n_records, n_stages * size, n_stages * size)
    matrix += np.eye(n_stages * size)
    rhs = -residual.reshape(n_records, n_stages * size, 1)
    try:
        correction = np.linalg.solve(matrix, rhs)
    except np.linalg.LinAlgError:
        correction = np.full_like(rhs, np.nan)
        for i in range(n_records):
            try:
                correction[i] = np.linalg.solve(matrix[i], rhs[i])
            except np.linalg.LinAlgError:
                continue
    return correction.reshape(increments.shape)


def _damped(model, state, increments, residual, correction, accel, step, scale):
    """Stage increments moved along ``correction``, by the largest fraction in
    1, 1/2, ..., 2^-BACKTRACKS that lowers the scaled residual, and their residual."""
    before = _size(residual, scale)
    fraction = np.ones(state.shape[0])
    trial = increments + correction
    trial_residual = _residual(model, state, trial, accel, step)
    for _ in range(BACKTRACKS):
        worse = ~(_size(trial_residual, scale) < before) & (before > 0.0)
        if not worse.any():
            break
        fraction[worse] *= 0.5
        trial[worse] = increments[worse] + fraction[worse, None, None] * correction[worse]
        trial_residual[worse] = _residual(model, state[worse], trial[worse], accel[worse], step)
    return trial, trial_residual


def _size(residual, scale):
    """``[n]`` root mean square of the residual in units of ``scale``."""
    return np.sqrt(np.mean((residual / scale) ** 2, axis=(1, 2)))
