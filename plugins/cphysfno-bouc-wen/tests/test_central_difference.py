"""The central-difference integrator against closed-form linear response and tight
solve_ivp solutions, its order, and the building features it must carry (coupling,
projection, collapse)."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_core import GroundMotions, create

from .conftest import ALPHA, AMPLITUDE, EXPONENT, MASS, STIFFNESS, YIELD, elastic_response

CENTRAL = {"integrator": "central-difference"}


def paper_building(**params):
    """The paper's five-story Bouc-Wen building (tests' conftest) on the generic kernels."""
    return create(
        "structure",
        "shear-building",
        masses=MASS,
        stiffnesses=tuple(STIFFNESS),
        story_law={
            "name": "bouc-wen",
            "alpha": ALPHA,
            "exponent": EXPONENT,
            "A": AMPLITUDE,
            "yield_displacement": YIELD,
        },
        **params,
    )


def test_small_amplitudes_converge_to_the_exact_elastic_response_at_second_order(
    white_noise, matrices, rel_l2
) -> None:
    """Far below yield the building is linear: the error against the closed-form response
    falls fourfold when the step halves, and is 2.4 % at the automatic step (omega_max h
    <= 1 rad: one step a sample here, omega_max h = 0.86) under a white noise that drives
    the highest mode as hard as the first."""
    dt = 0.01
    motions = GroundMotions(1e-4 * white_noise(2, seed=5, dt=dt, duration=10.0), dt)
    exact = elastic_response(motions.acceleration, dt, matrices)
    errors = [
        rel_l2(paper_building(**CENTRAL, substeps=n).simulate(motions).displacement, exact).max()
        for n in (1, 2, 4)
    ]
    automatic = paper_building(**CENTRAL).simulate(motions).displacement
    assert rel_l2(automatic, exact).max() == errors[0]
    assert errors[0] < 0.03, errors
    np.testing.assert_allclose(np.array(errors[:-1]) / errors[1:], 4.0, rtol=0.1)


def test_the_yielding_building_follows_a_tight_solve_ivp(
    white_noise, matrices, reference_rhs, piecewise_solver, rel_l2
) -> None:
    """The paper's building yielding under its white noise (past 1.5 yield drifts):
    3 % from the tight reference at the automatic step (one a sample), 0.2 % at four steps
    a sample (second order: the smooth law takes the midpoint rule)."""
    candidates = GroundMotions(white_noise(6, seed=101), 0.01)
    drift = paper_building().simulate(candidates).extras["story_drift"]
    record = int(np.argmax(np.abs(drift).max(axis=(1, 2))))
    assert np.abs(drift[record]).max() > 1.5 * YIELD
    _, _, damping = matrices
    reference = piecewise_solver(
        reference_rhs,
        np.zeros(15),
        candidates.acceleration[record],
        0.01,
        rtol=1e-10,
        atol=1e-13,
        args=(damping,),
    )[None, :, :5]
    motion = candidates[record]
    automatic = paper_building(**CENTRAL).simulate(motion).displacement
    finer = paper_building(**CENTRAL, substeps=4).simulate(motion).displacement
    assert rel_l2(automatic, reference).max() < 0.04
    assert rel_l2(finer, reference).max() < 0.003


@pytest.mark.parametrize(
    "law",
    [
        {"name": "bilinear", "alpha": 0.05, "yield_displacement": 0.01},
        {"name": "pinching", "alpha": 0.05, "yield_displacement": 0.01, "beta_unload": 0.3},
        {
            "name": "cracked-pinching",
            "yield_displacement": 0.01,
            "crack_displacement": 0.002,
            "crack_share": 0.5,
            "crack_hysteresis": 0.5,
        },
    ],
)
def test_piecewise_linear_laws_converge_to_the_runge_kutta_response(white_noise, law) -> None:
    """Laws with corners (the reference is the Runge-Kutta kernel at 16 steps a sample,
    itself checked against solve_ivp): the error is below 3 % at the automatic step and
    falls as the step shrinks."""
    motions = GroundMotions(1.5 * white_noise(3, seed=11, duration=15.0), 0.01)
    building = {"masses": MASS, "stiffnesses": tuple(STIFFNESS), "story_law": law}
    reference = create("structure", "shear-building", **building, substeps=16)
    truth = reference.simulate(motions).extras["story_drift"]
    assert np.abs(truth).max() > 2.0 * 0.01

    def error(**params) -> float:
        central = create("structure", "shear-building", **building, **CENTRAL, **params)
        drift = central.simulate(motions).extras["story_drift"]
        return float(np.sqrt(np.sum((drift - truth) ** 2) / np.sum(truth**2)))

    errors = [error(substeps=n) for n in (1, 2, 4)]
    assert errors[0] == error()
    assert errors[0] < 0.15
    assert errors[1] < errors[0] / 3.0 and errors[2] < errors[1] / 3.0


def test_a_coupled_and_projected_building_follows_the_runge_kutta_one(white_noise) -> None:
    """A linear coupling between the floors and a projection onto two shapes go through
    the same chain as the Runge-Kutta kernel's (both at four steps a sample)."""
    chain = 2.0 * np.eye(5) - np.eye(5, k=1) - np.eye(5, k=-1)
    chain[0, 0] = chain[-1, -1] = 1.0  # a free chain of springs between the floors
    coupling = 0.2 * STIFFNESS[1] * chain
    params = {"coupling": tuple(map(tuple, coupling)), "rayleigh_modes": (1, 3)}
    motions = GroundMotions(white_noise(2, seed=3, duration=10.0), 0.01)
    basis = np.column_stack([np.arange(1.0, 6.0), np.arange(1.0, 6.0) ** 2])
    for run in (
        lambda b: b.simulate_projected(motions, np.eye(5), substeps=4).extras["story_shear"],
        lambda b: b.simulate_projected(motions, basis, substeps=4).displacement,
    ):
        reference = run(paper_building(**params))
        central = run(paper_building(**params, **CENTRAL))
        error = np.sqrt(np.sum((central - reference) ** 2) / np.sum(reference**2))
        assert error < 0.003


def test_a_story_past_its_zero_strength_collapses_on_central_difference() -> None:
    """The softening story runs away as with Runge-Kutta: the record is a collapse, NaN
    from there; a weak record beside it is not."""
    building = create(
        "structure",
        "shear-building",
        masses=(MASS,),
        stiffnesses=(STIFFNESS[0],),
        story_law={"name": "bilinear", "alpha": -0.5, "yield_displacement": YIELD},
        **CENTRAL,
    )
    dt = 0.01
    t = np.arange(0.0, 20.0, dt)
    resonant = 20.0 * np.sin(2.0 * np.pi * t / float(building.periods()[0]))
    responses = building.simulate(GroundMotions(np.stack([resonant, 0.01 * resonant]), dt))
    assert responses.collapsed.tolist() == [True, False]
    assert np.isnan(responses.displacement[0, -1, 0])
    assert np.isfinite(responses.displacement[1]).all()


def test_an_unknown_integrator_is_refused() -> None:
    with pytest.raises(Exception, match="integrator"):
        paper_building(integrator="newmark")
