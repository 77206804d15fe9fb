"""Lognormal fragility fitting against known curves and a brute-force likelihood."""

import warnings

import numpy as np
import pytest
import scipy.stats

import cphysfno_core as cp
from cphysfno_core import InputError
from cphysfno_core.app.fragility_study import draw
from cphysfno_core.app.metrics_document import MetricsDocument
from cphysfno_core.reporting.fragility import (
    Fragility,
    fit_lognormal,
    fit_with_intervals,
    lognormal_through,
    with_collapse,
)


def _records(n, median, beta, seed):
    """``n`` records with log-uniform intensities over 0.05-3 and exceedance drawn from a
    known lognormal fragility."""
    rng = np.random.default_rng(seed)
    x = np.exp(rng.uniform(np.log(0.05), np.log(3.0), n))
    y = rng.random(n) < scipy.stats.norm.cdf(np.log(x / median) / beta)
    return x, y


def test_a_large_sample_recovers_the_curve_it_was_drawn_from():
    x, y = _records(6000, median=0.5, beta=0.4, seed=1)
    fitted = fit_lognormal(x, y)
    assert fitted.median == pytest.approx(0.5, rel=0.04)
    assert fitted.beta == pytest.approx(0.4, abs=0.03)


def test_the_fit_is_the_maximum_of_the_likelihood():
    x, y = _records(60, median=0.8, beta=0.5, seed=2)
    fitted = fit_lognormal(x, y)
    medians = np.exp(np.linspace(np.log(0.3), np.log(2.0), 301))
    betas = np.linspace(0.1, 1.5, 281)
    m, b = np.meshgrid(medians, betas, indexing="ij")
    z = (np.log(x)[None, None, :] - np.log(m)[..., None]) / b[..., None]
    log_l = np.where(y, scipy.stats.norm.logcdf(z), scipy.stats.norm.logcdf(-z)).sum(axis=-1)
    i, j = np.unravel_index(np.argmax(log_l), log_l.shape)
    assert fitted.median == pytest.approx(medians[i], rel=0.01)
    assert fitted.beta == pytest.approx(betas[j], abs=0.01)


def test_bootstrap_intervals_hold_the_truth_and_narrow_with_more_records():
    rng = np.random.default_rng(3)
    small = fit_with_intervals(*_records(100, 0.5, 0.4, seed=4), rng, n_bootstrap=100)
    large = fit_with_intervals(*_records(1600, 0.5, 0.4, seed=5), rng, n_bootstrap=100)
    for fit in (small, large):
        assert fit.median_interval[0] < 0.5 < fit.median_interval[1]
        assert fit.beta_interval[0] < 0.4 < fit.beta_interval[1]
    width = lambda interval: interval[1] - interval[0]  # noqa: E731
    assert width(large.median_interval) < 0.5 * width(small.median_interval)
    assert large.to_dict()["n_records"] == 1600


def test_collapse_adds_by_total_probability():
    demand, collapse = Fragility(0.4, 0.3), Fragility(1.2, 0.35)
    x = np.array([0.2, 0.4, 1.2, 3.0])
    pc = scipy.stats.norm.cdf(np.log(x / 1.2) / 0.35)
    pd = scipy.stats.norm.cdf(np.log(x / 0.4) / 0.3)
    np.testing.assert_allclose(with_collapse(demand, collapse, x), pc + (1 - pc) * pd)
    np.testing.assert_allclose(with_collapse(demand, None, x), pd)
    grid = np.exp(np.linspace(np.log(0.05), np.log(5.0), 200))
    summary = lognormal_through(demand.probability(grid), grid)
    assert summary.median == pytest.approx(0.4, rel=1e-4)
    assert summary.beta == pytest.approx(0.3, rel=1e-3)


@pytest.mark.parametrize(
    ("exceeded", "message"),
    [
        (np.zeros(5, bool), "no record exceeds it .*lower the limit state"),
        (np.ones(5, bool), "every record exceeds it"),
        (np.ones(4, bool), "intensity and exceedance need one value per record"),
    ],
)
def test_a_fit_without_both_outcomes_says_what_to_change(exceeded, message):
    with pytest.raises(InputError, match=f"pid > 0.01: {message}"):
        fit_lognormal(np.linspace(0.1, 1.0, 5), exceeded, what="pid > 0.01")


class _ThreeRecords:
    """A finite source: at most three records a draw, each scaled by a new random factor,
    with a warning when asked for more (as the recorded source does)."""

    def sample(self, n, rng):
        k = min(n, 3)
        if n > k:
            warnings.warn("only three", cp.CphysfnoWarning, stacklevel=2)
        factors = rng.uniform(1.0, 2.0, size=k)
        return cp.GroundMotions(
            factors[:, None] * np.ones((k, 5)), 0.01, [{"f": f} for f in factors]
        )


def test_a_finite_source_is_drawn_in_rounds_until_there_are_enough():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        motions, largest = draw(_ThreeRecords(), 8, np.random.default_rng(0))
    assert motions.n_records == 8 and largest == 3
    factors = [meta["f"] for meta in motions.metadata]
    np.testing.assert_allclose(motions.acceleration[:, 0], factors)
    assert len(set(factors)) == 8
    single, largest = draw(_ThreeRecords(), 2, np.random.default_rng(0))
    assert single.n_records == 2 and largest == 2


def _metrics(rows):
    """A metrics.json of ``rows`` (label -> the keys that matter), each with test errors."""
    models = {label: {"rmse": [0.0], "rel_l2": [0.1], **row} for label, row in rows.items()}
    return MetricsDocument(models=models, output_names=["roof"], sizes={}, epochs=1)


def test_the_default_model_is_the_best_on_validation_rel_l2_without_edps():
    from cphysfno_core.app.fragility_study import default_model

    rows = {
        "physics-els": {"validation_rel_l2": [0.1], "rel_l2": [0.1]},
        "fno": {"validation_rel_l2": [0.19], "rel_l2": [0.1]},
        "c-physfno-els": {"validation_rel_l2": [0.18, 0.18], "rel_l2": [0.9, 0.9]},
        "refined-c-physfno-els": {"validation_rel_l2": [0.21, 0.21], "rel_l2": [0.1, 0.1]},
        "refined-c-physfno-relaxed": {"validation_rel_l2": [0.3], "rel_l2": [0.1]},
    }
    assert default_model(_metrics(rows)) == "c-physfno-els"
    rows["refined-c-physfno-els"]["validation_rel_l2"] = [0.18, 0.18]
    assert default_model(_metrics(rows)) == "refined-c-physfno-els"
    assert default_model(_metrics({"fno": rows["fno"]})) == "fno"


def _edp_errors(pid: list[float], pfa: list[float]) -> dict:
    return {"PID": {"median": pid, "p90": pid}, "PFA": {"median": pfa, "p90": pfa}}


def test_the_default_model_is_the_best_on_validation_edp_error_of_the_demands():
    from cphysfno_core.app.fragility_study import default_model

    rows = {
        "physics-els": {"validation_edp": _edp_errors([0.01, 0.01], [0.01])},
        "fno": {"validation_rel_l2": [0.1], "validation_edp": _edp_errors([0.05, 0.07], [0.5])},
        "c-physfno-els": {
            "validation_rel_l2": [0.5],
            "validation_edp": _edp_errors([0.08, 0.06], [0.1]),
        },
    }
    # PID alone: fno 0.06 < 0.07; PID and PFA: c-physfno-els (0.08+0.06+0.1)/3 < 0.207
    assert default_model(_metrics(rows), ("PID",)) == "fno"
    assert default_model(_metrics(rows), ("PID", "PFA")) == "c-physfno-els"
    assert default_model(_metrics(rows)) == "c-physfno-els"
