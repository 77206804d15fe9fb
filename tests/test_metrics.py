import numpy as np
import pytest
import torch

import cphysfno_core as cp
from cphysfno_core.model.training import relative_l2_loss
from cphysfno_core.reporting import metrics


def _pair():
    truth = np.zeros((2, 2, 2))
    truth[:, :, 0] = [[1.0, 2.0], [3.0, 4.0]]
    truth[:, :, 1] = [[1.0, -1.0], [1.0, -1.0]]
    prediction = truth.copy()
    prediction[:, :, 0] += [[1.0, 0.0], [0.0, -1.0]]
    prediction[:, :, 1] = 0.0
    return prediction, truth


def test_rmse_by_hand():
    prediction, truth = _pair()
    # DOF 0: errors 1, 0, 0, -1 -> sqrt(2/4); DOF 1: errors all 1 -> 1
    np.testing.assert_allclose(metrics.rmse(prediction, truth), [np.sqrt(0.5), 1.0])


def test_relative_l2_by_hand():
    prediction, truth = _pair()
    # DOF 0: sqrt(2 / (1 + 4 + 9 + 16)); DOF 1: sqrt(4 / 4)
    np.testing.assert_allclose(metrics.relative_l2(prediction, truth), [np.sqrt(2 / 30), 1.0])


def test_peak_r2_by_hand():
    truth = np.zeros((3, 2, 1))
    truth[:, 0, 0] = [1.0, 2.0, 3.0]
    prediction = np.zeros((3, 2, 1))
    prediction[:, 1, 0] = [-1.0, 2.5, 2.5]  # peaks of |u|: 1, 2.5, 2.5
    # SS_res = 0 + 0.25 + 0.25; SS_tot = 1 + 0 + 1 -> R^2 = 1 - 0.5 / 2
    assert metrics.peak_r2(prediction, truth) == pytest.approx(0.75)


def test_peak_r2_of_records_whose_peaks_do_not_vary_is_nan():
    one = np.ones((1, 5, 2))
    assert np.isnan(metrics.peak_r2(2.0 * one, one))


def test_coverage_by_hand():
    truth = np.array([[[0.0], [1.0], [2.0], [3.0]]])
    mean = np.zeros_like(truth)
    np.testing.assert_allclose(metrics.coverage(mean, np.full_like(truth, 1.5), truth), [0.5])


def test_metrics_refuse_mismatched_shapes():
    with pytest.raises(cp.InputError, match="must both be"):
        metrics.rmse(np.zeros((2, 3, 1)), np.zeros((2, 3, 2)))


def test_relative_l2_loss_is_the_papers_ratio_of_sums():
    prediction, truth = _pair()
    error_norms = np.linalg.norm(prediction - truth, axis=1).sum()
    truth_norms = np.linalg.norm(truth, axis=1).sum()
    loss = relative_l2_loss(torch.tensor(prediction), torch.tensor(truth))
    assert loss.item() == pytest.approx(error_norms / truth_norms)
    # by hand: error norms DOF0 rec0 1, rec1 1, DOF1 sqrt2 twice; truth sqrt5, 5, sqrt2, sqrt2
    assert loss.item() == pytest.approx((2 + 2 * np.sqrt(2)) / (np.sqrt(5) + 5 + 2 * np.sqrt(2)))


def test_interval_coverage_counts_points_inside_by_hand():
    truth = np.array([[[0.0], [1.0], [2.0], [3.0]]])
    lower = np.array([[[-1.0], [1.5], [2.0], [0.0]]])
    upper = lower + 2.0  # intervals [-1, 1], [1.5, 3.5], [2, 4], [0, 2]
    np.testing.assert_allclose(metrics.interval_coverage(lower, upper, truth), [0.5])


def test_coverage_standard_error_is_over_records_by_hand():
    truth = np.zeros((3, 2, 1))
    lower = np.array([[-1.0, -1.0], [-1.0, 1.0], [1.0, 1.0]])[..., None]  # 2, 1, 0 inside
    upper = lower + 2.0
    # per-record coverage 1, 0.5, 0: mean 0.5, sample std 0.5, over sqrt(3) records
    np.testing.assert_allclose(metrics.interval_coverage(lower, upper, truth), [0.5])
    np.testing.assert_allclose(
        metrics.coverage_standard_error(lower, upper, truth), [0.5 / np.sqrt(3.0)]
    )
    # calibrated on 6 other records: 0.5 * sqrt(1/3 + 1/6)
    np.testing.assert_allclose(
        metrics.coverage_standard_error(lower, upper, truth, calibration_records=6),
        [0.5 * np.sqrt(0.5)],
    )
    with pytest.raises(cp.InputError, match="calibration_records must be positive"):
        metrics.coverage_standard_error(lower, upper, truth, calibration_records=0)


def test_the_calibrated_standard_error_matches_resampled_split_conformal():
    rng = np.random.default_rng(0)
    n_records, n_steps = 300, 200
    # record-to-record spread of the error size, as a trained operator has
    scale = np.exp(0.4 * rng.standard_normal((n_records, 1, 1)))
    errors = scale * rng.standard_normal((n_records, n_steps, 1))
    level, n_cal = 0.68, 100
    misses, predicted = [], []
    for _ in range(400):
        order = rng.permutation(n_records)
        calibration, test = errors[order[:n_cal]], errors[order[n_cal:]]
        scores = np.sort(np.abs(calibration).ravel())
        q = scores[int(np.ceil((scores.size + 1) * level)) - 1]
        lower, upper = np.full_like(test, -q), np.full_like(test, q)
        misses.append(metrics.interval_coverage(lower, upper, test)[0] - level)
        predicted.append(
            metrics.coverage_standard_error(lower, upper, test, calibration_records=n_cal)[0]
        )
    assert abs(np.mean(misses)) < 0.005
    assert np.std(misses) == pytest.approx(np.mean(predicted), rel=0.15)


def test_a_refiners_default_interval_is_the_gaussian_quantile_band():
    from toy_components import ToyRefiner

    refiner = ToyRefiner()
    refiner.load_state_dict({"offset": np.array([0.5]), "sigma": np.array([2.0])})
    u_hat = np.zeros((1, 3, 1))
    lower, upper = refiner.interval(u_hat, u_hat, 0.90)
    np.testing.assert_allclose(upper - 0.5, 2.0 * 1.6448536, rtol=1e-6)
    np.testing.assert_allclose(lower - 0.5, -2.0 * 1.6448536, rtol=1e-6)
    lower68, upper68 = refiner.interval(u_hat, u_hat, 0.68)
    np.testing.assert_allclose(upper68 - 0.5, 2.0 * 0.9944579, rtol=1e-6)
    with pytest.raises(cp.InputError, match="level must lie in"):
        refiner.interval(u_hat, u_hat, 1.0)


def test_record_relative_l2_is_the_median_of_each_records_by_hand():
    truth = np.zeros((4, 2, 1))
    truth[:, :, 0] = [[3.0, 4.0], [1.0, 0.0], [0.0, 2.0], [0.0, 0.0]]
    prediction = truth.copy()
    prediction[0, 0, 0] += 1.0  # record 0: 1 / 5
    prediction[1, 1, 0] += 0.5  # record 1: 0.5 / 1
    prediction[3, 0, 0] += 7.0  # record 3 has no response: left out
    # record 2: 0; the median of 0.2, 0.5 and 0
    assert metrics.record_relative_l2(prediction, truth).tolist() == pytest.approx([0.2])


def test_the_largest_records_share_by_hand():
    truth = np.zeros((3, 2, 2))
    truth[0, 0, 0] = 1.0
    truth[1, :, :] = 1.0  # 4
    truth[2, 1, 1] = np.sqrt(3.0)  # 3
    assert metrics.largest_record_share(truth) == pytest.approx(0.5)
