"""The numba Concrete04 against OpenSees' own, stress and tangent at every step of many
strain histories, and its trial states independent of uncommitted trials."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_opensees.bridge.design import BridgeDesign
from cphysfno_opensees.fibre import concrete04
from cphysfno_opensees.fibre.concrete04 import (
    N_STATE,
    Concrete04Parameters,
    initial_state,
    trial,
)
from cphysfno_opensees.loader import import_opensees

RTOL = 1e-10
ATOL = 1e-3  # Pa, for stresses and tangents at or next to zero

DESIGN = BridgeDesign()
CORE = DESIGN.confined_concrete()
EC = DESIGN.concrete_modulus
FT = DESIGN.concrete_tensile_strength

MATERIALS = {
    # The two of the bridge model: cracking drops the tensile stress to zero at once.
    "core": (-CORE.strength, -CORE.peak_strain, -CORE.ultimate_strain, EC, FT, FT / EC),
    "cover": (-34.5e6, -0.002, -0.005, EC, FT, FT / EC),
    # Exponential softening after cracking, default and explicit beta.
    "softening": (-34.5e6, -0.002, -0.005, EC, FT, 10.0 * FT / EC),
    "softening beta": (-34.5e6, -0.002, -0.005, EC, FT, 20.0 * FT / EC, 0.3),
    # No tension (OpenSees' four-argument form).
    "no tension": (-34.5e6, -0.002, -0.005, EC),
    # Secant to the peak steeper than Ec: OpenSees' Popovics exponent of 400.
    "steep secant": (-30e6, -0.001, -0.002, 20e9, 2e6, 2e-4),
}


def opensees(arguments: tuple, strains: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Stress and tangent of OpenSees' Concrete04 along ``strains``, each step committed."""
    ops = import_opensees()
    ops.wipe()
    if len(arguments) == 6:
        arguments = arguments + (0.1,)  # the default beta, as Concrete04Parameters has it
    ops.uniaxialMaterial("Concrete04", 1, *arguments)
    ops.testUniaxialMaterial(1)
    stress = np.empty(len(strains))
    tangent = np.empty(len(strains))
    for i, strain in enumerate(strains):
        ops.setStrain(float(strain))  # sets the trial strain and commits it
        stress[i] = ops.getStress()
        tangent[i] = ops.getTangent()
    ops.wipe()
    return stress, tangent


def numba_run(arguments: tuple, strains: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stress, tangent and committed states of the port along ``strains``, each committed."""
    p = Concrete04Parameters(*arguments).packed()
    committed = initial_state(p)
    out = np.empty(N_STATE)
    stress = np.empty(len(strains))
    tangent = np.empty(len(strains))
    states = np.empty((len(strains), N_STATE))
    for i, strain in enumerate(strains):
        stress[i], tangent[i] = trial(p, committed, out, float(strain))
        committed[:] = out
        states[i] = committed
    return stress, tangent, states


def assert_matches_opensees(arguments: tuple, strains: np.ndarray) -> np.ndarray:
    """Compare stress and tangent at every step; returns the port's committed states."""
    expected_stress, expected_tangent = opensees(arguments, strains)
    stress, tangent, states = numba_run(arguments, strains)
    np.testing.assert_allclose(stress, expected_stress, rtol=RTOL, atol=ATOL)
    np.testing.assert_allclose(tangent, expected_tangent, rtol=RTOL, atol=ATOL)
    return states


def path(*points: float, step: float = 5e-5) -> np.ndarray:
    """Strains along straight segments through ``points`` (from zero), ``step`` apart at most,
    every point included."""
    strains = []
    start = 0.0
    for point in points:
        count = max(1, int(np.ceil(abs(point - start) / step)))
        strains.append(np.linspace(start, point, count + 1)[1:])
        start = point
    return np.concatenate(strains)


def random_walk(seed: int, steps: int = 3000) -> np.ndarray:
    """A strain history of small and large increments, mostly in -0.02..+0.003."""
    rng = np.random.default_rng(seed)
    scale = np.where(rng.random(steps) < 0.1, 2e-3, np.where(rng.random(steps) < 0.5, 2e-4, 1e-5))
    drift = -2e-5 * np.sin(np.linspace(0.0, 6.0 * np.pi, steps)) - 1e-6
    strains = np.empty(steps)
    strain = 0.0
    for i in range(steps):
        strain = min(max(strain + drift[i] + scale[i] * rng.standard_normal(), -0.02), 0.003)
        strains[i] = strain
    return strains


@pytest.fixture(params=list(MATERIALS), ids=list(MATERIALS))
def material(request) -> tuple:
    return MATERIALS[request.param]


def test_monotonic_compression_past_the_peak_and_the_crushing_strain(material):
    epscu = material[2]
    assert_matches_opensees(material, path(1.6 * epscu, step=2e-5))


def test_cyclic_compression_partial_and_full_unloading(material):
    epsc, epscu = material[1], material[2]
    points = []
    for amplitude in (0.5 * epsc, epsc, 1.7 * epsc, 0.5 * (epsc + epscu), epscu, 1.3 * epscu):
        points += [amplitude, 0.5 * amplitude, 0.9 * amplitude, 0.0, 0.6 * amplitude]
        points += [0.2 * amplitude, 1.05 * amplitude, 1e-4, amplitude]
    assert_matches_opensees(material, path(*points, step=3e-5))


def test_tension_cracking_softening_and_crack_closing(material):
    cracking = FT / EC
    points = [0.5 * cracking, 0.2 * cracking, cracking, 0.0, 1.5 * cracking, 0.5 * cracking]
    points += [3.0 * cracking, 8.0 * cracking, 2.0 * cracking, 12.0 * cracking, 25.0 * cracking]
    points += [-0.0005, 4.0 * cracking, -0.0015, 0.5 * cracking, 30.0 * cracking, -0.003]
    points += [40.0 * cracking, 0.0, 0.002, -0.0005]
    assert_matches_opensees(material, path(*points, step=1e-5))


@pytest.mark.parametrize("seed", range(5))
def test_random_walks(material, seed):
    states = assert_matches_opensees(material, random_walk(seed))
    assert np.isfinite(states).all()


def test_tiny_increments_around_zero(material):
    rng = np.random.default_rng(7)
    cracking = FT / EC
    tiny = np.cumsum(rng.choice([-3e-16, -1e-16, -1e-17, 1e-17, 1e-16, 2.5e-16], size=400))
    exact_zeros = np.array([0.0, -1e-9, 0.0, 1e-9, 0.0, -1e-6, 0.0, 0.0, 1e-6, 0.0])
    strains = np.concatenate(
        [tiny, exact_zeros, -2e-4 + tiny, exact_zeros, 0.5 * cracking + tiny, exact_zeros]
    )
    strains = np.concatenate([strains, 2.0 * cracking + tiny, exact_zeros, -3e-3 + tiny, tiny])
    assert_matches_opensees(material, strains)


def knife_edge_history(arguments: tuple) -> np.ndarray:
    """Strains landing exactly on the branch boundaries and a few ulps either side: the end
    strains of unloading lines, the most compressive and largest tensile strains reached,
    epscu, 2 epsc (where Karsan and Jirsa's rule changes formula), the cracking strain, et,
    zero, and first compressive strains barely above machine epsilon. Each strain is chosen
    from the port's own committed state, so a port off by an ulp picks it off the edge."""
    p = Concrete04Parameters(*arguments).packed()
    committed = initial_state(p)
    out = np.empty(N_STATE)
    strains = []

    def go(*targets: float) -> None:
        for strain in targets:
            strains.append(float(strain))
            trial(p, committed, out, float(strain))
            committed[:] = out

    epsc, epscu = p[concrete04.EPSC], p[concrete04.EPSCU]
    # First compressive strains about DBL_EPSILON: the unloading line ends next to zero.
    go(-2.3e-16, 1e-16, -1.5e-16, 0.0, -4e-16, -2.4e-16, 1e-16, -1e-16, 0.0)
    for amplitude in (0.5 * epsc, epsc, 2.0 * epsc, epscu, 1.2 * epscu):
        go(0.3 * amplitude, amplitude)
        peak, end = committed[concrete04.MIN_STRAIN], committed[concrete04.END_STRAIN]
        for edge in (end, np.nextafter(end, 0.0), np.nextafter(end, -1.0)):
            go(0.5 * (peak + end), edge, 0.5 * end, edge, 0.0, edge)  # unload, reload
        for edge in (np.nextafter(peak, 0.0), peak):
            go(0.5 * (peak + end), edge)  # reloading up to the envelope
    cracking, et = p[concrete04.CRACKING_STRAIN], p[concrete04.ET]
    for target in (cracking, 0.5 * (cracking + et), et, np.nextafter(et, 1.0), 1.5 * et):
        top = max(target, committed[concrete04.MAX_STRAIN])
        go(target, 0.4 * target)
        for edge in (np.nextafter(top, 0.0), top):
            go(0.5 * top, edge)  # reloading up to the tension envelope
        go(-1e-4, 0.0)
    return np.array(strains)


def test_knife_edges(material):
    """Steps within ulps of every boundary; stresses there are tiny, so compared with an
    absolute tolerance of 1e-12 Pa rather than 1e-3."""
    strains = knife_edge_history(material)
    expected_stress, expected_tangent = opensees(material, strains)
    stress, tangent, _ = numba_run(material, strains)
    np.testing.assert_allclose(stress, expected_stress, rtol=RTOL, atol=1e-12)
    np.testing.assert_allclose(tangent, expected_tangent, rtol=RTOL, atol=1e-12)


def test_trial_depends_only_on_the_committed_state(material):
    """Uncommitted trials leave no trace: the last trial is the one-shot trial, bit for bit,
    and the committed state is never written."""
    rng = np.random.default_rng(11)
    p = Concrete04Parameters(*material).packed()
    strains = random_walk(3, steps=1500)
    committed = initial_state(p)
    out = np.empty(N_STATE)
    fresh = np.empty(N_STATE)
    checked = 0
    for i, strain in enumerate(strains):
        if i % 7 == 3:
            before = committed.copy()
            for other in strain + rng.choice([1e-4, 2e-3, 1e-16]) * rng.standard_normal(3):
                trial(p, committed, out, float(other))
            last = trial(p, committed, out, float(strain))
            once = trial(p, committed, fresh, float(strain))
            assert last == once
            assert np.array_equal(out, fresh)
            assert np.array_equal(committed, before)
            in_place = committed.copy()  # the committed state may be the output as well
            assert trial(p, in_place, in_place, float(strain)) == once
            assert np.array_equal(in_place, fresh)
            checked += 1
        trial(p, committed, out, float(strain))
        committed[:] = out
    assert checked > 200


def test_virgin_state_and_layout():
    p = Concrete04Parameters(*MATERIALS["cover"]).packed()
    state = initial_state(p)
    assert state.shape == (N_STATE,) and state.dtype == np.float64
    assert state[concrete04.TANGENT] == EC and state[concrete04.UNLOAD_SLOPE] == EC
    assert trial(p, state, np.empty(N_STATE), 0.0) == (0.0, EC)
    secant = 34.5e6 / 0.002
    assert p[concrete04.R] == EC / (EC - secant)
    assert Concrete04Parameters(*MATERIALS["steep secant"]).packed()[concrete04.R] == 400.0
    no_tension = Concrete04Parameters(*MATERIALS["no tension"]).packed()
    assert initial_state(no_tension)[concrete04.TENSION_SLOPE] == 0.0


@pytest.mark.parametrize(
    "arguments, word",
    [
        ((34.5e6, -0.002, -0.005, EC), "fc"),
        ((-34.5e6, 0.002, -0.005, EC), "epsc"),
        ((-34.5e6, -0.002, 0.0, EC), "epscu"),
        ((-34.5e6, -0.002, -0.005, -EC), "ec"),
        ((-34.5e6, -0.002, -0.005, EC, -FT), "ft"),
        ((-34.5e6, -0.002, -0.005, EC, FT, -1e-4), "et"),
        ((-34.5e6, -0.002, -0.005, EC, FT, 1e-3, 0.0), "beta"),
        ((-34.5e6, -0.002, float("nan"), EC), "epscu"),
    ],
)
def test_bad_parameters_are_refused(arguments, word):
    with pytest.raises(ValueError, match=word):
        Concrete04Parameters(*arguments)
