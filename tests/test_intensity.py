"""Intensity measures against closed-form oscillator and ground-motion results, and the
response spectrum against an independent frequency-domain implementation (pyrotd)."""

import importlib
import importlib.metadata
import math
import sys
import types

import numpy as np
import pytest
import scipy.linalg
import scipy.signal

import cphysfno_core as cp
from cphysfno_core.signals import intensity

ZETA = 0.05


def _step_response(a0, period, zeta, t):
    """Oscillator from rest under a constant base acceleration a0 from t = 0."""
    w = 2 * math.pi / period
    wd = w * math.sqrt(1 - zeta**2)
    decay = np.exp(-zeta * w * t)
    return -(a0 / w**2) * (
        1 - decay * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * t))
    )


def _ramp_response(rate, period, zeta, t):
    """Oscillator from rest under a base acceleration rate * t."""
    w = 2 * math.pi / period
    wd = w * math.sqrt(1 - zeta**2)
    particular = -(rate / w**2) * (t - 2 * zeta / w)
    a = -2 * zeta * rate / w**3
    b = (rate / w**2 + zeta * w * a) / wd
    return particular + np.exp(-zeta * w * t) * (a * np.cos(wd * t) + b * np.sin(wd * t))


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.3])
@pytest.mark.parametrize("period", [0.05, 0.5, 4.0])
def test_oscillator_is_exact_for_step_and_ramp(zeta, period):
    dt = 0.01
    t = np.arange(2001) * dt
    records = np.stack([np.full_like(t, 2.0), 0.3 * t])
    u = intensity.oscillator_displacement(records, dt, period, zeta)
    for got, expected in zip(
        u, [_step_response(2.0, period, zeta, t), _ramp_response(0.3, period, zeta, t)], strict=True
    ):
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
    assert u[:, 0].tolist() == [0.0, 0.0]


def test_update_matrices_agree_with_a_matrix_exponential():
    periods = np.array([0.02, 0.3, 7.0])
    dt = 0.005
    phi, gain_b, gain_c = intensity.oscillator_filters(periods, ZETA, dt)
    for j, period in enumerate(periods):
        w = 2 * math.pi / period
        system = np.zeros((4, 4))
        system[0, 1], system[1, 0], system[1, 1], system[1, 2], system[2, 3] = (
            1.0,
            -w * w,
            -2 * ZETA * w,
            -1.0,
            1.0,
        )
        step = scipy.linalg.expm(system * dt)
        np.testing.assert_allclose(phi[j], step[:2, :2], rtol=1e-10, atol=1e-14)
        np.testing.assert_allclose(gain_c[j], step[:2, 3] / dt, rtol=1e-9, atol=1e-16)
        np.testing.assert_allclose(gain_b[j], step[:2, 2] - step[:2, 3] / dt, rtol=1e-9, atol=1e-16)


def test_spectrum_of_a_step_is_the_dynamic_overshoot():
    dt, a0 = 0.001, 1.5
    record = np.full(8001, a0)
    periods = np.array([0.2, 0.5, 1.0])
    spectrum = intensity.response_spectrum(record, dt, periods)
    w = 2 * math.pi / periods
    overshoot = 1 + math.exp(-ZETA * math.pi / math.sqrt(1 - ZETA**2))
    np.testing.assert_allclose(spectrum.displacement[0], a0 / w**2 * overshoot, rtol=1e-4)
    np.testing.assert_allclose(spectrum.pseudo_acceleration[0], a0 * overshoot, rtol=1e-4)
    np.testing.assert_allclose(spectrum.pseudo_velocity[0], a0 / w * overshoot, rtol=1e-4)


@pytest.fixture(scope="module")
def pyrotd():
    """pyrotd 0.6 reads its own version through pkg_resources, which setuptools >= 81 no
    longer ships; a stand-in answering that one call is enough to import it."""
    with pytest.MonkeyPatch.context() as patch:
        if importlib.util.find_spec("pkg_resources") is None:
            shim = types.ModuleType("pkg_resources")
            shim.get_distribution = lambda name: types.SimpleNamespace(
                version=importlib.metadata.version(name)
            )
            patch.setitem(sys.modules, "pkg_resources", shim)
        return importlib.import_module("pyrotd")


def test_spectrum_agrees_with_pyrotd(pyrotd):
    dt, n = 0.005, 4001
    rng = np.random.default_rng(3)
    band = scipy.signal.butter(4, [0.2, 10.0], btype="band", fs=1 / dt, output="sos")
    records = scipy.signal.sosfiltfilt(band, rng.standard_normal((3, n)), axis=-1)
    records *= np.hanning(n)
    periods = np.geomspace(0.1, 5.0, 12)
    ours = intensity.response_spectrum(records, dt, periods).pseudo_acceleration
    padded = np.concatenate([records, np.zeros((3, 16000))], axis=1)  # no wrap-around
    for i in range(3):
        fourier = np.fft.rfft(padded[i])
        freq = np.linspace(0, 0.5 / dt, fourier.size)
        theirs = [
            pyrotd.calc_oscillator_resp(freq, fourier, ZETA, 1 / t, peak_resp_only=True)
            for t in periods
        ]
        np.testing.assert_allclose(ours[i], theirs, rtol=0.015)


def test_velocity_and_displacement_are_exact_for_a_ramp():
    dt, rate = 0.02, 0.7
    t = np.arange(501) * dt
    velocity, displacement = intensity.velocity_displacement(rate * t, dt)
    np.testing.assert_allclose(velocity[0], rate * t**2 / 2, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(displacement[0], rate * t**3 / 6, rtol=1e-12, atol=1e-15)


def test_peaks_arias_and_significant_duration_of_a_sine():
    dt, amplitude, frequency = 0.001, 2.0, 1.0
    t = np.arange(10001) * dt  # ten whole cycles
    record = amplitude * np.sin(2 * math.pi * frequency * t)
    w = 2 * math.pi * frequency
    assert intensity.peak_ground_acceleration(record)[0] == pytest.approx(amplitude, rel=1e-6)
    assert intensity.peak_ground_velocity(record, dt)[0] == pytest.approx(
        2 * amplitude / w, rel=1e-5
    )
    arias = math.pi / (2 * intensity.STANDARD_GRAVITY) * amplitude**2 * 10.0 / 2
    assert intensity.arias_intensity(record, dt)[0] == pytest.approx(arias, rel=1e-5)
    assert intensity.significant_duration(record, dt)[0] == pytest.approx(9.0, abs=0.01)


def test_arias_and_duration_of_a_constant_record_are_exact():
    dt, level = 0.01, 3.0
    record = np.zeros((2, 1001))
    record[0] = level
    record[1, 200:601] = level  # motion between 2 s and 6 s, ramps of one step at the ends
    arias = intensity.arias_intensity(record, dt)
    assert arias[0] == pytest.approx(math.pi / (2 * 9.80665) * level**2 * 10.0, rel=1e-12)
    durations = intensity.significant_duration(record, dt)
    assert durations[0] == pytest.approx(9.0, rel=1e-12)
    assert durations[1] == pytest.approx(0.9 * 4.0, abs=dt)


def test_still_ground_has_zero_measures():
    still = np.zeros((1, 100))
    assert intensity.significant_duration(still, 0.01)[0] == 0.0
    assert intensity.arias_intensity(still, 0.01)[0] == 0.0
    assert intensity.response_spectrum(still, 0.01, [0.1, 1.0]).displacement.max() == 0.0


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: intensity.response_spectrum(np.zeros((2, 3, 4)), 0.01, [1.0]), "shape"),
        (lambda: intensity.response_spectrum(np.array([0.0, np.nan, 0.0]), 0.01, [1.0]), "NaN"),
        (lambda: intensity.response_spectrum(np.zeros(10), 0.01, [0.0, 1.0]), "periods"),
        (lambda: intensity.response_spectrum(np.zeros(10), 0.01, [1.0], damping=1.0), "damping"),
        (lambda: intensity.response_spectrum(np.zeros(10), -0.01, [1.0]), "dt"),
        (lambda: intensity.significant_duration(np.zeros(10), 0.01, 0.9, 0.1), "start < end"),
    ],
)
def test_bad_input_is_an_input_error(call, message):
    with pytest.raises(cp.InputError, match=message):
        call()


def test_spectral_acceleration_of_a_slowly_growing_sine_is_its_steady_state():
    """Under ``a_g = A sin(w t)``, brought in smoothly (a sin^2 envelope over 60 s) so that
    no transient overshoots, a 5 % damped oscillator of period T settles at the amplitude
    ``A / |w_n^2 - w^2 + 2 i zeta w_n w|``; Sa is ``w_n^2`` times it (within 0.13 %)."""
    dt, amplitude, w = 0.01, 2.0, 2 * np.pi / 2.0
    t = np.arange(int(200.0 / dt) + 1) * dt
    ag = amplitude * np.sin(w * t) * np.where(t < 60.0, np.sin(np.pi * t / 120.0) ** 2, 1.0)
    for period in (0.5, 1.0, 3.0):
        wn = 2 * np.pi / period
        steady = wn**2 * amplitude / abs(wn**2 - w**2 + 2j * 0.05 * wn * w)
        found = intensity.spectral_acceleration(ag[None], dt, period)
        np.testing.assert_allclose(found, [steady], rtol=5e-3)
