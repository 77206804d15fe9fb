"""The exact linear solver against closed-form, lsim and solve_ivp references."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_physics import linear_response as linear_response_module
from cphysfno_physics.linear_response import linear_response
from scipy.integrate import solve_ivp

from cphysfno_core import GroundMotions
from cphysfno_core.plugin import LinearSystem


def sdof(mass: float, omega: float, zeta: float) -> LinearSystem:
    """One DOF of ``mass`` kg, circular frequency ``omega`` rad/s and damping ratio ``zeta``."""
    return LinearSystem([[mass]], [[2 * zeta * omega * mass]], [[omega**2 * mass]], [1.0], [[1.0]])


def sdof_to_ramp(omega: float, zeta: float, c0: float, c1: float, t: np.ndarray) -> np.ndarray:
    """Closed-form ``u(t)`` of ``u'' + 2 zeta omega u' + omega^2 u = -(c0 + c1 t)`` from rest."""
    p1 = -c1 / omega**2
    p0 = (-c0 - 2 * zeta * omega * p1) / omega**2
    if zeta == 1.0:
        a, b = -p0, -p1 - omega * p0
        return p0 + p1 * t + (a + b * t) * np.exp(-omega * t)
    root = omega * np.sqrt(complex(zeta**2 - 1.0))
    s1, s2 = -zeta * omega + root, -zeta * omega - root
    b = (s1 * p0 - p1) / (s2 - s1)
    a = -p0 - b
    return (p0 + p1 * t + a * np.exp(s1 * t) + b * np.exp(s2 * t)).real


def three_story(non_classical: bool) -> LinearSystem:
    """A three-story shear building; ``non_classical`` puts a strong damper in story 1 only."""
    mass = np.diag([3.0e4, 2.5e4, 2.0e4])
    k = np.array([6.0e7, 4.0e7, 2.0e7])
    stiffness = np.diag(k + np.append(k[1:], 0.0)) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    damping = 0.2 * mass + 1e-3 * stiffness
    if non_classical:
        damping[0, 0] += 4.0e5
    output_map = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 1.0]])
    return LinearSystem(mass, damping, stiffness, np.ones(3), output_map)


def random_records(n: int, n_steps: int, seed: int) -> np.ndarray:
    """``[n, n_steps]`` rough ground accelerations in m/s^2 with nonzero first samples."""
    return np.random.default_rng(seed).normal(0.0, 1.5, size=(n, n_steps))


@pytest.mark.parametrize(
    ("omega", "zeta"),
    [(2 * np.pi / 0.5, 0.05), (2 * np.pi / 3.0, 0.02), (40.0, 1.5), (12.0, 1.0)],
    ids=["underdamped", "long-period", "overdamped", "critical"],
)
def test_sdof_matches_closed_form_for_step_plus_ramp(omega, zeta):
    dt, t = 0.01, np.arange(2001) * 0.01
    loads = [(0.0, 1.0), (2.0, 0.0), (-1.5, 0.4)]
    ag = np.stack([c0 + c1 * t for c0, c1 in loads])
    y = linear_response(sdof(7.0e3, omega, zeta), ag, dt)
    assert y.shape == (3, t.size, 1) and y.dtype == np.float64
    for record, (c0, c1) in enumerate(loads):
        exact = sdof_to_ramp(omega, zeta, c0, c1, t)
        assert np.max(np.abs(y[record, :, 0] - exact)) <= 1e-8 * np.max(np.abs(exact))


def test_one_dimensional_input_is_one_record():
    t = np.arange(501) * 0.02
    y = linear_response(sdof(1.0, 5.0, 0.1), 0.3 * t, 0.02)
    assert y.shape == (1, 501, 1)
    exact = sdof_to_ramp(5.0, 0.1, 0.0, 0.3, t)
    assert np.max(np.abs(y[0, :, 0] - exact)) <= 1e-8 * np.max(np.abs(exact))


@pytest.mark.parametrize("non_classical", [False, True], ids=["rayleigh", "non-classical"])
def test_mdof_matches_lsim_across_chunks(non_classical, lsim_response):
    system = three_story(non_classical)
    ag = random_records(120, 3001, seed=3)
    y = linear_response(system, ag, 0.01)
    picked = [0, 57, 119]
    reference = lsim_response(system, GroundMotions(ag[picked], 0.01))
    scale = np.max(np.abs(reference), axis=(0, 1))
    assert np.all(np.max(np.abs(y[picked] - reference), axis=(0, 1)) <= 1e-8 * scale)


def test_every_length_and_record_count_is_written_in_place():
    """Outputs leave the kernel in windows of samples and blocks of records: a record cut
    short, or solved among other records, gives the start of the same response."""
    window, lanes = linear_response_module.WINDOW, linear_response_module.LANES
    system = three_story(non_classical=False)
    ag = random_records(lanes + 3, 2 * window + 2, seed=8)
    whole = linear_response(system, ag, 0.01)
    assert np.abs(whole[:, -1]).min() > 0.0
    for length in (2, window - 1, window, window + 1, 2 * window + 2):
        for records in (slice(lanes + 2, lanes + 3), slice(0, lanes + 3)):
            part = linear_response(system, ag[records, :length], 0.01)
            np.testing.assert_array_equal(part, whole[records, :length])


def test_non_classical_mdof_matches_tight_solve_ivp():
    system = three_story(non_classical=True)
    dt, n_steps = 0.01, 301
    ag = random_records(2, n_steps, seed=5)
    y = linear_response(system, ag, dt)
    inverse_mass = np.linalg.inv(system.mass)

    def rate(t, x, t0, a0, a1):
        u, v = x[:3], x[3:]
        a = a0 + (a1 - a0) * (t - t0) / dt
        force = system.damping @ v + system.stiffness @ u
        return np.concatenate([v, -inverse_mass @ force - system.influence * a])

    for response, record in zip(y, ag, strict=True):
        state, reference = np.zeros(6), [system.output_map @ np.zeros(3)]
        for k in range(n_steps - 1):
            interval = solve_ivp(
                rate,
                (k * dt, (k + 1) * dt),
                state,
                method="DOP853",
                args=(k * dt, record[k], record[k + 1]),
                rtol=1e-12,
                atol=1e-15,
            )
            state = interval.y[:, -1]
            reference.append(system.output_map @ state[:3])
        reference = np.array(reference)
        error = np.max(np.abs(response - reference), axis=0)
        assert np.all(error <= 1e-7 * np.max(np.abs(reference), axis=0))


def test_defective_system_uses_the_direct_recurrence(lsim_response):
    """Two critically damped, coupled DOFs with a rigid-body mode: A is defective."""
    mass = np.diag([1.0, 2.0])
    stiffness = np.array([[1.0, -1.0], [-1.0, 1.0]]) * 50.0
    damping = 2.0 * np.sqrt(50.0) * np.array([[1.0, -1.0], [-1.0, 1.0]])
    influence = np.array([1.0, 0.0])
    system = LinearSystem(mass, damping, stiffness, influence, np.eye(2))
    ag = random_records(2, 401, seed=9)
    y = linear_response(system, ag, 0.01)
    reference = lsim_response(system, GroundMotions(ag, 0.01))
    assert np.max(np.abs(y - reference)) <= 1e-8 * np.max(np.abs(reference))
