"""A shear building with a linear coupling between its floors (a frame's flexure) against
its own equations integrated by ``solve_ivp``, the coupling's story shears against a hand
computation, and its checks."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
from cphysfno_core import ConfigError, GroundMotions, create
from cphysfno_core.signals import coupling_story_shear

MASSES = np.array([3.0e4, 2.0e4])
STIFFNESS = np.array([4.0e7, 2.5e7])
COUPLING = np.array([[1.0e7, -0.6e7], [-0.6e7, 0.5e7]])
YIELD, ALPHA, EXPONENT = 0.01, 0.1, 2.0
DAMPING_RATIO = 0.04


def coupled(**extra):
    params = {
        "masses": tuple(MASSES),
        "stiffnesses": tuple(STIFFNESS),
        "story_law": {
            "name": "bouc-wen",
            "alpha": ALPHA,
            "exponent": EXPONENT,
            "yield_displacement": YIELD,
        },
        "damping_ratio": DAMPING_RATIO,
        "coupling": tuple(map(tuple, COUPLING)),
    }
    return create("structure", "shear-building", **{**params, **extra})


def reference(ag: np.ndarray, dt: float) -> np.ndarray:
    """``[T, 2]`` floor displacements (m) of ``M u'' + C u' + A^T F + K_c u = -M 1 a_g``
    with Bouc-Wen springs ``F = k (alpha v + (1 - alpha) z)``, ``A = 1``,
    ``beta = gamma = 1 / (2 u_y^n)``, ``C`` classical on ``A^T diag(k) A + K_c``."""
    compat = np.array([[1.0, 0.0], [-1.0, 1.0]])
    stiffness = compat.T @ np.diag(STIFFNESS) @ compat + COUPLING
    squares, modes = scipy.linalg.eigh(stiffness, np.diag(MASSES))
    mass_modes = MASSES[:, None] * modes
    damping = mass_modes @ np.diag(2.0 * DAMPING_RATIO * np.sqrt(squares)) @ mass_modes.T
    shape = 0.5 / YIELD**EXPONENT
    t = np.arange(ag.size) * dt

    def rhs(time, y):
        u, w, z = y[:2], y[2:4], y[4:]
        v_dot = compat @ w
        springs = STIFFNESS * (ALPHA * (compat @ u) + (1.0 - ALPHA) * z)
        force = compat.T @ springs + COUPLING @ u + damping @ w
        acceleration = -force / MASSES - np.interp(time, t, ag)
        power = np.abs(z) ** (EXPONENT - 1.0)
        z_dot = v_dot * (1.0 - shape * power * np.abs(z)) - shape * np.abs(v_dot) * power * z
        return np.concatenate([w, acceleration, z_dot])

    solution = scipy.integrate.solve_ivp(
        rhs,
        (0.0, t[-1]),
        np.zeros(6),
        method="DOP853",
        t_eval=t,
        rtol=1e-10,
        atol=1e-13,
        max_step=dt / 2,
    )
    return solution.y[:2].T


def test_a_coupled_building_follows_its_equations():
    rng = np.random.default_rng(3)
    motions = GroundMotions(7.0 * rng.standard_normal((1, 801)), 0.01)
    building = coupled(substeps=20)  # steps short enough to leave the model's own error
    u = building.simulate(motions).displacement[0]
    truth = reference(motions.acceleration[0], motions.dt)
    assert np.abs(np.diff(truth, axis=1, prepend=0.0)).max() > 2.0 * YIELD  # past yield
    assert np.linalg.norm(u - truth) / np.linalg.norm(truth) < 1e-5
    # the floors' forces the restoring force gives carry the coupling too
    force = building.restoring_force().force(truth[100:101], np.zeros((1, 2)))
    springs = STIFFNESS * ALPHA * np.diff(truth[100], prepend=0.0)
    by_hand = np.array([springs[0] - springs[1], springs[1]]) + COUPLING @ truth[100]
    assert np.allclose(force[0], by_hand, rtol=1e-12)


def test_the_coupling_counts_in_the_periods():
    compat = np.array([[1.0, 0.0], [-1.0, 1.0]])
    stiffness = compat.T @ np.diag(STIFFNESS) @ compat + COUPLING
    squares = scipy.linalg.eigh(stiffness, np.diag(MASSES), eigvals_only=True)
    assert np.allclose(coupled().periods(), 2.0 * np.pi / np.sqrt(squares), rtol=1e-12)


def test_the_coupling_story_shears_by_hand():
    drift = np.array([[0.01, 0.02]])  # floors at 0.01 and 0.03 m
    # K_c u = [1e7 * 0.01 - 0.6e7 * 0.03, -0.6e7 * 0.01 + 0.5e7 * 0.03] = [-8e4, 9e4] N
    assert np.allclose(coupling_story_shear(COUPLING, drift), [[1.0e4, 9.0e4]], rtol=1e-12)


def test_a_coupled_pushover_adds_the_couplings_shears():
    building = coupled()
    curve = building.story_pushover(np.linspace(0.0, 0.01, 21))
    springs = building.story_shears(curve.story_drift)
    share = coupling_story_shear(COUPLING, curve.story_drift)
    assert np.allclose(curve.story_shear, springs + share, rtol=1e-12)
    assert np.abs(share).max() > 0.1 * np.abs(springs).max()


def elastic(**extra):
    """The coupled building with springs that never yield."""
    law = {"name": "bilinear", "alpha": 0.5, "yield_displacement": 10.0}
    return coupled(story_law=law, **extra)


def test_the_story_shears_of_a_record_carry_the_coupling():
    rng = np.random.default_rng(4)
    responses = elastic().simulate(GroundMotions(rng.standard_normal((2, 301)), 0.01))
    drift = responses.extras["story_drift"]
    by_hand = STIFFNESS * drift + coupling_story_shear(COUPLING, drift)
    assert np.allclose(responses.extras["story_shear"], by_hand, rtol=1e-12, atol=1e-6)


def test_a_coupled_building_on_a_coarse_grid_or_in_its_modes_keeps_the_coupling():
    rng = np.random.default_rng(5)
    motions = GroundMotions(7.0 * rng.standard_normal((1, 801)), 0.01)
    building = coupled()
    coarse = building.simulate(motions, dt=0.02).displacement
    resampled = building.simulate(motions.resample(0.02)).displacement
    assert np.allclose(coarse, resampled, rtol=0.0, atol=1e-12)
    _, modes = scipy.linalg.eigh(building.linear_system().stiffness, np.diag(MASSES))
    projected = building.simulate_projected(motions, modes).displacement
    full = building.simulate(motions).displacement
    assert np.linalg.norm(projected - full) / np.linalg.norm(full) < 1e-6


@pytest.mark.parametrize(
    ("coupling", "complaint"),
    [
        (((1.0, 2.0), (0.0, 1.0)), "symmetric"),
        (((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)), r"\[2, 2\]"),
        (((1.0, 0.0), (0.0,)), r"\[2, 2\]"),
    ],
)
def test_a_wrong_coupling_is_refused(coupling, complaint):
    with pytest.raises(ConfigError, match=complaint):
        create(
            "structure",
            "shear-building",
            masses=(1.0, 1.0),
            stiffnesses=(1.0, 1.0),
            coupling=coupling,
        )


def test_a_coupling_that_makes_the_building_unstable_is_refused():
    with pytest.raises(ConfigError, match="not positive definite"):
        create(
            "structure",
            "shear-building",
            masses=(1.0, 1.0),
            stiffnesses=(1.0, 1.0),
            coupling=((-3.0, 0.0), (0.0, 0.0)),
        ).periods()
