"""The fine-grid simulator against a tight solve_ivp solution, and the response level."""

from __future__ import annotations

import numpy as np
from cphysfno_core import GroundMotions

from cphysfno_bouc_wen import BoucWenShearBuilding

DESIGN_RMS = np.array([0.0039, 0.0075, 0.0109, 0.0146, 0.0195])


def test_fine_grid_matches_tight_solve_ivp(
    white_noise, matrices, reference_rhs, piecewise_solver, rel_l2
) -> None:
    building = BoucWenShearBuilding()
    candidates = GroundMotions(white_noise(6, seed=101), 0.01)
    drift = building.simulate(candidates).extras["story_drift"]
    hardest = int(np.argmax(np.abs(drift).max(axis=(1, 2))))
    assert np.abs(drift[hardest]).max() > 1.5 * 0.01
    motion = candidates[hardest]
    _, _, damping = matrices
    reference = piecewise_solver(
        reference_rhs,
        np.zeros(15),
        motion.acceleration[0],
        0.01,
        rtol=1e-10,
        atol=1e-13,
        args=(damping,),
    )
    simulated = building.simulate(motion).displacement
    error = rel_l2(simulated, reference[None, :, :5])
    assert simulated.shape == (1, 3001, 5)
    assert np.all(error <= 1e-3), f"relative L2 per story {error}"


def test_rms_response_matches_design_level(white_noise) -> None:
    responses = BoucWenShearBuilding().simulate(GroundMotions(white_noise(50, seed=7), 0.01))
    rms = np.sqrt((responses.displacement**2).mean(axis=(0, 1)))
    np.testing.assert_allclose(rms, DESIGN_RMS, rtol=0.15)
