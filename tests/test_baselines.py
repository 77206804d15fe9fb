"""The baselines an engineer would fit instead of a surrogate: the cloud regression against
the closed-form least-squares line, the Gaussian process against its own likelihood and on
synthetic data whose law is known."""

import numpy as np
import pytest

from cphysfno_core import GroundMotions, InputError
from cphysfno_core.reporting import baselines
from cphysfno_core.signals.intensity import average_spectral_acceleration, response_spectrum


def test_the_cloud_regression_is_the_closed_form_least_squares_line():
    rng = np.random.default_rng(1)
    im = np.exp(rng.normal(0.0, 0.6, 40))
    pid = np.exp(-4.0 + 0.9 * np.log(im) + rng.normal(0.0, 0.3, 40))
    pfa = np.exp(1.0 + 0.5 * np.log(im) + rng.normal(0.0, 0.2, 40))
    pfa[3] = np.nan  # a failed record: left out of that column only
    cloud = baselines.CloudRegression().fit(im, np.column_stack([pid, pfa]))
    for column, values in enumerate((pid, pfa)):
        keep = np.isfinite(values)
        x, y = np.log(im[keep]), np.log(values[keep])
        slope = np.sum((x - x.mean()) * (y - y.mean())) / np.sum((x - x.mean()) ** 2)
        intercept = y.mean() - slope * x.mean()
        beta = np.sqrt(np.sum((y - intercept - slope * x) ** 2) / (x.size - 2))
        fit = cloud.columns_[column]
        np.testing.assert_allclose([fit.intercept, fit.slope, fit.beta], [intercept, slope, beta])
    new = np.array([0.5, 2.0])
    expected = np.exp(cloud.columns_[0].intercept + cloud.columns_[0].slope * np.log(new))
    np.testing.assert_allclose(cloud.predict(new)[:, 0], expected)


def test_too_few_records_or_a_zero_intensity_give_nan_not_a_fit():
    im = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    values = np.column_stack([im**2, [1.0, 2.0, np.nan, 0.0, np.nan, 3.0]])
    predicted = baselines.CloudRegression().fit(im, values).predict(np.array([2.5, 0.0]))
    np.testing.assert_allclose(predicted[0, 0], 2.5**2)
    assert np.isnan(predicted[:, 1]).all()  # three valid records < MIN_RECORDS
    assert np.isnan(predicted[1]).all()  # Sa = 0 has no logarithm


def test_the_likelihood_gradient_agrees_with_finite_differences():
    rng = np.random.default_rng(2)
    x = rng.normal(size=(12, 3))
    y = np.sin(x[:, 0]) + 0.1 * rng.normal(size=12)
    squared = (x[:, None, :] - x[None, :, :]) ** 2
    theta = np.array([0.2, -0.1, 0.3, 0.5, -1.0])
    _, grad = baselines._negative_log_likelihood(theta, squared, y)
    step = 1e-6
    numeric = [
        (
            baselines._negative_log_likelihood(theta + step * e, squared, y)[0]
            - baselines._negative_log_likelihood(theta - step * e, squared, y)[0]
        )
        / (2 * step)
        for e in np.eye(theta.size)
    ]
    np.testing.assert_allclose(grad, numeric, rtol=1e-5, atol=1e-8)


def test_the_gaussian_process_learns_a_nonlinear_law_to_its_noise_level():
    rng = np.random.default_rng(0)
    im = np.exp(rng.normal(0.0, 0.7, (400, 3)))
    x = np.log(im)
    noise = 0.05
    law = 0.3 + 1.1 * x[:, 0] + 0.3 * np.sin(2.0 * x[:, 1])
    values = np.exp(law + rng.normal(0.0, noise, 400))[:, None]
    gp = baselines.GaussianProcess().fit(im[:300], values[:300])
    error = np.abs(np.log(gp.predict(im[300:]) / values[300:]))
    # |N(0, 0.05)| has median 0.034; the cloud on the first measure alone cannot follow x_1
    assert np.median(error) < 1.3 * 0.6745 * noise
    cloud = baselines.CloudRegression().fit(im[:300, 0], values[:300])
    assert np.median(np.abs(np.log(cloud.predict(im[300:, 0]) / values[300:]))) > 3 * noise


def test_the_gaussian_process_extrapolates_a_linear_law_along_its_trend():
    rng = np.random.default_rng(3)
    im = np.exp(rng.normal(0.0, 0.5, (60, 2)))
    values = np.exp(0.5 + 0.8 * np.log(im[:, 0]) - 0.3 * np.log(im[:, 1]))[:, None]
    far = np.array([[20.0, 0.1]])
    predicted = baselines.GaussianProcess().fit(im, values).predict(far)
    np.testing.assert_allclose(predicted[0, 0], np.exp(0.5 + 0.8 * np.log(20.0) + 0.3 * np.log(10)))


def test_a_baseline_must_be_fitted_and_given_its_number_of_measures():
    with pytest.raises(InputError, match="not fitted"):
        baselines.GaussianProcess().predict(np.ones((3, 2)))
    fitted = baselines.CloudRegression().fit(np.arange(1.0, 9.0), np.arange(1.0, 9.0)[:, None])
    with pytest.raises(InputError, match="fitted on 1 measures, given 2"):
        fitted.predict(np.ones((3, 2)))
    with pytest.raises(InputError, match="n_edps"):
        baselines.CloudRegression().fit(np.ones(4), np.ones(3))


def test_average_spectral_acceleration_is_the_geometric_mean_of_the_spectrum():
    rng = np.random.default_rng(4)
    ag = rng.normal(size=(2, 600))
    periods = np.geomspace(0.1, 1.5, 10)
    spectrum = response_spectrum(ag, 0.01, periods).pseudo_acceleration
    expected = np.prod(spectrum, axis=1) ** (1 / 10)
    np.testing.assert_allclose(average_spectral_acceleration(ag, 0.01, 0.1, 1.5), expected)
    single = average_spectral_acceleration(ag, 0.01, 0.4, 0.4, n_periods=1)
    np.testing.assert_allclose(single, response_spectrum(ag, 0.01, [0.4]).pseudo_acceleration[:, 0])
    with pytest.raises(InputError, match="0 < low <= high"):
        average_spectral_acceleration(ag, 0.01, 1.0, 0.5)


def test_the_intensity_vector_holds_each_named_measure_in_order():
    rng = np.random.default_rng(5)
    motions = GroundMotions(rng.normal(size=(3, 800)), 0.01)
    vector = baselines.intensity_vector(motions, 0.5)
    assert vector.shape == (3, len(baselines.GP_INTENSITY_MEASURES))
    names = list(baselines.GP_INTENSITY_MEASURES)
    np.testing.assert_allclose(vector[:, names.index("PGA")], np.abs(motions.acceleration).max(1))
    np.testing.assert_allclose(vector[:, names.index("Sa(T1)")], baselines.sa_t1(motions, 0.5))
    twice = response_spectrum(motions.acceleration, 0.01, [1.0]).pseudo_acceleration[:, 0]
    np.testing.assert_allclose(vector[:, names.index("Sa(2 T1)")], twice)


def _row(pid, pfa):
    return {"edp": {"PID": {"median": pid, "p90": pid}, "PFA": {"median": pfa, "p90": pfa}}}


def test_a_baseline_that_beats_every_trained_model_is_named_with_both_errors():
    models = {
        "physics-els": _row([0.01, 0.01], [0.01]),  # physics is not a trained model
        "fno": _row([0.20, 0.10], [0.30]),
        "c-physfno-els": _row([0.15, 0.04], [0.25]),
    }
    found_baselines = {
        "baseline-cloud": _row([0.12, 0.09], [0.40]),
        "baseline-gp": _row([0.10, float("nan")], [0.35]),
    }
    names = {"PID": ["story-1", "story-2"], "PFA": ["roof"]}
    beaten = baselines.beaten_surrogates(models, found_baselines, names)
    assert beaten == [
        {
            "edp": "PID",
            "location": "story-1",
            "baseline": "baseline-gp",
            "baseline_error": 0.10,
            "surrogate": "c-physfno-els",
            "surrogate_error": 0.15,
        }
    ]
    (line,) = baselines.describe_beaten(beaten)
    assert "PID" in line and "story-1 (baseline-gp 0.100 against c-physfno-els 0.150)" in line
    assert baselines.beaten_surrogates({}, found_baselines, names) == []
