"""Kanai-Tajimi records against the closed-form spectrum, statistically."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.integrate
import scipy.signal
from cphysfno_core import ConfigError, InputError

from cphysfno_plugin_template import KanaiTajimi, kanai_tajimi_psd, kanai_tajimi_variance

S0, WG, ZG = 0.015, 15.6, 0.6


def folded_psd(omega: np.ndarray, dt: float) -> np.ndarray:
    """The Kanai-Tajimi spectrum of samples every ``dt`` s: the continuous spectrum summed
    over its aliases ``omega + 2 pi m / dt``."""
    aliases = 2 * np.pi / dt * np.arange(-20000, 20001)
    return kanai_tajimi_psd(omega[:, None] + aliases, S0, WG, ZG).sum(axis=1)


@pytest.fixture(scope="module")
def records() -> np.ndarray:
    """64 records of 42 s at dt = 0.01 s, the first second (start-up from rest) cut."""
    motions = KanaiTajimi(duration=41.95).sample(64, np.random.default_rng(0))
    return motions.acceleration[:, 100:]


def test_closed_forms_agree() -> None:
    assert kanai_tajimi_psd(0.0, S0, WG, ZG) == pytest.approx(S0)
    peak = S0 * (1 + 4 * ZG**2) / (4 * ZG**2)
    assert kanai_tajimi_psd(WG, S0, WG, ZG) == pytest.approx(peak)
    integral, _ = scipy.integrate.quad(
        lambda w: 2 * kanai_tajimi_psd(w, S0, WG, ZG), 0, np.inf, limit=200
    )
    assert integral == pytest.approx(kanai_tajimi_variance(S0, WG, ZG), rel=1e-8)


def test_variance_is_the_closed_form(records) -> None:
    variance = kanai_tajimi_variance(S0, WG, ZG)
    # 64 records of ~4000 correlated samples: the sample variance is within a few percent
    assert records.var() == pytest.approx(variance, rel=0.03)


def test_power_spectrum_is_the_closed_form(records) -> None:
    frequency, one_sided = scipy.signal.welch(
        records, fs=100.0, nperseg=512, detrend=False, axis=-1
    )
    measured = one_sided.mean(axis=0)[1:-1]
    expected = 4 * np.pi * folded_psd(2 * np.pi * frequency[1:-1], 0.01)
    ratio = measured / expected
    # about 900 Welch segments: each bin scatters by ~4 %, 16-bin bands by ~1 %
    assert abs(ratio.mean() - 1) < 0.01
    assert np.abs(ratio - 1).max() < 0.2
    bands = ratio[: 16 * (len(ratio) // 16)].reshape(-1, 16).mean(axis=1)
    assert np.abs(bands - 1).max() < 0.05
    flat = measured / (4 * np.pi * S0)
    assert flat.max() / flat.min() > 10


def test_records_start_at_rest_on_the_requested_grid() -> None:
    motions = KanaiTajimi(dt=0.02, duration=3.0).sample(3, np.random.default_rng(1))
    assert motions.acceleration.shape == (3, 151)
    assert motions.dt == 0.02
    assert np.array_equal(motions.acceleration[:, 0], np.zeros(3))


def test_bad_requests_are_refused() -> None:
    with pytest.raises(InputError, match="positive integer"):
        KanaiTajimi().sample(0, np.random.default_rng(0))
    with pytest.raises(ConfigError, match=r"kanai-tajimi\.duration"):
        KanaiTajimi(dt=0.1, duration=0.05)
    with pytest.raises(ConfigError, match=r"kanai-tajimi\.ground_damping"):
        KanaiTajimi(ground_damping=0.0)
