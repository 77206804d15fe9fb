"""Amplitude scaling of record sets: to a target PGA or Sa(T1), by fixed factors, and by
random factors drawn log-uniformly."""

from __future__ import annotations

import numpy as np
from cphysfno_core import GroundMotions
from cphysfno_core.signals.intensity import peak_ground_acceleration, response_spectrum


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
    rows = np.repeat(np.arange(motions.n_records), len(factors))
    total = (base[:, None] * np.asarray(factors)[None, :]).ravel()
    scaled = scaled_copies(motions, rows, total)
    metadata = [
        {**meta, "base_index": int(i)} for meta, i in zip(scaled.metadata, rows, strict=True)
    ]
    return GroundMotions(scaled.acceleration, scaled.dt, metadata)


def scaled_copies(motions: GroundMotions, rows: np.ndarray, factors: np.ndarray) -> GroundMotions:
    """Record ``rows[k]`` of ``motions`` times ``factors[k]``, for every ``k``; each copy
    keeps its record's metadata, with ``scale_factor`` (1 where absent) multiplied by its
    factor. The intensity measures in the metadata are those of the record, not the copy."""
    rows, factors = np.asarray(rows), np.asarray(factors, dtype=np.float64)
    acceleration = motions.acceleration[rows] * factors[:, None]
    metadata = []
    for i, factor in zip(rows, factors, strict=True):
        meta = dict(motions.metadata[i]) if motions.metadata else {}
        meta["scale_factor"] = float(meta.get("scale_factor", 1.0) * factor)
        metadata.append(meta)
    return GroundMotions(acceleration, motions.dt, metadata)


def log_uniform_factors(
    n: int, copies: int, scale_range: tuple[float, float], rng: np.random.Generator
) -> np.ndarray:
    """``[n, copies]`` factors whose logarithms are uniform between those of
    ``scale_range`` (low, high), drawn by ``rng`` in one call."""
    low, high = np.log(scale_range[0]), np.log(scale_range[1])
    return np.exp(rng.uniform(low, high, size=(n, copies)))
