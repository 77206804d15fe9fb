"""White-noise source: determinism, grid, spectrum and variance against paper Eq. (WN)."""

from __future__ import annotations

import math

import cphysfno_core
import numpy as np
import pytest
import scipy.signal
from cphysfno_core.plugin import get_registry

from cphysfno_ground_motions import WhiteNoise

S = 0.015
CUTOFF = 20.0 * math.pi


@pytest.fixture(scope="module")
def records() -> cphysfno_core.GroundMotions:
    return WhiteNoise().sample(200, np.random.default_rng(2024))


def test_same_seed_gives_same_records() -> None:
    source = WhiteNoise()
    first = source.sample(3, np.random.default_rng(7)).acceleration
    second = source.sample(3, np.random.default_rng(7)).acceleration
    other = source.sample(3, np.random.default_rng(8)).acceleration
    np.testing.assert_array_equal(first, second)
    assert not np.allclose(first, other)


def test_paper_grid_and_metadata(records: cphysfno_core.GroundMotions) -> None:
    assert records.acceleration.shape == (200, 3001)
    assert records.acceleration.dtype == np.float64
    assert records.dt == pytest.approx(0.01)
    assert records.duration == pytest.approx(30.0)
    assert records.metadata[5] == {"source": "white-noise", "index": 5}


def test_first_record_is_the_paper_sum_of_cosines() -> None:
    rng = np.random.default_rng(3)
    record = WhiteNoise(n_terms=8, frequency_step=0.5, dt=0.1, duration=2.0).sample(1, rng)
    x = np.random.default_rng(3).standard_normal(8)
    t = np.arange(21) * 0.1
    sigma = math.sqrt(2 * S * 0.5)
    expected = sigma * sum(
        x[j - 1] * np.cos(j * 0.5 * t) + x[4 + j - 1] * np.sin(j * 0.5 * t) for j in range(1, 5)
    )
    np.testing.assert_allclose(record.acceleration[0], expected, rtol=1e-12, atol=1e-14)


def test_two_sided_psd_is_flat_at_s_below_cutoff(records: cphysfno_core.GroundMotions) -> None:
    freq, one_sided = scipy.signal.welch(records.acceleration, fs=1 / records.dt, nperseg=512)
    omega = 2 * math.pi * freq
    two_sided = one_sided.mean(axis=0) / (4 * math.pi)
    band = (omega > 1.0) & (omega < CUTOFF - 3.0)
    assert two_sided[band].mean() == pytest.approx(S, rel=0.05)
    for low, high in [(1.0, 15.0), (15.0, 30.0), (30.0, 45.0), (45.0, CUTOFF - 3.0)]:
        sub = (omega > low) & (omega < high)
        assert two_sided[sub].mean() == pytest.approx(S, rel=0.10)
    assert two_sided[omega > CUTOFF + 5.0].max() < 0.01 * S


def test_variance_is_twice_s_times_cutoff(records: cphysfno_core.GroundMotions) -> None:
    assert records.acceleration.var() == pytest.approx(2 * S * CUTOFF, rel=0.03)
    assert abs(records.acceleration.mean()) < 0.05 * math.sqrt(2 * S * CUTOFF)


def test_registry_creates_it_by_name() -> None:
    source = cphysfno_core.create("ground_motion", "white-noise", duration=10.0)
    assert isinstance(source, WhiteNoise)
    assert source.sample(2, np.random.default_rng(0)).n_steps == 1001
    entry = get_registry().entry("ground_motion", "white-noise")
    assert entry.distribution.startswith("cphysfno-ground-motions")


@pytest.mark.parametrize(
    ("params", "field"),
    [
        ({"spectral_intensity": -1.0}, "white-noise.spectral_intensity"),
        ({"n_terms": 1201}, "white-noise.n_terms"),
        ({"n_terms": 0}, "white-noise.n_terms"),
        ({"frequency_step": 0.0}, "white-noise.frequency_step"),
        ({"dt": 0.06}, "white-noise.dt"),
        ({"duration": 0.001}, "white-noise.duration"),
        ({"spectral_intensity_range": [0.02, 0.01]}, "white-noise.spectral_intensity_range"),
        ({"spectral_intensity_range": [0.0, 0.01]}, "white-noise.spectral_intensity_range"),
        ({"seed": 1}, "white-noise.seed"),
    ],
)
def test_bad_params_name_the_field(params: dict, field: str) -> None:
    with pytest.raises(cphysfno_core.ConfigError, match=field):
        WhiteNoise(**params)


def test_bad_record_count_is_an_input_error() -> None:
    with pytest.raises(cphysfno_core.InputError, match="positive integer"):
        WhiteNoise().sample(0, np.random.default_rng(0))


def test_a_range_of_spectral_intensities_scales_each_record_by_its_own() -> None:
    """The records of a range are those of the fixed density (same coefficients), each
    scaled by sqrt(S_i / S), with S_i log-uniform in the range and in the metadata."""
    fixed = WhiteNoise().sample(400, np.random.default_rng(5))
    ranged = WhiteNoise(spectral_intensity_range=(0.0015, 0.06)).sample(
        400, np.random.default_rng(5)
    )
    intensity = np.array([meta["spectral_intensity"] for meta in ranged.metadata])
    assert intensity.min() >= 0.0015 and intensity.max() <= 0.06
    np.testing.assert_allclose(
        ranged.acceleration, np.sqrt(intensity / S)[:, None] * fixed.acceleration, rtol=1e-12
    )
    # log-uniform: the decades below and above the geometric middle hold about half each
    middle = math.sqrt(0.0015 * 0.06)
    assert 0.4 < np.mean(intensity < middle) < 0.6
    assert fixed.metadata[0] == {"source": "white-noise", "index": 0}
