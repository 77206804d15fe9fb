"""Anti-aliased resampling of accelerations onto another time step.

Resampling is polyphase (``scipy.signal.resample_poly``): the rate is changed by a
rational factor through a Kaiser-windowed FIR low-pass at the lower of the two Nyquist
frequencies, so content above the new Nyquist frequency is removed, not folded back.
(:meth:`GroundMotions.resample <cphysfno_core.signals.GroundMotions.resample>` instead
samples the record linearly between its samples.)
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import scipy.signal

from .errors import InputError

RELATIVE_DT_TOLERANCE = 1e-6
"""Two time steps closer than this, relatively, are the same."""


def same_step(a: float, b: float) -> bool:
    """Whether the time steps ``a`` and ``b`` (s) are equal within the tolerance."""
    return abs(a - b) <= RELATIVE_DT_TOLERANCE * max(a, b)


def resample(acceleration: np.ndarray, dt: float, new_dt: float) -> np.ndarray:
    """Accelerations on the grid ``0, new_dt, ...`` with anti-aliasing.

    Args:
        acceleration: ``[..., T]`` samples every ``dt`` s (time along the last axis).
        dt: original time step in s.
        new_dt: new time step in s; ``dt / new_dt`` must be a ratio of integers up to 1000.

    Returns:
        ``[..., floor((T - 1) dt / new_dt) + 1]`` samples every ``new_dt`` s from t = 0,
        covering the original record.

    Raises:
        InputError: the two steps are not in a ratio of integers up to 1000.
    """
    if same_step(dt, new_dt):
        return np.array(acceleration, dtype=np.float64)
    ratio = Fraction(dt / new_dt).limit_denominator(1000)
    if abs(ratio.numerator / ratio.denominator * new_dt - dt) > 1e-9 * dt:
        raise InputError(
            f"cannot resample from dt = {dt:g} s to {new_dt:g} s: their ratio is not a "
            "fraction of integers up to 1000; choose a dt that divides evenly"
        )
    out = scipy.signal.resample_poly(acceleration, ratio.numerator, ratio.denominator, axis=-1)
    steps = int(np.floor((acceleration.shape[-1] - 1) * dt / new_dt + 1e-9)) + 1
    return out[..., :steps]
