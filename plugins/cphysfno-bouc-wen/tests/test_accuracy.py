"""The fine-grid simulator against a tight solve_ivp solution, and the response level."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_core import GroundMotions

from cphysfno_bouc_wen import BoucWenShearBuilding

DESIGN_RMS = np.array([0.0039, 0.0075, 0.0109, 0.0146, 0.0195])


@pytest.fixture(scope="module")
def hardest(white_noise) -> GroundMotions:
    """The most strongly yielding of six paper white-noise records."""
    candidates = GroundMotions(white_noise(6, seed=101), 0.01)
    drift = BoucWenShearBuilding().simulate(candidates).extras["story_drift"]
    hardest = int(np.argmax(np.abs(drift).max(axis=(1, 2))))
    assert np.abs(drift[hardest]).max() > 1.5 * 0.01
    return candidates[hardest]


@pytest.fixture(scope="module")
def reference(hardest, matrices, reference_rhs, piecewise_solver) -> np.ndarray:
    _, _, damping = matrices
    return piecewise_solver(
        reference_rhs,
        np.zeros(15),
        hardest.acceleration[0],
        0.01,
        rtol=1e-10,
        atol=1e-13,
        args=(damping,),
    )


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_fine_grid_matches_tight_solve_ivp(hardest, reference, rel_l2, precision) -> None:
    simulated = BoucWenShearBuilding(precision=precision).simulate(hardest)
    error = rel_l2(simulated.displacement, reference[None, :, :5])
    assert simulated.displacement.shape == (1, 3001, 5)
    assert simulated.displacement.dtype == np.float64
    assert simulated.extras["story_shear"].dtype == np.dtype(precision)
    assert np.all(error <= 1e-3), f"relative L2 per story {error}"
    drift = np.diff(reference[:, :5], axis=1, prepend=0.0)
    np.testing.assert_allclose(simulated.extras["story_drift"][0], drift, atol=3e-5)


def test_float32_arithmetic_costs_no_accuracy(white_noise, rel_l2) -> None:
    motions = GroundMotions(white_noise(20, seed=5, duration=10.0), 0.01)
    single = BoucWenShearBuilding().simulate(motions).displacement
    double = BoucWenShearBuilding(precision="float64").simulate(motions).displacement
    assert np.all(rel_l2(single, double) <= 1e-5)


def test_rms_response_matches_design_level(white_noise) -> None:
    responses = BoucWenShearBuilding().simulate(GroundMotions(white_noise(50, seed=7), 0.01))
    rms = np.sqrt((responses.displacement**2).mean(axis=(0, 1)))
    np.testing.assert_allclose(rms, DESIGN_RMS, rtol=0.15)
