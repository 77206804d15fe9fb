"""Frequency-domain spectral matching of modulated Fourier series, all records at once.

Each record is ``a(t) = baseline(e(t) s(t))``: a stationary Fourier series ``s`` with
amplitudes ``A_j`` and phases ``phi_j`` at the frequencies ``f_j = j / (T dt)``, modulated
by the envelope ``e`` and baseline corrected. Every iteration computes the record's
5%-damped PSA at the matching periods, and multiplies each amplitude by the ratio
target / PSA interpolated (linearly in log frequency) at its frequency; phases are kept.
A record's misfit is ``exp(max |ln(PSA / target)|) - 1`` over the periods: within a
tolerance of 0.1, every ordinate lies between ``target / 1.1`` and ``1.1 target``. A record
stops when its misfit is within the tolerance, or when it has not improved by
:data:`MIN_IMPROVEMENT` for :data:`PATIENCE` iterations (its target asks for what
amplitudes alone cannot give, such as a short-period ordinate below the PGA the rest of
the spectrum implies); the best iterate of each record is returned.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from cphysfno_core.intensity import response_spectrum

from .baseline import baseline_correct

PATIENCE = 4
"""Iterations without improvement after which a record stops."""

MIN_IMPROVEMENT = 0.005
"""Decrease of the largest misfit that counts as an improvement."""


@dataclass(frozen=True)
class MatchResult:
    """Matched records.

    Attributes:
        acceleration: ``[n, T]`` matched, baseline-corrected accelerations in m/s^2.
        misfit: ``[n]`` ``exp(max |ln(PSA / target)|) - 1`` over the matching periods.
        iterations: ``[n]`` amplitude adjustments made for each record.
    """

    acceleration: np.ndarray
    misfit: np.ndarray
    iterations: np.ndarray


def interpolation_weights(frequencies: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """``[F, P]`` weights that interpolate values at ``nodes`` (Hz, any order) linearly in
    log frequency onto ``frequencies`` (Hz, > 0), holding the end values beyond the nodes."""
    order = np.argsort(nodes)
    log_nodes = np.log(nodes[order])
    position = np.interp(np.log(frequencies), log_nodes, np.arange(nodes.size))
    lower = np.floor(position).astype(int).clip(0, nodes.size - 1)
    upper = np.minimum(lower + 1, nodes.size - 1)
    share = position - lower
    weights = np.zeros((frequencies.size, nodes.size))
    rows = np.arange(frequencies.size)
    np.add.at(weights, (rows, order[lower]), 1.0 - share)
    np.add.at(weights, (rows, order[upper]), share)
    return weights


def match_spectra(
    amplitude: np.ndarray,
    phase: np.ndarray,
    envelope: np.ndarray,
    dt: float,
    periods: np.ndarray,
    target: np.ndarray,
    *,
    tolerance: float,
    max_iterations: int,
    damping: float = 0.05,
) -> MatchResult:
    """Adjust Fourier amplitudes until each record's PSA matches its own target spectrum.

    Args:
        amplitude: ``[n, F]`` starting amplitudes of the stationary series at the
            frequencies ``f_j = j / (T dt)``, ``j = 0 .. F - 1`` with ``F = T // 2 + 1``;
            a zero amplitude stays zero.
        phase: ``[n, F]`` phases in rad, kept throughout.
        envelope: ``[T]`` modulating function, also the shape of the baseline correction.
        dt: time step in s.
        periods: ``[P]`` matching periods in s.
        target: ``[n, P]`` target PSA of each record in m/s^2.
        tolerance: largest accepted misfit ``exp(max |ln(PSA / target)|) - 1``.
        max_iterations: most amplitude adjustments per record.
        damping: damping ratio of the spectra.

    Returns:
        The best iterate of each record, its misfit and the adjustments it took.
    """
    steps = envelope.size
    frequencies = np.arange(amplitude.shape[1]) / (steps * dt)
    weights = interpolation_weights(np.maximum(frequencies, frequencies[1]), 1.0 / periods)
    coefficients = amplitude * np.exp(1j * phase)
    n = amplitude.shape[0]
    best = np.zeros((n, steps))
    best_misfit = np.full(n, np.inf)
    iterations = np.zeros(n, dtype=int)
    last_improvement = np.zeros(n, dtype=int)
    active = np.arange(n)
    for iteration in range(max_iterations + 1):
        series = np.fft.irfft(coefficients[active], n=steps, axis=-1)
        records = baseline_correct(series * envelope, dt, envelope)
        psa = response_spectrum(records, dt, periods, damping).pseudo_acceleration
        ratio = target[active] / psa
        misfit = np.expm1(np.abs(np.log(ratio)).max(axis=1))
        better = misfit < best_misfit[active]
        last_improvement[active[misfit < best_misfit[active] - MIN_IMPROVEMENT]] = iteration
        improved = active[better]
        best[improved] = records[better]
        best_misfit[improved] = misfit[better]
        iterations[active] = iteration
        keep = (misfit > tolerance) & (iteration - last_improvement[active] < PATIENCE)
        if iteration == max_iterations or not keep.any():
            break
        active = active[keep]
        coefficients[active] *= np.exp(np.log(ratio[keep]) @ weights.T)
    return MatchResult(best, best_misfit, iterations)
