"""Spectrum-compatible records: every record of a batch matched to its own target (checked
with the core's response spectrum, not the plugin's own number), retries, the BSSA14 /
Baker-Jayaram target the ensemble follows, baseline correction, determinism, figure,
parameters."""

from __future__ import annotations

import math
import warnings

import cphysfno_core
import numpy as np
import pytest
from cphysfno_core.plugin import get_registry
from cphysfno_core.signals.intensity import response_spectrum
from scipy.integrate import cumulative_trapezoid

from cphysfno_ground_motions import GroundMotionWarning, SpectrumCompatible, plot_spectra
from cphysfno_ground_motions.plots import plot_records

N_RECORDS = 200
BATCH = 40


def independent_misfit(motions, periods) -> np.ndarray:
    """``[n]`` ``exp(max |ln(PSA / target)|) - 1`` of each record against its own drawn
    target, PSA from :func:`cphysfno_core.signals.intensity.response_spectrum`."""
    psa = response_spectrum(motions.acceleration, motions.dt, periods).pseudo_acceleration
    drawn = np.array([m["target_psa"] for m in motions.metadata])
    return np.expm1(np.abs(np.log(psa / drawn)).max(axis=1))


def sample_with_warnings(source, n, seed):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        motions = source.sample(n, np.random.default_rng(seed))
    return motions, [str(w.message) for w in caught if issubclass(w.category, GroundMotionWarning)]


@pytest.fixture(scope="module")
def source() -> SpectrumCompatible:
    return SpectrumCompatible()


@pytest.fixture(scope="module")
def batch(source):
    """40 default records (seed 8), with the warnings their sampling gave."""
    return sample_with_warnings(source, BATCH, 8)


@pytest.fixture(scope="module")
def matched(source):
    """200 default records (seed 2024), with the warnings their sampling gave."""
    return sample_with_warnings(source, N_RECORDS, 2024)


@pytest.fixture(scope="module")
def log_spectra(source, matched):
    """ln PSA of the matched records and of the targets they were drawn, ``[n, P]``."""
    motions, _ = matched
    psa = response_spectrum(motions.acceleration, motions.dt, source.matching_periods)
    drawn = np.array([m["target_psa"] for m in motions.metadata])
    return np.log(psa.pseudo_acceleration), np.log(drawn)


def test_records_are_on_the_paper_grid_with_metadata(source, matched):
    motions, _ = matched
    assert motions.acceleration.shape == (N_RECORDS, 3001)
    assert motions.dt == pytest.approx(0.01)
    meta = motions.metadata[7]
    assert meta["source"] == "spectrum-compatible" and meta["index"] == 7
    assert (meta["magnitude"], meta["rjb_km"], meta["vs30"], meta["mechanism"]) == (
        7.0,
        20.0,
        400.0,
        "SS",
    )
    assert np.allclose(meta["matching_periods"], source.matching_periods)
    assert len(meta["target_psa"]) == source.params.n_periods
    for key in (
        "match_misfit",
        "match_iterations",
        "match_attempts",
        "pga",
        "pgv",
        "arias_intensity",
        "d5_95",
    ):
        assert np.isfinite(meta[key])
    assert 5.0 < meta["d5_95"] < 25.0


def test_every_record_of_a_batch_matches_its_own_target(source, batch):
    """All 40 records lie within 10% of their own drawn target at every matching period,
    after baseline correction, and the misfit in each record's metadata is that misfit."""
    motions, messages = batch
    independent = independent_misfit(motions, source.matching_periods)
    assert independent.max() <= source.params.tolerance, independent
    stored = np.array([m["match_misfit"] for m in motions.metadata])
    np.testing.assert_allclose(stored, independent, rtol=1e-9)
    assert messages == []


def test_records_left_outside_are_retried_with_new_phases(source, batch):
    """Without retries some records of the same batch end outside the tolerance (and a
    warning counts them); with retries exactly those take a second attempt and end inside,
    while the others are the very same records."""
    motions, _ = batch
    first, messages = sample_with_warnings(SpectrumCompatible(retries=0), BATCH, 8)
    outside = independent_misfit(first, source.matching_periods) > source.params.tolerance
    assert outside.sum() >= 2
    assert len(messages) == 1 and f"{outside.sum()} of {BATCH} records" in messages[0]
    attempts = np.array([m["match_attempts"] for m in motions.metadata])
    np.testing.assert_array_equal(attempts > 1, outside)
    np.testing.assert_array_equal(motions.acceleration[~outside], first.acceleration[~outside])


def test_nearly_all_of_many_records_match(source, matched, log_spectra):
    """Of 200 records at least 98% lie within the tolerance at every period; half of all
    ordinates lie within 2% of their target and 90% within 8%; the one warning counts the
    records left outside, and their metadata holds their misfit."""
    motions, messages = matched
    matched_ln, drawn_ln = log_spectra
    independent = np.expm1(np.abs(matched_ln - drawn_ln).max(axis=1))
    stored = np.array([m["match_misfit"] for m in motions.metadata])
    np.testing.assert_allclose(stored, independent, rtol=1e-9)
    outside = int((independent > source.params.tolerance).sum())
    assert outside <= 0.02 * N_RECORDS
    residual = np.abs(matched_ln - drawn_ln)
    assert np.median(residual) < 0.02
    assert np.quantile(residual, 0.9) < 0.08
    if outside:
        assert len(messages) == 1 and f"{outside} of {N_RECORDS} records" in messages[0]
    else:
        assert messages == []


def test_ensemble_follows_the_drawn_targets(log_spectra):
    """Over all records, the matched spectra keep the drawn targets' geometric mean and
    their log-standard deviation within 3% at every matching period."""
    matched_ln, drawn_ln = log_spectra
    mean_ratio = np.exp(matched_ln.mean(axis=0) - drawn_ln.mean(axis=0))
    std_ratio = matched_ln.std(axis=0, ddof=1) / drawn_ln.std(axis=0, ddof=1)
    assert np.all(np.abs(mean_ratio - 1) < 0.03), mean_ratio
    assert np.all(np.abs(std_ratio - 1) < 0.03), std_ratio


def test_ensemble_reproduces_bssa14_median_and_dispersion(source, log_spectra):
    """Against the model itself: median within 12% and log-std within 20% at every period
    (200 records: the sampling error of the median alone is about sigma / sqrt(200) = 5%)."""
    matched_ln, _ = log_spectra
    target = source.target
    median_ratio = np.exp(matched_ln.mean(axis=0)) / target.median
    std_ratio = matched_ln.std(axis=0, ddof=1) / target.ln_std
    assert np.all(np.abs(median_ratio - 1) < 0.12), median_ratio
    assert np.all(np.abs(std_ratio - 1) < 0.20), std_ratio


def test_target_samples_have_bssa14_moments_and_baker_jayaram_correlation(source):
    target = source.target
    draws = np.log(target.sample(4000, np.random.default_rng(11)))
    z = (draws.mean(axis=0) - np.log(target.median)) / (target.ln_std / math.sqrt(4000))
    assert np.all(np.abs(z) < 4.0)
    np.testing.assert_allclose(draws.std(axis=0), target.ln_std, rtol=0.05)
    np.testing.assert_allclose(np.corrcoef(draws.T), target.correlation, atol=0.06)
    assert target.median[0] / 9.80665 == pytest.approx(0.33, rel=0.3)  # M7 at 20 km, ~0.3 g


def test_ground_comes_back_to_rest(matched):
    """Integrated independently (trapezoid twice): final velocity below 1e-6 m/s, final
    displacement below 1e-4 m, and over the last 5 s the displacement stays below 15% of
    each record's peak (no drift)."""
    motions, _ = matched
    velocity = cumulative_trapezoid(motions.acceleration, dx=motions.dt, initial=0, axis=1)
    displacement = cumulative_trapezoid(velocity, dx=motions.dt, initial=0, axis=1)
    assert np.abs(velocity[:, -1]).max() < 1e-6
    assert np.abs(displacement[:, -1]).max() < 1e-4
    tail = np.abs(displacement[:, -500:]).max(axis=1) / np.abs(displacement).max(axis=1)
    assert tail.max() < 0.15


def test_same_generator_state_gives_the_same_records():
    source = SpectrumCompatible(duration=10.0, max_iterations=5, wavelet_iterations=5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GroundMotionWarning)
        first = source.sample(3, np.random.default_rng(5)).acceleration
        second = source.sample(3, np.random.default_rng(5)).acceleration
        other = source.sample(3, np.random.default_rng(6)).acceleration
    np.testing.assert_array_equal(first, second)
    assert not np.allclose(first, other)


def test_median_only_targets_are_matched_tightly():
    """Every record matches the BSSA14 median within a 3% tolerance."""
    source = SpectrumCompatible(variability=False, tolerance=0.03)
    motions, messages = sample_with_warnings(source, 10, 1)
    assert np.allclose(motions.metadata[0]["target_psa"], source.target.median)
    assert independent_misfit(motions, source.matching_periods).max() <= 0.03
    assert messages == []


def test_spectra_figure_is_written(tmp_path, source, matched):
    """Fig. 10(b): the matched records' spectra under the target's median and 2.5-97.5%
    band, and a few acceleration histories."""
    motions, _ = matched
    path = plot_spectra(motions, tmp_path / "fig" / "spectra.png", target=source.target)
    assert path.is_file() and path.stat().st_size > 20_000
    records = plot_records(motions, tmp_path / "records.png", count=3)
    assert records.is_file() and records.stat().st_size > 10_000


def test_reports_get_the_targets_median_and_95_percent_band(source):
    band = source.target_spectrum()
    target = source.target
    np.testing.assert_array_equal(band.periods, source.matching_periods)
    np.testing.assert_allclose(band.median, target.median)
    np.testing.assert_allclose(band.lower, target.median * np.exp(-1.959964 * target.ln_std))
    np.testing.assert_allclose(band.upper, target.median * np.exp(1.959964 * target.ln_std))


def test_registry_creates_it_by_name():
    source = cphysfno_core.create("ground_motion", "spectrum-compatible", magnitude=6.5)
    assert isinstance(source, SpectrumCompatible)
    entry = get_registry().entry("ground_motion", "spectrum-compatible")
    assert entry.distribution.startswith("cphysfno-ground-motions")


@pytest.mark.parametrize(
    ("params", "field"),
    [
        ({"magnitude": 9.0}, "spectrum-compatible.magnitude"),
        ({"rjb_km": -1.0}, "spectrum-compatible.rjb_km"),
        ({"vs30": 100.0}, "spectrum-compatible.vs30"),
        ({"mechanism": "thrust"}, "spectrum-compatible.mechanism"),
        ({"period_band": (2.0, 1.0)}, "spectrum-compatible.period_band"),
        ({"period_band": (0.005, 1.0)}, "spectrum-compatible.period_band"),
        ({"dt": 0.02, "period_band": (0.03, 1.0)}, "spectrum-compatible.period_band: .*Nyquist"),
        ({"tolerance": 0.0}, "spectrum-compatible.tolerance"),
        ({"duration": 0.05}, "spectrum-compatible.duration"),
        ({"duration": 8.0}, "spectrum-compatible.period_band: .*two of its cycles"),
        ({"n_periods": 60}, "spectrum-compatible.n_periods"),
        ({"retries": 5}, "spectrum-compatible.retries"),
        ({"wavelet_iterations": -1}, "spectrum-compatible.wavelet_iterations"),
        ({"seed": 1}, "spectrum-compatible.seed"),
    ],
)
def test_bad_params_name_the_field(params, field):
    with pytest.raises(cphysfno_core.ConfigError, match=field):
        SpectrumCompatible(**params)


def test_bad_record_count_is_an_input_error(source):
    with pytest.raises(cphysfno_core.InputError, match="positive integer"):
        source.sample(0, np.random.default_rng(0))
