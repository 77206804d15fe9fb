"""The two matching stages: wavelets checked against an independent oscillator solver and
for drift, the time-domain stage finishing what the frequency-domain stage leaves, and the
crest-factor limit that retries use."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
from cphysfno_core.signals.intensity import response_spectrum, velocity_displacement
from scipy.integrate import cumulative_trapezoid

from cphysfno_ground_motions import SpectrumCompatible
from cphysfno_ground_motions.matching import (
    WaveletBasis,
    match_amplitudes,
    match_wavelets,
    series_frequencies,
)
from cphysfno_ground_motions.spectrum_compatible import jennings_envelope

DT = 0.01
STEPS = 3001
PERIODS = np.geomspace(0.1, 5.0, 20)
TOLERANCE = 0.1


@pytest.fixture(scope="module")
def envelope() -> np.ndarray:
    return jennings_envelope(np.arange(STEPS) * DT, 2.0, 10.0, 0.3)


def starting_point(spectra: np.ndarray, rng: np.random.Generator):
    """Target-shaped amplitudes and random phases for ``spectra`` ``[n, P]``."""
    source = SpectrumCompatible()
    amplitude = source._starting_amplitude(spectra, series_frequencies(STEPS, DT))
    return amplitude, rng.uniform(0.0, 2.0 * np.pi, size=amplitude.shape)


def test_wavelets_leave_the_ground_at_rest():
    """Integrated independently (trapezoid twice), each wavelet ends with a velocity below
    1e-3 and a displacement below 1e-2 of their peaks: it needs no baseline correction."""
    basis = WaveletBasis.build(PERIODS, 0.05, DT, STEPS)
    for template in basis.templates:
        velocity = cumulative_trapezoid(template, dx=DT, initial=0.0)
        displacement = cumulative_trapezoid(velocity, dx=DT, initial=0.0)
        assert abs(velocity[-1]) < 1e-3 * np.abs(velocity).max()
        assert abs(displacement[-1]) < 1e-2 * np.abs(displacement).max()


def test_wavelet_effects_match_an_independent_oscillator():
    """The linear system the time-domain stage solves: the response of each oscillator, at
    the sample its wavelet aims at, to a sum of wavelets equals ``effects @ amplitude``;
    responses from scipy's ``lsim`` of ``u'' + 2 zeta w u' + w^2 u = -a(t)`` with the
    acceleration linear between samples."""
    steps = 6001
    basis = WaveletBasis.build(PERIODS, 0.05, DT, steps)
    rng = np.random.default_rng(0)
    index = rng.integers(2500, 3500, size=(1, PERIODS.size))
    amplitude = rng.normal(size=(1, PERIODS.size))
    acceleration = basis.synthesize(index, amplitude, steps)[0]
    time = np.arange(steps) * DT
    predicted = basis.effects(index)[0] @ amplitude[0]
    for i, period in enumerate(PERIODS):
        omega = 2.0 * np.pi / period
        oscillator = scipy.signal.StateSpace(
            [[0.0, 1.0], [-(omega**2), -0.1 * omega]], [[0.0], [-1.0]], [[1.0, 0.0]], [[0.0]]
        )
        _, displacement, _ = scipy.signal.lsim(oscillator, acceleration, time, interp=True)
        assert displacement[index[0, i]] == pytest.approx(predicted[i], abs=1e-8)


def test_wavelets_finish_what_the_frequency_stage_leaves(envelope):
    """Of 30 drawn targets, the frequency-domain stage leaves most records outside the
    10% tolerance; wavelets bring at least 80% of those inside, no record gets worse, the
    records stay baseline-corrected, and those adjusted have a PGA within their target PSA
    at the shortest period."""
    target = SpectrumCompatible().target
    rng = np.random.default_rng(3)
    spectra = target.sample(30, rng)
    amplitude, phase = starting_point(spectra, rng)
    first = match_amplitudes(
        amplitude, phase, envelope, DT, PERIODS, spectra, tolerance=TOLERANCE, max_iterations=10
    )
    second = match_wavelets(
        first.acceleration, envelope, DT, PERIODS, spectra, tolerance=TOLERANCE, max_iterations=40
    )
    psa = response_spectrum(second.acceleration, DT, PERIODS).pseudo_acceleration
    independent = np.expm1(np.abs(np.log(psa / spectra)).max(axis=1))
    np.testing.assert_allclose(second.misfit, independent, rtol=1e-9)
    left = first.misfit > TOLERANCE
    assert left.sum() >= 15
    assert (independent[left] <= TOLERANCE).mean() >= 0.8
    assert np.all(second.misfit <= first.misfit * (1.0 + 1e-9))  # two spectrum solvers
    velocity, displacement = velocity_displacement(second.acceleration, DT)
    assert np.abs(velocity[:, -1]).max() < 1e-9 and np.abs(displacement[:, -1]).max() < 1e-9
    adjusted = second.iterations > 0
    pga = np.abs(second.acceleration[adjusted]).max(axis=1)
    assert np.all(pga <= 1.01 * spectra[adjusted, 0])


def test_crest_limit_lowers_the_pga_a_spectrum_needs(envelope):
    """Matched to the same median spectrum from the same start, series clipped at 1.6
    standard deviations give records whose largest PSA is at least 1.5 times as many PGAs
    as unclipped ones."""
    target = SpectrumCompatible().target
    spectra = np.tile(target.median, (20, 1))
    amplitude, phase = starting_point(spectra, np.random.default_rng(0))
    amplification = {}
    for crest in (None, 1.6):
        result = match_amplitudes(
            amplitude,
            phase,
            envelope,
            DT,
            PERIODS,
            spectra,
            tolerance=TOLERANCE,
            max_iterations=10,
            crest_factor=crest,
        )
        assert np.median(result.misfit) < 0.15
        psa = response_spectrum(result.acceleration, DT, PERIODS).pseudo_acceleration
        amplification[crest] = np.mean(psa.max(axis=1) / np.abs(result.acceleration).max(axis=1))
    assert amplification[1.6] > 1.5 * amplification[None]


def test_amplitudes_on_the_wrong_grid_are_refused(envelope):
    spectra = SpectrumCompatible().target.median[None, :]
    with pytest.raises(ValueError, match="frequencies"):
        match_amplitudes(
            np.ones((1, STEPS // 2 + 1)),
            np.zeros((1, STEPS // 2 + 1)),
            envelope,
            DT,
            PERIODS,
            spectra,
            tolerance=TOLERANCE,
            max_iterations=1,
        )
