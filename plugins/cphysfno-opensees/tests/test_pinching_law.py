"""The ``pinching`` story law against OpenSees' ``Hysteretic`` material (``pinchX``,
``pinchY``, no damage, ``beta``) along one cyclic drift history, and ``cracked-pinching``
against ``Hysteretic`` beside ``ElasticPP`` and ``ElasticMultiLinear`` materials (in
parallel: their stresses add).

Where the two differ, and why:

- A step in which the force changes sign: OpenSees takes the whole step at the unloading
  stiffness of the side the force heads for, the law switches at the zero crossing. The
  difference is of the order of that stiffness difference times the step and shrinks with
  the step (here below 1e-3 of the peak force, 2e-3 with ``beta = 1``).
- Before the story has passed ``u_y`` both ways, OpenSees takes its backbone whenever the
  drift passes the largest drift seen that way, even below yield (its largest drift starts
  at zero), where the law aims at the yield point: the history first goes past yield
  both ways.
- With unloading lines flatter than the reloading branches (``beta`` near 1), a force can
  keep the sign of the side the drift heads for past that side's last zero crossing;
  OpenSees then sets it to zero in one step, the law keeps it on its branch. Up to the
  first such jump the two agree as closely as elsewhere.
"""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_bouc_wen.laws import CrackedPinchingLaw, PinchingLaw
from cphysfno_opensees.uniaxial import uniaxial_stress

from cphysfno_core.testing.story_law import cyclic_drift, drive

K, U_Y, ALPHA = 1.0e7, 0.01, 0.05
FAR = 11.0 * U_Y
"""The second backbone point of the OpenSees material, far past every drift here, m."""


def _history() -> np.ndarray:
    """Past yield both ways (1.5 u_y), cycles growing to 4 u_y, a half-size excursion
    off-centre, then a random walk to about 8 u_y with many small reversals; samples at
    most 0.03 u_y apart."""
    first = np.concatenate([np.linspace(0, 1.5, 61), np.linspace(1.5, -1.5, 121)[1:]])
    first = np.concatenate([first, np.linspace(-1.5, 0.0, 61)[1:]]) * U_Y
    cycles = cyclic_drift(4.0 * U_Y)
    cycles = np.concatenate([cycles, 0.5 * cycles[:800] + cycles[-1]])
    walk = np.cumsum(np.random.default_rng(0).standard_normal(4000))
    walk = np.convolve(walk, np.ones(50) / 50, "same")
    walk = cycles[-1] + 8.0 * U_Y * (walk - walk[0]) / np.abs(walk).max()
    path = np.concatenate([first, cycles[1:], walk])
    return np.interp(np.arange(2 * len(path) - 1) / 2.0, np.arange(len(path)), path)


def _opensees(
    pinch_x: float, pinch_y: float, beta: float, path: np.ndarray, k: float = K
) -> np.ndarray:
    fy, strength = k * U_Y, k * U_Y + ALPHA * k * (FAR - U_Y)
    backbone = [fy, U_Y, strength, FAR, -fy, -U_Y, -strength, -FAR]
    return uniaxial_stress(
        ["Hysteretic", 1, *backbone, pinch_x, pinch_y, 0.0, 0.0, beta], path
    )


def _law(pinch_x: float, pinch_y: float, beta: float, path: np.ndarray) -> np.ndarray:
    law = PinchingLaw(
        alpha=ALPHA, yield_displacement=U_Y, pinch_x=pinch_x, pinch_y=pinch_y, beta_unload=beta
    )
    return drive(law.functions(), law.n_states, law.coefficients(np.array([K]))[0], path)


@pytest.fixture(scope="module")
def history() -> np.ndarray:
    return _history()


@pytest.mark.parametrize(
    ("pinch_x", "pinch_y", "beta"),
    [(0.8, 0.2, 0.0), (0.5, 0.3, 0.4), (0.2, 0.5, 0.2), (1.0, 0.4, 0.5), (0.05, 0.05, 0.0)],
)
def test_pinching_follows_opensees_hysteretic(pinch_x, pinch_y, beta, history) -> None:
    reference = _opensees(pinch_x, pinch_y, beta, history)
    loop = _law(pinch_x, pinch_y, beta, history)
    assert np.max(np.abs(loop - reference)) < 1e-3 * np.max(np.abs(reference))


def test_pinching_follows_opensees_up_to_its_jump_to_zero_force(history) -> None:
    """``beta = 1``: OpenSees' force jumps to zero once (a change larger than ``k`` times
    the drift step); before it the two agree, to 2e-3 of the peak force (the steps that
    cross zero force differ by the largest stiffness difference of all here)."""
    reference = _opensees(0.5, 0.2, 1.0, history)
    loop = _law(0.5, 0.2, 1.0, history)
    jumps = np.flatnonzero(
        (reference[1:] == 0.0) & (np.abs(np.diff(reference)) > 1.01 * K * np.abs(np.diff(history)))
    )
    assert len(jumps) > 0
    before = slice(0, jumps[0] + 1)
    assert np.max(np.abs(loop[before] - reference[before])) < 2e-3 * np.max(np.abs(reference))
    assert np.all(np.isfinite(loop))
    assert np.max(np.abs(loop)) <= np.max(np.abs(reference)) * (1.0 + 1e-3)


@pytest.mark.parametrize(
    ("share", "cracking", "hysteresis"),
    [(0.4, 0.1 * U_Y, 0.0), (0.8, 0.5 * U_Y, 1.0), (0.6, 0.2 * U_Y, 0.5)],
)
def test_cracked_pinching_follows_opensees_hysteretic_beside_its_cracking_materials(
    share, cracking, hysteresis, history
):
    """The cracking spring as ``ElasticPP`` (its elastic-perfectly-plastic share ``h``)
    beside ``ElasticMultiLinear`` (its nonlinear-elastic rest), in parallel with
    ``Hysteretic``."""
    pinch_x, pinch_y, beta = 0.5, 0.3, 0.4
    reference = _opensees(pinch_x, pinch_y, beta, history, k=(1.0 - share) * K)
    plastic, elastic = hysteresis * share * K, (1.0 - hysteresis) * share * K
    if plastic > 0.0:
        reference += uniaxial_stress(["ElasticPP", 1, plastic, cracking], history)
    if elastic > 0.0:
        top = elastic * cracking
        strain, stress = (-FAR, -cracking, cracking, FAR), (-top, -top, top, top)
        reference += uniaxial_stress(
            ["ElasticMultiLinear", 1, 0.0, "-strain", *strain, "-stress", *stress], history
        )
    law = CrackedPinchingLaw(
        alpha=ALPHA,
        yield_displacement=U_Y,
        pinch_x=pinch_x,
        pinch_y=pinch_y,
        beta_unload=beta,
        crack_share=share,
        crack_displacement=cracking,
        crack_hysteresis=hysteresis,
    )
    loop = drive(law.functions(), law.n_states, law.coefficients(np.array([K]))[0], history)
    assert np.max(np.abs(loop - reference)) < 1e-3 * np.max(np.abs(reference))
