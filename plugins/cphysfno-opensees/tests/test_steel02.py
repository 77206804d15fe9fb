"""The numba Steel02 against OpenSees' Steel02: stress and tangent at every step of many
strain histories, trials before a commit, and the validation of its parameters."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from cphysfno_opensees.fibre.steel02 import (
    EPS,
    FY,
    KON,
    N_STATE,
    SIG,
    TANGENT,
    Steel02Parameters,
    initial_state,
    trial,
)
from cphysfno_opensees.loader import import_opensees

YIELD_STRESS = 475e6
MODULUS = 200e9
# The bridge's bars: 475 MPa at yield, 655 MPa at 9 % strain.
BAR_HARDENING = (655e6 - 475e6) / (MODULUS * (0.09 - YIELD_STRESS / MODULUS))
MATERIALS = {
    "bridge bar": (YIELD_STRESS, MODULUS, BAR_HARDENING, 20.0, 0.925, 0.15),
    # Different in compression (a1, a2) and tension (a3, a4), so that a swap shows.
    "isotropic hardening": (YIELD_STRESS, MODULUS, BAR_HARDENING, 18.0, 0.9, 0.1)
    + (0.05, 1.5, 0.02, 0.8),
}
EPSY = YIELD_STRESS / MODULUS
RTOL = 1e-10
ATOL = 1e-3  # Pa


def _path(points, step):
    """Strains along straight lines through `points`, at most `step` apart, the points
    included (the first point not: the material starts at zero strain)."""
    strains = []
    for start, end in zip(points[:-1], points[1:], strict=True):
        n = max(1, int(np.ceil(abs(end - start) / step)))
        strains.extend(np.linspace(start, end, n + 1)[1:])
    return np.asarray(strains)


def _random_walk(seed, n=3000, limit=0.03):
    """Strains of a walk that keeps its direction for a while, with increments from zero to
    several yield strains, reflected at +-limit."""
    rng = np.random.default_rng(seed)
    scales = np.array([0.0, 1e-9, 1e-6, 3e-5, 3e-4, 2e-3, 8e-3])
    weights = np.array([0.05, 0.05, 0.15, 0.25, 0.25, 0.15, 0.10])
    direction = 1.0
    eps = 0.0
    strains = np.empty(n)
    for i in range(n):
        if rng.random() < 0.15:
            direction = -direction
        eps += direction * rng.choice(scales, p=weights) * abs(rng.standard_normal())
        if abs(eps) > limit:
            eps = np.sign(eps) * 2.0 * limit - eps
            direction = -direction
        strains[i] = eps
    return strains


def _growing_cycles(amplitudes, compression_share):
    points = [0.0]
    for amplitude in amplitudes:
        points += [amplitude, -compression_share * amplitude]
    return _path(points + [0.0], 2e-4)


HISTORIES = {
    "monotonic tension": _path([0.0, 0.06], 1e-4),
    "monotonic compression": _path([0.0, -0.06], 1e-4),
    "symmetric growing cycles": _growing_cycles(EPSY * np.array([0.5, 1, 2, 4, 8, 12]), 1.0),
    "asymmetric growing cycles": _growing_cycles(np.array([0.002, 0.006, 0.015, 0.03]), 0.35),
    "compression first": _growing_cycles(-np.array([0.002, 0.006, 0.015, 0.03]), 0.5),
    # Partial unloading and reloading inside Menegotto-Pinto branches, in both directions.
    "small reversals": _path(
        [0.0, 0.02, 0.019, 0.025, 0.0235, 0.024, 0.0238, 0.03, 0.01, 0.012, 0.0115, -0.02]
        + [-0.019, -0.0195, -0.0185, -0.025, -0.024, 0.0],
        2e-4,
    ),
    "zero increments": np.repeat(_path([0.0, 0.01, -0.008, 0.004, 0.0], 1e-3), 3),
    "null first steps": np.array([0.0, 0.0, 1e-16, -1e-16, 2e-15, 0.0, 0.001, 0.003, 0.0]),
    "null first step then compression": np.array([0.0, -1e-15, -3e-15, -0.002, -0.004, 0.0]),
    "tiny increments around zero": np.concatenate(
        [
            np.array([1e-17, -1e-17, 1e-16, 3e-15, 1e-15, -2e-15, 4e-15, -1e-14]),
            _path([0.0, 0.01, 0.0], 5e-4),
            np.array([1e-16, -1e-16, 0.0, 2e-15, -2e-15, 1e-13, -1e-13, 0.0]),
            _path([0.0, -0.01, 0.0], 5e-4),
            np.array([-1e-16, 1e-16, 0.0, -2e-15, 2e-15, -1e-13, 1e-13, 0.0]),
        ]
    ),
} | {f"random walk {seed}": _random_walk(seed) for seed in range(5)}


@pytest.fixture(scope="module")
def ops():
    return import_opensees()


def _opensees(ops, arguments, strains):
    """OpenSees' stress and tangent after each strain of `strains`, each step committed."""
    ops.wipe()
    ops.uniaxialMaterial("Steel02", 1, *arguments)
    ops.testUniaxialMaterial(1)
    response = np.empty((len(strains), 2))
    for i, strain in enumerate(strains):
        ops.setStrain(float(strain))  # setTrialStrain, then commitState
        response[i] = ops.getStress(), ops.getTangent()
    ops.wipe()
    return response


@numba.njit(cache=True)
def _follow(p, state, strains):
    """Stress and tangent after each strain, each step committed, and the states."""
    response = np.empty((strains.size, 2))
    states = np.empty((strains.size, state.size))
    committed = state.copy()
    out = np.empty_like(state)
    for i in range(strains.size):
        response[i] = trial(p, committed, out, strains[i])
        committed[:] = out
        states[i] = committed
    return response, states


def _assert_matches(ours, theirs, atol=ATOL):
    np.testing.assert_allclose(ours[:, 0], theirs[:, 0], rtol=RTOL, atol=atol, err_msg="stress")
    np.testing.assert_allclose(ours[:, 1], theirs[:, 1], rtol=RTOL, atol=atol, err_msg="tangent")


@pytest.mark.parametrize("material", MATERIALS)
@pytest.mark.parametrize("history", HISTORIES)
def test_stress_and_tangent_are_those_of_opensees(ops, material, history):
    arguments = MATERIALS[material]
    strains = HISTORIES[history]
    p = Steel02Parameters(*arguments).packed()
    ours, states = _follow(p, initial_state(p), strains)
    # A null first increment gives exactly zero stress, which an absolute margin would hide.
    _assert_matches(ours, _opensees(ops, arguments, strains), 0.0 if "null" in history else ATOL)
    assert np.array_equal(states[:, EPS], strains)
    assert np.array_equal(states[:, SIG], ours[:, 0])
    assert np.array_equal(states[:, TANGENT], ours[:, 1])


@pytest.mark.parametrize("material", MATERIALS)
def test_the_histories_reach_every_branch(material):
    p = Steel02Parameters(*MATERIALS[material]).packed()
    kons = set()
    for name, strains in HISTORIES.items():
        ours, states = _follow(p, initial_state(p), strains)
        kons |= set(states[:, KON])
        if name.startswith(("monotonic", "symmetric", "random")):
            assert np.max(np.abs(ours[:, 0])) > 1.05 * p[FY]
    assert kons == {1.0, 2.0, 3.0}


def test_isotropic_hardening_shifts_the_curves():
    """The hardening set departs from the bar without it once cycles have grown."""
    strains = HISTORIES["symmetric growing cycles"]
    plain = Steel02Parameters(*MATERIALS["bridge bar"][:3], 18.0, 0.9, 0.1).packed()
    hardening = Steel02Parameters(*MATERIALS["isotropic hardening"]).packed()
    difference = _follow(hardening, initial_state(hardening), strains)[0][:, 0]
    difference -= _follow(plain, initial_state(plain), strains)[0][:, 0]
    assert np.max(np.abs(difference)) > 0.02 * YIELD_STRESS


@pytest.mark.parametrize("material", MATERIALS)
@pytest.mark.parametrize("seed", [11, 12])
def test_trials_before_a_commit_leave_no_trace(material, seed):
    """From every committed state of a history, trials at other strains (zero, tiny and
    large increments, both ways) then at the step's strain give what one trial gives."""
    p = Steel02Parameters(*MATERIALS[material]).packed()
    rng = np.random.default_rng(seed)
    strains = np.concatenate([[0.0, 1e-16], _random_walk(seed, n=1500)])
    committed = initial_state(p)
    out = np.empty(N_STATE)
    once = np.empty(N_STATE)
    for strain in strains:
        kept = committed.copy()
        probes = committed[EPS] + np.array([0.0, 1e-16, -1e-15, *rng.normal(0.0, 0.01, 3)])
        for probe in rng.permutation(probes):
            trial(p, committed, out, probe)
        result = trial(p, committed, out, strain)
        assert result == trial(p, committed, once, strain)
        assert np.array_equal(out, once)
        assert np.array_equal(committed, kept)
        committed[:] = out


def test_the_trial_state_may_overwrite_the_committed_one():
    p = Steel02Parameters(*MATERIALS["isotropic hardening"]).packed()
    committed = initial_state(p)
    apart = np.empty(N_STATE)
    for strain in HISTORIES["random walk 0"][:500]:
        expected = trial(p, committed.copy(), apart, strain)
        assert trial(p, committed, committed, strain) == expected
        assert np.array_equal(committed, apart)


def test_initial_state_and_parameters():
    p = Steel02Parameters(*MATERIALS["isotropic hardening"]).packed()
    assert p.dtype == np.float64 and p.ndim == 1
    state = initial_state(p)
    assert state.shape == (N_STATE,) and state.dtype == np.float64
    assert state[TANGENT] == MODULUS and state[KON] == 0.0
    assert state[SIG] == 0.0 and state[EPS] == 0.0
    defaults = Steel02Parameters(1.0, 2.0, 0.1).packed()
    assert np.array_equal(defaults, Steel02Parameters(1.0, 2.0, 0.1, 20.0, 0.925, 0.15).packed())


@pytest.mark.parametrize(
    "arguments",
    [
        (0.0, MODULUS, 0.01),
        (YIELD_STRESS, -MODULUS, 0.01),
        (YIELD_STRESS, MODULUS, 1.0),
        (YIELD_STRESS, MODULUS, -0.01),
        (YIELD_STRESS, MODULUS, 0.01, 0.0),
        (YIELD_STRESS, MODULUS, 0.01, 20.0, 1.0),
        (YIELD_STRESS, MODULUS, 0.01, 20.0, 0.925, 0.0),
        (YIELD_STRESS, MODULUS, 0.01, 20.0, 0.925, 0.15, 0.0, 0.0, 0.0, 1.0),
        (YIELD_STRESS, MODULUS, 0.01, 20.0, 0.925, 0.15, 0.0, 1.0, 0.0, -1.0),
        (float("nan"), MODULUS, 0.01),
        (YIELD_STRESS, float("inf"), 0.01),
        (YIELD_STRESS, MODULUS, "b"),
    ],
)
def test_bad_parameters_are_refused(arguments):
    with pytest.raises(ValueError, match="Steel02"):
        Steel02Parameters(*arguments)
