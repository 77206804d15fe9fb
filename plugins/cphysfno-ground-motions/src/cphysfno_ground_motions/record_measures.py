"""Intensity measures that travel with each record as metadata."""

from __future__ import annotations

import numpy as np
from cphysfno_core.signals.intensity import (
    arias_intensity,
    peak_ground_acceleration,
    peak_ground_velocity,
    significant_duration,
)


def intensity_metadata(acceleration: np.ndarray, dt: float) -> list[dict[str, float]]:
    """Per record of ``[n, T]`` accelerations (m/s^2): ``pga`` (m/s^2), ``pgv`` (m/s),
    ``arias_intensity`` (m/s) and ``d5_95`` (significant duration, s)."""
    columns = {
        "pga": peak_ground_acceleration(acceleration),
        "pgv": peak_ground_velocity(acceleration, dt),
        "arias_intensity": arias_intensity(acceleration, dt),
        "d5_95": significant_duration(acceleration, dt),
    }
    return [
        {key: float(values[i]) for key, values in columns.items()}
        for i in range(acceleration.shape[0])
    ]
