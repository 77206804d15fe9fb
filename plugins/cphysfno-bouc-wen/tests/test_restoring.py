"""The restoring force handed to modal reduction agrees with the simulator."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_core import GroundMotions
from cphysfno_core.plugin import RestoringForce

from cphysfno_bouc_wen import BoucWenShearBuilding


def test_protocol_and_elastic_consistency(matrices) -> None:
    force = BoucWenShearBuilding().restoring_force()
    assert isinstance(force.n_states, int) and force.n_states == 5
    state = force.initial_state(3)
    np.testing.assert_array_equal(state, np.zeros((3, 5)))
    u = np.random.default_rng(0).normal(0.0, 0.01, (3, 5))
    drift = np.diff(u, axis=1, prepend=0.0)
    _, stiffness, _ = matrices
    np.testing.assert_allclose(force.force(u, drift), u @ stiffness, rtol=1e-12)
    np.testing.assert_allclose(force.force(u, np.zeros((3, 5))), 0.1 * u @ stiffness, rtol=1e-12)
    velocity = np.random.default_rng(1).normal(0.0, 0.1, (3, 5))
    rate = force.state_rate(u, velocity, np.zeros((3, 5)))
    np.testing.assert_allclose(rate, np.diff(velocity, axis=1, prepend=0.0), rtol=1e-12)


@pytest.mark.parametrize("exponent", [3.0, 2.5], ids=["whole-exponent", "pow"])
def test_restoring_force_reproduces_simulate(
    white_noise, piecewise_solver, rel_l2, exponent
) -> None:
    building = BoucWenShearBuilding(exponent=exponent)
    force: RestoringForce = building.restoring_force()
    system = building.linear_system()
    inverse_mass = np.linalg.inv(system.mass)
    ag = white_noise(1, seed=17, duration=6.0)[0]

    def rhs(t, y, a_start, a_slope, t_start):
        u, w, h = y[:5], y[5:10], y[10:]
        internal = system.damping @ w + force.force(u[None], h[None])[0]
        acceleration = -inverse_mass @ internal - system.influence * (
            a_start + a_slope * (t - t_start)
        )
        h_rate = force.state_rate(u[None], w[None], h[None])[0]
        return np.concatenate([w, acceleration, h_rate])

    y0 = np.concatenate([np.zeros(10), force.initial_state(1)[0]])
    reference = piecewise_solver(rhs, y0, ag, 0.01, rtol=1e-9, atol=1e-12)
    simulated = building.simulate(GroundMotions(ag, 0.01))
    error = rel_l2(simulated.displacement[0], reference[:, :5])
    assert np.abs(np.diff(reference[:, :5], axis=1, prepend=0.0)).max() > 0.01
    assert np.all(error <= 1e-3), f"relative L2 per story {error}"
