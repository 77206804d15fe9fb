"""Classical Runge-Kutta integration of many records at once, ground motion linear between
samples."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

Rate = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""``rate(y [n, m], a_g [n]) -> y' [n, m]``: a first-order system driven by ``a_g``."""


def integrate_rk4(
    rate: Rate, y0: np.ndarray, acceleration: np.ndarray, dt: float, substeps: int
) -> np.ndarray:
    """States of every record at every sample, by classical RK4.

    Each sample interval is split into ``substeps`` equal steps; the ground acceleration
    between two samples is the straight line joining them.

    Args:
        rate: the system (see :data:`Rate`).
        y0: ``[n, m]`` initial states.
        acceleration: ``[n, T]`` ground accelerations in m/s^2.
        dt: sample interval in s.
        substeps: RK4 steps per sample interval (>= 1).

    Returns:
        ``[n, T, m]`` states at the samples (``[:, 0]`` is ``y0``).
    """
    n, steps = acceleration.shape
    h = dt / substeps
    out = np.empty((n, steps, y0.shape[1]))
    out[:, 0] = y = y0
    for k in range(steps - 1):
        start, slope = acceleration[:, k], (acceleration[:, k + 1] - acceleration[:, k]) / dt
        for j in range(substeps):
            a0 = start + slope * (j * h)
            am = a0 + slope * (0.5 * h)
            a1 = a0 + slope * h
            k1 = rate(y, a0)
            k2 = rate(y + 0.5 * h * k1, am)
            k3 = rate(y + 0.5 * h * k2, am)
            k4 = rate(y + h * k3, a1)
            y = y + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        out[:, k + 1] = y
    return out
