"""Amplitude scaling of record sets: to a target PGA or Sa(T1), and by fixed factors."""

from __future__ import annotations

import numpy as np
from cphysfno_core import GroundMotions
from cphysfno_core.intensity import peak_ground_acceleration, response_spectrum


def factors_to_target(
    motions: GroundMotions,
    *,
    target_pga: float | None = None,
    target_sa: float | None = None,
    sa_period: float | None = None,
    damping: float = 0.05,
) -> np.ndarray:
    """``[n]`` factors that bring each record's PGA to ``target_pga`` (m/s^2), or its
    pseudo-spectral acceleration at ``sa_period`` (s) to ``target_sa`` (m/s^2); ones when
    neither target is given."""
    if target_pga is not None:
        return target_pga / peak_ground_acceleration(motions.acceleration)
    if target_sa is not None and sa_period is not None:
        spectrum = response_spectrum(motions.acceleration, motions.dt, [sa_period], damping)
        return target_sa / spectrum.pseudo_acceleration[:, 0]
    return np.ones(motions.n_records)


def scale(motions: GroundMotions, base: np.ndarray, factors: tuple[float, ...]) -> GroundMotions:
    """Every record times ``base`` times each of ``factors``: ``n * len(factors)`` records,
    record-major (the copies of record 0 first), each with its total ``scale_factor`` and
    the ``base_index`` of the record it was made from in its metadata."""
    total = base[:, None] * np.asarray(factors)[None, :]
    acceleration = (motions.acceleration[:, None, :] * total[:, :, None]).reshape(
        -1, motions.n_steps
    )
    metadata = [
        {**motions.metadata[i], "scale_factor": float(total[i, j]), "base_index": i}
        for i in range(motions.n_records)
        for j in range(len(factors))
    ]
    return GroundMotions(acceleration, motions.dt, metadata)
