"""The refiner passes the conformance checks every refiner must pass."""

from cphysfno_refiners import LinearRegressionRefiner

from cphysfno_core.testing import check_refiner


def test_linear_regression_conforms():
    check_refiner(LinearRegressionRefiner(n_points=200))
