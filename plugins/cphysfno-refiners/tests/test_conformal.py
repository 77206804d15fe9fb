"""Split-conformal intervals: the finite-sample quantile by hand, nominal coverage on fresh
records, and an envelope scale that follows the response amplitude."""

import numpy as np
import pytest
from cphysfno_refiners import ConformalRefiner

from cphysfno_core import InputError, NotFittedError
from cphysfno_core.testing import check_refiner


def test_conformal_conforms():
    check_refiner(ConformalRefiner())
    check_refiner(ConformalRefiner(scale="physics-envelope", window=5))


def test_the_interval_is_the_k_th_smallest_score_by_hand():
    u_hat = np.zeros((1, 4, 1))
    u = np.array([3.0, -1.0, 4.0, 2.0]).reshape(1, 4, 1)  # scores 1, 2, 3, 4
    refiner = ConformalRefiner().fit(u_hat, u_hat, u, np.random.default_rng(0))
    for level, k in ((0.5, 3), (0.2, 1), (0.7, 4), (0.99, 4)):  # k = ceil(5 p), at most 4
        lower, upper = refiner.interval(u_hat, u_hat, level)
        np.testing.assert_allclose(upper, float(k), atol=1e-2)
        np.testing.assert_allclose(lower, -float(k), atol=1e-2)


def _heteroscedastic(n_records: int, rng: np.random.Generator):
    """z: sine bursts of varying amplitude; û = z; u = û + noise proportional to |z|'s
    envelope, so that errors are large where the structure moves much."""
    t = np.linspace(0.0, 20.0, 400)
    amplitude = rng.uniform(0.2, 2.0, size=(n_records, 1, 1))
    envelope = np.exp(-(((t - 10.0) / 4.0) ** 2))[None, :, None] + 0.05
    z = amplitude * envelope * np.sin(2 * np.pi * 0.8 * t)[None, :, None] * np.ones((1, 1, 2))
    noise = rng.standard_normal(z.shape) * 0.1 * amplitude * envelope
    return z, z.copy(), z + noise


@pytest.mark.parametrize("scale", ["constant", "physics-envelope"])
def test_fresh_records_are_covered_at_the_nominal_levels(scale):
    rng = np.random.default_rng(7)
    refiner = ConformalRefiner(scale=scale, window=51)
    refiner.fit(*_heteroscedastic(200, rng), rng)
    z, u_hat, u = _heteroscedastic(400, rng)
    for level in (0.68, 0.90):
        lower, upper = refiner.interval(z, u_hat, level)
        covered = np.mean((lower <= u) & (u <= upper), axis=(0, 1))
        np.testing.assert_allclose(covered, level, atol=0.02)
    mean, std = refiner.predict(z, u_hat)
    np.testing.assert_array_equal(mean, u_hat)
    lower, upper = refiner.interval(z, u_hat, 0.6826894921370859)
    np.testing.assert_allclose(std, (upper - lower) / 2)


def test_the_envelope_scale_keeps_coverage_where_the_response_is_small():
    rng = np.random.default_rng(3)
    calibration = _heteroscedastic(200, rng)
    z, u_hat, u = _heteroscedastic(400, rng)
    quiet = (np.abs(z) < np.quantile(np.abs(z), 0.3))[..., 0]
    coverage = {}
    for scale in ("constant", "physics-envelope"):
        refiner = ConformalRefiner(scale=scale, window=51).fit(*calibration, rng)
        lower, upper = refiner.interval(z, u_hat, 0.9)
        inside = ((lower <= u) & (u <= upper))[..., 0]
        width = (upper - lower)[..., 0]
        coverage[scale] = (inside[quiet].mean(), inside[~quiet].mean(), width[quiet].mean())
    # One width for all points over-covers quiet points and under-covers loud ones.
    assert coverage["constant"][0] > 0.97 and coverage["constant"][1] < 0.88
    assert abs(coverage["physics-envelope"][1] - 0.9) < 0.03
    assert coverage["physics-envelope"][2] < 0.5 * coverage["constant"][2]


def test_bad_use_is_refused():
    refiner = ConformalRefiner()
    u = np.zeros((2, 5, 1))
    with pytest.raises(NotFittedError):
        refiner.interval(u, u, 0.9)
    refiner.fit(u, u, u + 1, np.random.default_rng(0))
    with pytest.raises(InputError, match="level must lie in"):
        refiner.interval(u, u, 0.0)
    with pytest.raises(InputError, match="fitted for 1 DOFs"):
        refiner.interval(np.zeros((2, 5, 3)), np.zeros((2, 5, 3)), 0.9)
    with pytest.raises(InputError, match="z is zero"):
        ConformalRefiner(scale="physics-envelope").fit(u, u, u, np.random.default_rng(0))
