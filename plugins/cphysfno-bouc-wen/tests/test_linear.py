"""Elastic properties: periods, the linear system, and the small-amplitude limit."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from cphysfno_core import GroundMotions

from cphysfno_bouc_wen import BoucWenShearBuilding

from .conftest import elastic_response

DESIGN_PERIODS = [0.487, 0.199, 0.126, 0.092, 0.073]


def test_periods_match_design() -> None:
    periods = BoucWenShearBuilding().periods()
    np.testing.assert_allclose(periods, DESIGN_PERIODS, atol=5e-4)
    np.testing.assert_allclose(BoucWenShearBuilding().periods(2), periods[:2])


def test_linear_system_matches_independent_matrices(matrices) -> None:
    mass, stiffness, damping = matrices
    system = BoucWenShearBuilding().linear_system()
    np.testing.assert_allclose(system.mass, mass)
    np.testing.assert_allclose(system.stiffness, stiffness)
    np.testing.assert_allclose(system.damping, damping, rtol=1e-10, atol=1e-6 * damping.max())
    np.testing.assert_array_equal(system.influence, np.ones(5))
    np.testing.assert_array_equal(system.output_map, np.eye(5))
    squares, modes = scipy.linalg.eigh(stiffness, mass)
    modal_damping = modes.T @ system.damping @ modes
    np.testing.assert_allclose(
        modal_damping, np.diag(2 * 0.05 * np.sqrt(squares)), atol=1e-9 * modal_damping.max()
    )


@pytest.mark.parametrize("dt", [0.01, 0.02])
def test_small_amplitude_response_is_the_elastic_one(white_noise, matrices, rel_l2, dt) -> None:
    ag = 1e-4 * white_noise(2, seed=5, dt=dt, duration=10.0)
    elastic = elastic_response(ag, dt, matrices)
    building = BoucWenShearBuilding()
    motions = GroundMotions(ag, dt)
    fine = rel_l2(building.simulate(motions).displacement, elastic)
    implicit = rel_l2(building.simulate(motions, dt=dt).displacement, elastic)
    assert np.all(fine < 5e-4), f"relative L2 per story {fine}"
    assert np.all(implicit < 5e-4), f"relative L2 per story {implicit}"
