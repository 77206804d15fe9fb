"""Short records for one-record analyses of the SAC frame in the tests."""

from __future__ import annotations

import numpy as np

from cphysfno_core.plugin import Rayleigh

DT = 0.01
"""Time step of :func:`pulse`, s."""

DAMPING = Rayleigh.matching(2.0 * np.pi / 2.37, 2.0 * np.pi / 0.51, 0.03)
"""3 % in the frame's modes 1 and 3 (with P-Delta)."""


def pulse(amplitude: float) -> np.ndarray:
    """One sine cycle of 1.5 s and ``amplitude`` m/s^2, then 0.5 s at rest (dt 0.01 s)."""
    t = np.arange(201) * DT
    return amplitude * np.sin(2.0 * np.pi * t / 1.5) * (t < 1.5)


def relative(a: np.ndarray, b: np.ndarray) -> float:
    """Relative L2 of ``a`` from ``b`` over all entries."""
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))
