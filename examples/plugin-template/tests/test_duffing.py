"""The Duffing chain against scipy's solve_ivp, and its linear model and restoring force."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_core import ConfigError, GroundMotions, InputError
from scipy.integrate import solve_ivp

from cphysfno_plugin_template import DuffingChain, KanaiTajimi


def reference(chain: DuffingChain, motions: GroundMotions) -> np.ndarray:
    """``[n, T, d]`` floor displacements by solve_ivp (DOP853, rtol 1e-11), with the story
    forces written out floor by floor.

    Each sample interval, where the ground acceleration is a straight line, is one
    solve_ivp call, so that the integrator never steps across a kink of the forcing.
    """
    p = chain.params
    mass = np.asarray(p.masses)
    k = np.asarray(p.stiffnesses)
    damping = chain.linear_system().damping
    n, d = motions.n_records, len(mass)

    def rhs(t, y, start, slope):
        u, v = y.reshape(n, 2, d)[:, 0], y.reshape(n, 2, d)[:, 1]
        drift = np.diff(u, axis=1, prepend=0.0)
        shear = k * (drift + p.cubic * drift**3)
        force = shear - np.concatenate([shear[:, 1:], np.zeros((n, 1))], axis=1)
        a_g = start + slope * t
        acceleration = (-force - v @ damping.T) / mass - a_g[:, None]
        return np.stack([v, acceleration], axis=1).ravel()

    ag, dt = motions.acceleration, motions.dt
    y = np.zeros(n * 2 * d)
    out = np.zeros((n, motions.n_steps, d))
    for step in range(motions.n_steps - 1):
        args = (ag[:, step], (ag[:, step + 1] - ag[:, step]) / dt)
        solution = solve_ivp(rhs, (0.0, dt), y, "DOP853", args=args, rtol=1e-11, atol=1e-15)
        assert solution.success, solution.message
        y = solution.y[:, -1]
        out[:, step + 1] = y.reshape(n, 2, d)[:, 0]
    return out


def relative_l2(estimate: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per floor, over records and time."""
    return np.linalg.norm(estimate - truth, axis=(0, 1)) / np.linalg.norm(truth, axis=(0, 1))


@pytest.fixture(scope="module")
def motions() -> GroundMotions:
    """Two Kanai-Tajimi records of 3 s, four times the default intensity."""
    return KanaiTajimi(spectral_intensity=0.06, duration=3.0).sample(2, np.random.default_rng(3))


@pytest.fixture(scope="module")
def exact(motions) -> np.ndarray:
    return reference(DuffingChain(), motions)


def test_matches_solve_ivp(motions, exact) -> None:
    simulated = DuffingChain().simulate(motions).displacement
    assert simulated.shape == (2, 301, 3)
    assert relative_l2(simulated, exact).max() < 3e-4
    linear = DuffingChain(cubic=0.0).simulate(motions).displacement
    assert relative_l2(linear, exact).min() > 0.05


def test_error_falls_with_the_fourth_power_of_the_step(motions, exact) -> None:
    errors = [
        relative_l2(DuffingChain(substeps=s).simulate(motions).displacement, exact)
        for s in (4, 8, 16)
    ]
    assert np.all((errors[0] / errors[1] > 12) & (errors[0] / errors[1] < 22))
    assert errors[2].max() < 1e-6


def test_linear_system_is_the_small_amplitude_model() -> None:
    chain = DuffingChain()
    system = chain.linear_system()
    springs = chain.restoring_force()
    step = 1e-7
    jacobian = np.stack([springs.force(step * e[None], None)[0] / step for e in np.eye(3)], axis=1)
    np.testing.assert_allclose(jacobian, system.stiffness, rtol=1e-6, atol=1e-6 * 4e7)
    np.testing.assert_allclose(
        system.stiffness, [[7e7, -3e7, 0], [-3e7, 5e7, -2e7], [0, -2e7, 2e7]], rtol=1e-12
    )
    eigenvalues, modes = np.linalg.eig(np.linalg.solve(system.mass, system.stiffness))
    omega = np.sqrt(eigenvalues.real)
    modal = modes.T @ system.damping @ modes / np.diag(modes.T @ system.mass @ modes)[:, None]
    np.testing.assert_allclose(np.diag(modal), 2 * 0.05 * omega, rtol=1e-9)
    np.testing.assert_allclose(np.sort(2 * np.pi / omega)[::-1], chain.periods(), rtol=1e-12)


def test_restoring_force_of_a_cubic_story() -> None:
    springs = DuffingChain(masses=(1.0, 1.0), stiffnesses=(2.0, 3.0), cubic=5.0).restoring_force()
    u = np.array([[0.1, 0.3]])
    first, second = 2.0 * (0.1 + 5.0 * 0.1**3), 3.0 * (0.2 + 5.0 * 0.2**3)
    np.testing.assert_allclose(
        springs.force(u, springs.initial_state(1)), [[first - second, second]]
    )
    assert springs.state_rate(u, u, springs.initial_state(1)).shape == (1, 0)


def test_coarse_step_is_refused(motions) -> None:
    with pytest.raises(InputError, match="dt=None"):
        DuffingChain().simulate(motions, dt=0.05)


def test_one_stiffness_per_floor() -> None:
    with pytest.raises(ConfigError, match=r"duffing-chain\.stiffnesses: .*2 stiffnesses for 3"):
        DuffingChain(stiffnesses=(1e7, 1e7))
