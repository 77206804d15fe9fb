"""The generic shear building against references written here from its equations:
``solve_ivp`` at tight tolerance for the smooth laws, a fine-step central-difference
integration with each law's incremental rule for the laws with corners."""

from __future__ import annotations

import numba
import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
from cphysfno_core import ConfigError, CphysfnoError, GroundMotions, RegistryError, create
from cphysfno_core.testing import check_structure

from cphysfno_bouc_wen import BoucWenShearBuilding
from cphysfno_bouc_wen.shear_building import ShearBuilding

from .conftest import paper_white_noise

MASSES = np.array([2.0e4, 2.0e4, 1.5e4])
STIFFNESS = np.array([4.0e7, 3.0e7, 2.0e7])
YIELD = np.array([0.008, 0.01, 0.012])
ALPHA = 0.05
COMPAT = np.eye(3) - np.eye(3, k=-1)
DT = 0.01


def building(law: dict, **extra) -> ShearBuilding:
    return create(
        "structure",
        "shear-building",
        masses=tuple(MASSES),
        stiffnesses=tuple(STIFFNESS),
        story_law=law,
        **extra,
    )


@pytest.fixture(scope="module")
def strong() -> GroundMotions:
    """Two 8-s records of the paper's white noise, twice as strong: they yield every law."""
    return GroundMotions(2.0 * paper_white_noise(2, seed=11, duration=8.0), DT)


def classical_damping(ratio: float = 0.05) -> np.ndarray:
    stiffness = COMPAT.T @ np.diag(STIFFNESS) @ COMPAT
    squares, modes = scipy.linalg.eigh(stiffness, np.diag(MASSES))
    mass_modes = np.diag(MASSES) @ modes
    return mass_modes @ np.diag(2.0 * ratio * np.sqrt(squares)) @ mass_modes.T


def rel_l2(value: np.ndarray, reference: np.ndarray) -> float:
    return float(
        np.max(np.linalg.norm(value - reference, axis=1) / np.linalg.norm(reference, axis=1))
    )


def solve_smooth(ag: np.ndarray, damping: np.ndarray, shear, rate, n_states: int) -> np.ndarray:
    """Floor displacements ``[T, 3]`` of one record by DOP853 at rtol 1e-11."""
    t = np.arange(ag.shape[0]) * DT

    def rhs(time, y):
        u, w, s = y[:3], y[3:6], y[6:]
        v, v_dot = COMPAT @ u, COMPAT @ w
        ground = np.interp(time, t, ag)
        acceleration = -(COMPAT.T @ shear(v, s) + damping @ w) / MASSES - ground
        return np.concatenate([w, acceleration, rate(v, v_dot, s)])

    y0 = np.zeros(6 + 3 * n_states)
    solution = scipy.integrate.solve_ivp(
        rhs, (0.0, t[-1]), y0, method="DOP853", t_eval=t, rtol=1e-11, atol=1e-13, max_step=DT
    )
    return solution.y[:3].T


BOUC_WEN_N = np.array([2.0, 3.0, 4.0])


def bouc_wen_shear(v, h):
    return STIFFNESS * (0.1 * v + 0.9 * h)


def bouc_wen_rate(v, v_dot, h):
    shape = 0.5 / YIELD**BOUC_WEN_N
    power = np.abs(h) ** (BOUC_WEN_N - 1.0)
    return v_dot * (1.0 - shape * power * np.abs(h)) - shape * np.abs(v_dot) * power * h


def test_bouc_wen_law_differing_by_story_matches_solve_ivp(strong) -> None:
    structure = building(
        {"name": "bouc-wen", "yield_displacement": tuple(YIELD), "exponent": tuple(BOUC_WEN_N)}
    )
    response = structure.simulate(strong)
    reference = np.stack(
        [
            solve_smooth(ag, classical_damping(), bouc_wen_shear, bouc_wen_rate, 1)
            for ag in strong.acceleration
        ]
    )
    assert np.max(np.abs(response.extras["story_drift"]) / YIELD) > 1.5
    assert rel_l2(response.displacement, reference) < 2e-3


def test_linear_law_with_rayleigh_damping_matches_solve_ivp(strong) -> None:
    structure = building({"name": "linear"}, rayleigh_modes=(1, 3), damping_ratio=0.03)
    stiffness = COMPAT.T @ np.diag(STIFFNESS) @ COMPAT
    omega = np.sqrt(scipy.linalg.eigh(stiffness, np.diag(MASSES), eigvals_only=True))
    a1 = 2.0 * 0.03 / (omega[0] + omega[2])
    damping = a1 * omega[0] * omega[2] * np.diag(MASSES) + a1 * stiffness
    reference = np.stack(
        [
            solve_smooth(ag, damping, lambda v, s: STIFFNESS * v, lambda v, vd, s: s, 0)
            for ag in strong.acceleration
        ]
    )
    assert rel_l2(structure.simulate(strong).displacement, reference) < 2e-3
    np.testing.assert_allclose(structure.linear_system().damping, damping, rtol=1e-10)


@numba.njit
def _central_difference(ag, damping, law, substeps):
    """Chopra's central difference with the law's incremental rule, ``substeps`` steps per
    sample; law 0 is bilinear (kinematic), law 1 peak-oriented (Clough)."""
    n_steps = ag.shape[0]
    h = DT / substeps
    mass = np.diag(MASSES)
    left = mass / h**2 + damping / (2.0 * h)
    inverse = np.linalg.inv(left)
    u_prev = np.zeros(3)
    u = np.zeros(3)
    drift = np.zeros(3)
    force = np.zeros(3)
    z = np.zeros(3)
    peak_pos = YIELD.copy()
    peak_neg = -YIELD.copy()
    zero_pos = np.zeros(3)
    zero_neg = np.zeros(3)
    out = np.zeros((n_steps, 3))
    for k in range(n_steps - 1):
        for sub in range(substeps):
            ground = ag[k] + (ag[k + 1] - ag[k]) * sub / substeps
            rhs = -(COMPAT.T @ force) - MASSES * ground + (2.0 * mass / h**2) @ u
            rhs -= (mass / h**2 - damping / (2.0 * h)) @ u_prev
            u_next = inverse @ rhs
            new_drift = COMPAT @ u_next
            for s in range(3):
                k0, uy, step = STIFFNESS[s], YIELD[s], new_drift[s] - drift[s]
                if law == 0:
                    z[s] = min(max(z[s] + step, -uy), uy)
                    force[s] = k0 * (ALPHA * new_drift[s] + (1.0 - ALPHA) * z[s])
                    continue
                elastic = force[s] + k0 * step
                if step > 0.0:
                    if elastic <= 0.0:
                        force[s] = elastic
                        continue
                    if force[s] < 0.0:
                        zero_pos[s] = drift[s] - force[s] / k0
                    top = k0 * uy + ALPHA * k0 * (peak_pos[s] - uy)
                    if new_drift[s] >= peak_pos[s]:
                        target = k0 * uy + ALPHA * k0 * (new_drift[s] - uy)
                        peak_pos[s] = new_drift[s]
                    else:
                        slope = top / (peak_pos[s] - zero_pos[s])
                        target = slope * (new_drift[s] - zero_pos[s])
                    force[s] = min(elastic, target)
                elif step < 0.0:
                    if elastic >= 0.0:
                        force[s] = elastic
                        continue
                    if force[s] > 0.0:
                        zero_neg[s] = drift[s] - force[s] / k0
                    bottom = -k0 * uy + ALPHA * k0 * (peak_neg[s] + uy)
                    if new_drift[s] <= peak_neg[s]:
                        target = -k0 * uy + ALPHA * k0 * (new_drift[s] + uy)
                        peak_neg[s] = new_drift[s]
                    else:
                        slope = bottom / (peak_neg[s] - zero_neg[s])
                        target = slope * (new_drift[s] - zero_neg[s])
                    force[s] = max(elastic, target)
            drift = new_drift
            u_prev, u = u, u_next
        out[k + 1] = u
    return out


@pytest.mark.parametrize(("name", "code"), [("bilinear", 0), ("peak-oriented", 1)])
def test_laws_with_corners_match_a_fine_step_reference(strong, name, code) -> None:
    structure = building({"name": name, "alpha": ALPHA, "yield_displacement": tuple(YIELD)})
    response = structure.simulate(strong)
    reference = np.stack(
        [_central_difference(ag, classical_damping(), code, 200) for ag in strong.acceleration]
    )
    assert np.max(np.abs(response.extras["story_drift"]) / YIELD) > 1.5
    assert rel_l2(response.displacement, reference) < 1e-2


def test_example_1_through_the_generic_kernel_is_the_dedicated_building() -> None:
    motions = GroundMotions(paper_white_noise(4, seed=5, duration=10.0), DT)
    dedicated = BoucWenShearBuilding(precision="float64")
    generic = create(
        "structure",
        "shear-building",
        masses=dedicated.params.masses,
        stiffnesses=dedicated.params.stiffnesses,
        story_law={"name": "bouc-wen", "alpha": (0.1,) * 5},
    )
    assert generic._bouc_wen_model is None  # per-story values: the generic kernel
    assert (
        rel_l2(generic.simulate(motions).displacement, dedicated.simulate(motions).displacement)
        < 1e-9
    )


@pytest.mark.parametrize(
    "law",
    [
        {"name": "linear"},
        {"name": "bilinear", "yield_displacement": 0.01},
        {"name": "bouc-wen", "alpha": (0.1, 0.05, 0.1)},
        {"name": "peak-oriented", "yield_displacement": 0.01},
    ],
    ids=lambda law: law["name"],
)
def test_every_law_passes_the_structure_checks(law) -> None:
    check_structure(building(law))


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"masses": (1e4, 1e4), "stiffnesses": (1e7, 1e7, 1e7)}, "differs between fields"),
        ({"masses": 1e4, "stiffnesses": 1e7}, "give n_stories"),
        (
            {"masses": 1e4, "stiffnesses": 1e7, "n_stories": 3, "story_heights": (3.0, 3.0)},
            "differs",
        ),
        (
            {"masses": 1e4, "stiffnesses": 1e7, "n_stories": 3, "story_law": {"alpha": 0.1}},
            "needs a name",
        ),
        (
            {
                "masses": 1e4,
                "stiffnesses": 1e7,
                "n_stories": 3,
                "story_law": {"name": "bilinear", "yield_displacement": (0.01, 0.02)},
            },
            r"story_law\.yield_displacement: needs one value or one per story: got 2 values",
        ),
        (
            {"masses": 1e4, "stiffnesses": 1e7, "n_stories": 3, "story_law": {"name": "bilinear"}},
            r"story_law\.yield_displacement: Field required",
        ),
        (
            {"masses": 1e4, "stiffnesses": 1e7, "n_stories": 2, "rayleigh_modes": (1, 3)},
            "asks for mode 3 of a 2-story building",
        ),
    ],
)
def test_a_wrong_building_fails_with_the_field_named(params, message) -> None:
    with pytest.raises(ConfigError, match=message):
        ShearBuilding(**params).periods()


def test_an_unknown_law_lists_the_known_ones() -> None:
    with pytest.raises(RegistryError, match="known story_law names: .*bilinear"):
        ShearBuilding(masses=1e4, stiffnesses=1e7, n_stories=2, story_law={"name": "takeda"})


def test_peak_drift_ratios_are_the_integrators_drifts_over_the_story_heights(strong) -> None:
    from cphysfno_core import edp

    heights = (4.0, 3.2, 3.0)
    structure = building({"name": "bilinear", "yield_displacement": 0.01}, story_heights=heights)
    response = structure.simulate(strong)
    demands = edp.compute(response, structure, strong)
    expected = np.abs(response.extras["story_drift"]).max(axis=1) / np.array(heights)
    np.testing.assert_allclose(demands.pid, expected, rtol=1e-12)
    assert structure.stories().lower == (None, 0, 1)


def test_a_sharp_bouc_wen_corner_that_outruns_the_automatic_step_is_integrated_again():
    """Exponent 20: h' changes by n |v'| / u_y per metre of h, far faster than the periods
    say, and RK4 at the periods' step (2 a sample) diverges on a 10 m/s^2 pulse; the
    records that diverge are integrated again with 4 and then 16 times more steps."""
    from cphysfno_bouc_wen import shear_building

    t = np.arange(0.0, 10.0, 0.01)
    pulse = 10.0 * np.sin(2.0 * np.pi * 3.0 * t) * np.exp(-(((t - 3.0) / 2.0) ** 2))
    motions = GroundMotions(np.stack([pulse, 0.01 * pulse]), 0.01)
    law = {"name": "bouc-wen", "alpha": 0.05, "exponent": 20.0, "yield_displacement": 0.005}
    spec = {"masses": (2e4, 2e4), "stiffnesses": (3e7, 3e7), "story_law": law}
    automatic = create("structure", "shear-building", **spec)
    assert shear_building.AUTOMATIC_RETRIES == (4, 4)
    found = automatic.simulate(motions).displacement
    fine = create("structure", "shear-building", **spec, substeps=128).simulate(motions)
    np.testing.assert_allclose(found, fine.displacement, rtol=0, atol=1e-4 * np.abs(found).max())
    with pytest.raises(CphysfnoError, match="raise substeps"):
        create("structure", "shear-building", **spec, substeps=2).simulate(motions)
