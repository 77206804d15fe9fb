"""Baseline correction: ground velocity and displacement brought back to zero at the end."""

from __future__ import annotations

import numpy as np
from cphysfno_core.signals.intensity import velocity_displacement


def baseline_correct(acceleration: np.ndarray, dt: float, weight: np.ndarray) -> np.ndarray:
    """Records whose final ground velocity and displacement are zero.

    Subtracts from each record the slowly varying correction
    ``c1 w(t) + c2 w(t) (t / t_end)``, shaped by the weight ``w`` (an envelope that vanishes
    where the record is quiet), with ``c1, c2`` solved so that the velocity and displacement
    at the last sample, integrated exactly for acceleration linear between samples, are zero.

    Args:
        acceleration: ``[n, T]`` accelerations in m/s^2.
        dt: time step in s.
        weight: ``[T]`` non-negative shape of the correction, not all zero.

    Returns:
        ``[n, T]`` corrected accelerations in m/s^2.
    """
    steps = acceleration.shape[1]
    ramp = np.arange(steps) / (steps - 1)
    basis = np.stack([weight, weight * ramp])
    basis_v, basis_d = velocity_displacement(basis, dt)
    system = np.array([basis_v[:, -1], basis_d[:, -1]])
    velocity, displacement = velocity_displacement(acceleration, dt)
    ends = np.stack([velocity[:, -1], displacement[:, -1]])
    coefficients = np.linalg.solve(system, ends)
    return acceleration - coefficients.T @ basis
