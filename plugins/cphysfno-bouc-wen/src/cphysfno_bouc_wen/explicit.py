"""Classical fourth-order Runge-Kutta integration on the motion's own time grid."""

from __future__ import annotations

import numpy as np

from .model import ShearBuildingModel, rates


def integrate_rk4(
    model: ShearBuildingModel, ground_acceleration: np.ndarray, dt: float, substeps: int
) -> np.ndarray:
    """Response of a building at rest at t = 0 to ground accelerations linear between samples.

    Args:
        model: the building.
        ground_acceleration: ``[n, T]`` a_g in m/s^2, sampled every ``dt``.
        dt: sample spacing in s.
        substeps: Runge-Kutta steps per sample interval.

    Returns:
        ``[n, T, 3d]`` states ``[u, u', h]`` (m, m/s, m) at the samples.
    """
    n_records, n_steps = ground_acceleration.shape
    state = np.zeros((n_records, model.state_matrix.shape[0]))
    history = np.zeros((n_records, n_steps, state.shape[1]))
    step = dt / substeps
    for k in range(n_steps - 1):
        start = ground_acceleration[:, k]
        change = (ground_acceleration[:, k + 1] - start) / substeps
        for s in range(substeps):
            a0 = start + s * change
            a_mid = a0 + 0.5 * change
            k1 = rates(model, state, a0)
            k2 = rates(model, state + (0.5 * step) * k1, a_mid)
            k3 = rates(model, state + (0.5 * step) * k2, a_mid)
            k4 = rates(model, state + step * k3, a0 + change)
            state = state + (step / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
        history[:, k + 1] = state
    return history
