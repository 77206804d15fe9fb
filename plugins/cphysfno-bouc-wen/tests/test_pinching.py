"""The pinching law: one cycle computed by hand, the peak-oriented law as its special case,
and the law checks over its parameter range; the cracked pinching law: its trilinear
backbone by hand, the pinching law as its special case, its law checks."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_core import ConfigError, create
from cphysfno_core.testing import check_story_law
from cphysfno_core.testing.story_law import cyclic_drift, drive

from cphysfno_bouc_wen.laws import CrackedPinchingLaw, PeakOrientedLaw, PinchingLaw

K, U_Y, ALPHA = 1.0e7, 0.01, 0.05
PINCH_X, PINCH_Y, BETA = 0.5, 0.25, 0.5


def _loop(law, path: np.ndarray) -> np.ndarray:
    return drive(law.functions(), law.n_states, law.coefficients(np.array([K]))[0], path)


def _by_hand(v: float, leg: int) -> float:
    """The story shear over ``k u_y`` at drift ``v`` (in ``u_y``) on each leg of the cycle
    0 -> 2 -> -2 -> 2 u_y, from the law's rules (``pinch_x = 0.5``, ``pinch_y = 0.25``,
    ``beta_unload = 0.5``, ``alpha = 0.05``)."""
    top = 1.0 + ALPHA * (2.0 - 1.0)  # backbone at 2 u_y: 1.05
    k_u = (1.0 / 2.0) ** BETA  # unloading stiffness over k after reaching 2 u_y: 1/sqrt(2)
    if leg == 0:  # elastic, then the backbone
        return v if v <= 1.0 else 1.0 + ALPHA * (v - 1.0)
    if leg == 1:
        # unloading at k_u to the zero crossing, then toward the negative peak (-u_y, not
        # yet passed: unloading stiffness k there) through the pinch point
        crossing = 2.0 - top / k_u
        toward = -1.0 + (1.0 - PINCH_Y)  # unloading line from (-1, -1) at k reaches -0.25
        pinch = toward - (1.0 - PINCH_X) * (toward - crossing)
        if v >= crossing:
            return top + k_u * (v - 2.0)
        if v >= pinch:
            return -PINCH_Y * (crossing - v) / (crossing - pinch)
        if v >= -1.0:
            return -PINCH_Y - (1.0 - PINCH_Y) * (pinch - v) / (pinch + 1.0)
        return -1.0 + ALPHA * (v + 1.0)
    # leg 2: unloading from (-2, -1.05) at k_u, then through the pinch point to (2, 1.05)
    crossing = -2.0 + top / k_u
    toward = 2.0 - (1.0 - PINCH_Y) * top / k_u
    pinch = toward - (1.0 - PINCH_X) * (toward - crossing)
    if v <= crossing:
        return -top + k_u * (v + 2.0)
    if v <= pinch:
        return PINCH_Y * top * (v - crossing) / (pinch - crossing)
    return PINCH_Y * top + (1.0 - PINCH_Y) * top * (v - pinch) / (2.0 - pinch)


def test_one_cycle_follows_the_hand_computation() -> None:
    legs = [np.linspace(0.0, 2.0, 401), np.linspace(2.0, -2.0, 801), np.linspace(-2.0, 2.0, 801)]
    path = np.concatenate([legs[0], legs[1][1:], legs[2][1:]]) * U_Y
    law = PinchingLaw(
        alpha=ALPHA, yield_displacement=U_Y, pinch_x=PINCH_X, pinch_y=PINCH_Y, beta_unload=BETA
    )
    coefficients = law.coefficients(np.array([K]))[0]
    force = drive(law.functions(), law.n_states, coefficients, path, substeps=32) / (K * U_Y)
    leg = np.concatenate([np.zeros(401), np.ones(800), np.full(800, 2)]).astype(int)
    expected = np.array([_by_hand(v, n) for v, n in zip(path / U_Y, leg, strict=True)])
    error = np.abs(force - expected)
    # the samples that sit on a corner of the backbone (drift u_y, -u_y, then 2 u_y) carry
    # the error of the Runge-Kutta step that ends there; every other sample is exact
    corners = np.isclose(np.abs(path), U_Y) | (np.arange(len(path)) == len(path) - 1)
    assert np.max(error[~corners]) < 1e-6
    assert np.max(error[corners]) < 5e-5
    # the reloading branches are pinched: at zero drift the force is far below the
    # peak-oriented law's
    zero = np.flatnonzero((leg == 2) & (np.abs(path) < 1e-12))[0]
    assert force[zero] == pytest.approx(_by_hand(0.0, 2))
    assert force[zero] < 0.25


def _path() -> np.ndarray:
    path = cyclic_drift(4.0 * U_Y)
    walk = np.cumsum(np.random.default_rng(1).standard_normal(3000))
    walk = np.convolve(walk, np.ones(40) / 40, "same")
    return np.concatenate([path, path[-1] + 6.0 * U_Y * (walk - walk[0]) / np.abs(walk).max()])


def test_without_pinching_or_degradation_it_is_the_peak_oriented_law() -> None:
    path = _path()
    pinching = PinchingLaw(
        alpha=ALPHA, yield_displacement=U_Y, pinch_x=1.0, pinch_y=1.0, beta_unload=0.0
    )
    peak_oriented = PeakOrientedLaw(alpha=ALPHA, yield_displacement=U_Y)
    assert np.array_equal(_loop(pinching, path), _loop(peak_oriented, path))


@pytest.mark.parametrize(
    "shape",
    [
        {},
        {"pinch_x": 0.05, "pinch_y": 0.05, "beta_unload": 1.0},
        {"pinch_x": 1.0, "pinch_y": 0.3, "beta_unload": 0.4},
        {"pinch_x": 0.2, "pinch_y": 1.0, "beta_unload": 1.0},
    ],
    ids=["default", "strong", "force-only", "steep"],
)
def test_the_pinching_law_passes_the_law_checks(shape) -> None:
    check_story_law(create("story_law", "pinching", yield_displacement=U_Y, **shape))


def test_pinching_dissipates_less_than_the_peak_oriented_law() -> None:
    path = _path()
    pinched = _loop(PinchingLaw(alpha=ALPHA, yield_displacement=U_Y, pinch_y=0.2), path)
    full = _loop(PeakOrientedLaw(alpha=ALPHA, yield_displacement=U_Y), path)
    assert 0.0 < np.trapezoid(pinched, path) < 0.8 * np.trapezoid(full, path)


def test_per_story_shape_parameters_and_their_bounds() -> None:
    law = PinchingLaw(yield_displacement=U_Y, pinch_x=(0.2, 0.4), beta_unload=(0.0, 0.5))
    c = law.coefficients(np.array([K, 2 * K]))
    assert c.shape == (2, 6)
    assert np.array_equal(c[:, 3:], [[0.2, 0.2, 0.0], [0.4, 0.2, 0.5]])
    with pytest.raises(ConfigError, match=r"story_law\.pinch_x.*2 values for 3"):
        law.coefficients(np.full(3, K))
    for field in ("pinch_x", "pinch_y", "beta_unload"):
        with pytest.raises(ConfigError, match=field):
            create("story_law", "pinching", yield_displacement=U_Y, **{field: 1.5})


CRACKED = {"crack_share": 0.6, "crack_displacement": 0.2 * U_Y}


def test_the_cracked_backbone_is_trilinear() -> None:
    """Monotonic to 3 u_y: ``k`` to ``u_c``, ``(1 - r) k`` to ``u_y``, then
    ``alpha (1 - r) k``, plus the cracking spring's ``r k u_c``."""
    law = CrackedPinchingLaw(alpha=ALPHA, yield_displacement=U_Y, **CRACKED)
    v = np.linspace(0.0, 3.0 * U_Y, 601)
    force = _loop(law, v)
    r, u_c = CRACKED["crack_share"], CRACKED["crack_displacement"]
    cracking = r * K * np.minimum(v, u_c)
    pinching = (1.0 - r) * K * np.where(v <= U_Y, v, U_Y + ALPHA * (v - U_Y))
    corners = np.isclose(v, u_c) | np.isclose(v, U_Y)  # the step that ends there errs
    expected = cracking + pinching
    np.testing.assert_allclose(force[~corners], expected[~corners], rtol=1e-9, atol=1e-3)
    np.testing.assert_allclose(force[corners], expected[corners], rtol=5e-5)


def test_without_cracking_it_is_the_pinching_law() -> None:
    path = _path()
    shape = {"pinch_x": 0.5, "pinch_y": 0.3, "beta_unload": 0.4}
    pinching = PinchingLaw(alpha=ALPHA, yield_displacement=U_Y, **shape)
    cracked = CrackedPinchingLaw(
        alpha=ALPHA, yield_displacement=U_Y, crack_share=0.0, crack_displacement=U_Y, **shape
    )
    assert np.array_equal(_loop(pinching, path), _loop(cracked, path))


@pytest.mark.parametrize("hysteresis", [0.0, 0.5, 1.0])
def test_cycles_below_yield_dissipate_in_the_plastic_share_of_cracking(hysteresis) -> None:
    """Three cycles at 0.5 u_y after a first loading: the pinching spring stays elastic;
    the cracking spring's elastic-perfectly-plastic share ``h`` encloses
    ``4 h r k u_c (0.5 u_y - u_c)`` a cycle, by hand, its nonlinear-elastic rest nothing.
    With ``h = 0`` the force is the trilinear backbone's on the way back as on the way
    out (``k v`` to ``u_c``, then ``r k u_c + (1 - r) k v``)."""
    amplitude = 0.5 * U_Y
    ramp = np.linspace(0.0, amplitude, 201)
    cycles = amplitude * np.cos(2.0 * np.pi * np.linspace(0.0, 3.0, 2401))
    path = np.concatenate([ramp, cycles[1:]])
    steady = slice(len(ramp) - 1, None)
    law = CrackedPinchingLaw(yield_displacement=U_Y, crack_hysteresis=hysteresis, **CRACKED)
    force = _loop(law, path)
    r, u_c = CRACKED["crack_share"], CRACKED["crack_displacement"]
    plastic_cycle = 4.0 * r * K * u_c * (amplitude - u_c)
    area = np.trapezoid(force[steady], path[steady])
    assert area == pytest.approx(3 * hysteresis * plastic_cycle, abs=1e-3 * plastic_cycle)
    if hysteresis == 0.0:
        expected = r * K * np.clip(path, -u_c, u_c) + (1.0 - r) * K * path
        np.testing.assert_allclose(force, expected, rtol=1e-9, atol=1e-6 * K * U_Y)


@pytest.mark.parametrize("share", [0.3, 0.95])
def test_the_cracked_pinching_law_passes_the_law_checks(share) -> None:
    check_story_law(
        create(
            "story_law",
            "cracked-pinching",
            yield_displacement=U_Y,
            crack_share=share,
            crack_displacement=0.1 * U_Y,
            pinch_y=0.3,
        )
    )


def test_a_crack_share_that_leaves_the_pinching_spring_nothing_is_refused() -> None:
    with pytest.raises(ConfigError, match="crack_share"):
        create("story_law", "cracked-pinching", yield_displacement=U_Y, crack_share=1.0,
               crack_displacement=0.1 * U_Y)  # fmt: skip
