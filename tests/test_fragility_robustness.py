"""What keeps a fragility study going: prediction past the records it cannot predict, the
intensity measures by name, and the flags on fits the records do not determine."""

import numpy as np
import pytest

from cphysfno_core import ConfigError, CphysfnoError, GroundMotions, InputError
from cphysfno_core.app.fragility_study import LimitState, surrogate_outcomes
from cphysfno_core.model.composite import Prediction
from cphysfno_core.model.skipping import predict_skipping_failures
from cphysfno_core.plugin import Stories
from cphysfno_core.reporting.edp import EDPs
from cphysfno_core.reporting.fragility import Fragility, fit_flags
from cphysfno_core.reporting.intensity_measures import intensity_measure
from cphysfno_core.signals.intensity import average_spectral_acceleration, response_spectrum


class _Doubling:
    """Predicts twice the ground motion as displacement (or its parameter ``k`` times it)
    and three times it as acceleration; raises for a batch holding a record that starts at
    99, and gives NaN for one that starts at -1."""

    def predict_stages(self, motions, params=None):
        ag = motions.acceleration
        if np.any(ag[:, 0] == 99.0):
            raise InputError("z holds NaN or Inf (first in record 0)")
        factor = params["k"][:, None, None] if params else 2.0
        mean = factor * ag[:, :, None]
        mean[ag[:, 0] == -1.0] = np.nan
        return Prediction(None, mean, mean, np.zeros_like(mean), 3.0 * ag[:, :, None])


def test_prediction_goes_on_past_the_records_that_fail():
    ag = np.ones((4, 5))
    ag[1, 0], ag[3, 0] = 99.0, -1.0
    responses, failures = predict_skipping_failures(_Doubling(), GroundMotions(ag, 0.01))
    mean = responses.displacement
    np.testing.assert_array_equal(mean[[0, 2], :, 0], 2.0 * ag[[0, 2]])
    acceleration = responses.extras["absolute_acceleration"]
    np.testing.assert_array_equal(acceleration[[0, 2], :, 0], 3.0 * ag[[0, 2]])
    assert np.isnan(mean[[1, 3]]).all() and np.isnan(acceleration[[1, 3]]).all()
    assert failures == {
        1: "z holds NaN or Inf (first in record 0)",
        3: "the prediction is not finite",
    }
    k = np.array([1.0, 5.0, 2.0, 4.0])
    each, _ = predict_skipping_failures(_Doubling(), GroundMotions(ag, 0.01), {"k": k})
    np.testing.assert_array_equal(each.displacement[[0, 2], :, 0], k[[0, 2], None] * ag[[0, 2]])
    clean, none = predict_skipping_failures(_Doubling(), GroundMotions(np.ones((2, 5)), 0.01))
    assert none == {} and np.isfinite(clean.displacement).all()
    with pytest.raises(CphysfnoError, match="no record could be predicted"):
        predict_skipping_failures(_Doubling(), GroundMotions(np.full((2, 5), 99.0), 0.01))


class _Collapsing(_Doubling):
    """A model on physics that can collapse: z is NaN for a record that starts at -2 (its
    prediction too); and as :class:`_Doubling` otherwise."""

    class preprocessor:
        collapses = True

    def predict_stages(self, motions, params=None):
        ag = motions.acceleration
        found = super().predict_stages(motions, params)
        z = ag[:, :, None].copy()
        z[ag[:, 0] == -2.0] = np.nan
        found.mean[ag[:, 0] == -2.0] = np.nan
        return Prediction(z, found.operator_output, found.mean, found.std, found.acceleration)


def test_a_record_whose_physics_collapses_is_flagged_not_failed():
    ag = np.ones((4, 5))
    ag[1, 0], ag[3, 0] = -2.0, -1.0
    responses, failures = predict_skipping_failures(_Collapsing(), GroundMotions(ag, 0.01))
    assert responses.collapsed.tolist() == [False, True, False, False]
    assert failures == {3: "the prediction is not finite"}
    assert np.isnan(responses.displacement[1]).all()
    assert np.isnan(responses.extras["absolute_acceleration"][1]).all()
    ag[2, 0] = 99.0  # one record raises: the rest are predicted one by one, flags kept
    responses, failures = predict_skipping_failures(_Collapsing(), GroundMotions(ag, 0.01))
    assert responses.collapsed.tolist() == [False, True, False, False]
    assert sorted(failures) == [2, 3]
    _Collapsing.preprocessor.collapses = False  # physics that cannot collapse: NaN fails
    try:
        responses, failures = predict_skipping_failures(_Collapsing(), GroundMotions(ag, 0.01))
    finally:
        _Collapsing.preprocessor.collapses = True
    assert not responses.collapsed.any() and sorted(failures) == [1, 2, 3]


def test_a_collapse_of_the_surrogates_physics_exceeds_every_limit_state():
    pid = np.array([[0.004, 0.012], [np.nan, np.nan], [0.02, 0.001], [np.nan, np.nan]])
    demands = EDPs.from_tables({"PID": pid}, Stories.stacked((3.0, 3.0)))
    collapsed = np.array([False, True, False, False])
    for threshold, exceeded in ((0.01, [True, True, True]), (0.05, [False, True, False])):
        state = LimitState("pid", threshold)
        known, found = surrogate_outcomes(demands, collapsed, state)
        assert known.tolist() == [True, True, True, False]  # record 3 failed: unknown
        assert found[known].tolist() == exceeded


def test_intensity_measures_by_name():
    rng = np.random.default_rng(0)
    motions = GroundMotions(rng.normal(size=(3, 700)), 0.01)
    ag = motions.acceleration
    sa = intensity_measure("sa:0.75", first_period=0.3)
    np.testing.assert_allclose(
        sa.of(motions), response_spectrum(ag, 0.01, [0.75]).pseudo_acceleration[:, 0]
    )
    assert sa.unit == "m/s^2" and sa.periods_s == (0.75,)
    t1 = intensity_measure("SA-T1", first_period=0.3)
    assert t1.description == "Sa(0.3 s), 5 % damped"
    average = intensity_measure("sa-avg", first_period=0.5)
    assert average.periods_s == pytest.approx((0.1, 1.5))
    np.testing.assert_allclose(
        average.of(motions), average_spectral_acceleration(ag, 0.01, 0.1, 1.5)
    )
    ranged = intensity_measure("sa-avg:0.2-2", first_period=0.5)
    assert ranged.periods_s == (0.2, 2.0)
    np.testing.assert_allclose(intensity_measure("pga", 1.0).of(motions), np.abs(ag).max(axis=1))
    assert intensity_measure("pgv", 1.0).unit == "m/s"
    for bad, message in (
        ("arias", "unknown intensity measure 'arias'"),
        ("sa:abc", "periods must be numbers of s > 0"),
        ("sa-avg:2-1", "the range must rise"),
        ("sa-avg:1", "sa-avg:A-B"),
    ):
        with pytest.raises(ConfigError, match=message):
            intensity_measure(bad, 1.0)


def test_flags_name_what_the_records_do_not_determine():
    x = np.linspace(1.0, 10.0, 20)
    exceeded = x > 5.0
    assert fit_flags(Fragility(5.0, 0.4), x, exceeded) == ()
    flags = fit_flags(Fragility(30.0, 1e-3), x, x > 9.0)
    assert flags == (
        "beta 0.001 at its bound",
        "only 3 of 20 records exceed it",
        "median 30 outside the records' intensities (1-10)",
    )
    assert fit_flags(Fragility(1.5, 0.4), x, x > 1.5) == ("only 2 of 20 records stay below it",)
