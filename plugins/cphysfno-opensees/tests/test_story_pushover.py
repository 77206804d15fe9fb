"""The pushover capability of ``opensees-model`` against closed forms, on a script of two
floors joined by bilinear springs (OpenSees' Steel01, kinematic hardening), and the
``stick`` fitted to it against the model's own simulation."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import script_models as sm
from cphysfno_physics import Stick
from script_models import records, relative_l2

from cphysfno_core import CphysfnoWarning, InputError, create
from cphysfno_core.signals import cyclic_protocol, monotonic_protocol

STIFFNESS = np.array([4.0e7, 2.5e7])
YIELD_FORCE = np.array([3.0e5, 1.6e5])
HARDENING = 0.02
MASSES = np.array([2.0e4, 1.0e4])
HEIGHTS = (3.0, 3.0)

def springs_model(folder, rayleigh: bool, hardening: float = HARDENING):
    """The script as an ``opensees-model``; its springs take the stiffness part of the
    Rayleigh damping, or (``rayleigh`` False, zeroLength's default) do not."""
    script = sm.springs(
        folder, f"springs_{int(rayleigh)}_{hardening}", stiffness=tuple(STIFFNESS),
        yield_force=tuple(YIELD_FORCE), masses=tuple(MASSES), hardening=hardening,
        rayleigh=rayleigh,
    )  # fmt: skip
    return create(
        "structure",
        "opensees-model",
        script=script,
        outputs=[[1, 1], [2, 1]],
        story_heights=list(HEIGHTS),
    )


FAST = {"cycle_amplitudes": (0.004, 0.012), "points_per_cycle": 40}


@pytest.fixture(scope="module")
def springs(tmp_path_factory):
    return springs_model(tmp_path_factory.mktemp("springs"), rayleigh=True)


def kinematic_bilinear(drift: np.ndarray, k: float, fy: float) -> np.ndarray:
    """Shear (N) of a Steel01 spring without isotropic hardening along piecewise-linear
    drifts: its elastic-perfectly-plastic part ``z`` moves with the drift, clipped to
    ``+-u_y``."""
    u_y = fy / k
    z = np.zeros_like(drift)
    for i, step in enumerate(np.diff(drift)):
        z[i + 1] = np.clip(z[i] + step, -u_y, u_y)
    return k * (HARDENING * drift + (1.0 - HARDENING) * z)


def test_monotonic_pushover_follows_statics_and_the_spring_law(springs):
    protocol = monotonic_protocol(0.02, 41)
    curves = springs.story_pushover(protocol)
    assert curves.stopped == ""
    assert np.allclose(curves.story_drift.sum(axis=1), protocol * 6.0, rtol=1e-8, atol=1e-12)
    assert np.allclose(curves.masses, MASSES, rtol=1e-9)
    # first mode of the two-degree-of-freedom chain, times the masses
    stiffness = np.array([[6.5e7, -2.5e7], [-2.5e7, 2.5e7]])
    _, modes = scipy.linalg.eigh(stiffness, np.diag(MASSES))
    load = MASSES * np.abs(modes[:, 0])
    assert np.allclose(curves.pattern, load / load.sum(), rtol=1e-9)
    shares = np.array([1.0, curves.pattern[1]])
    base = curves.story_shear[:, 0]
    assert np.allclose(curves.story_shear, base[:, None] * shares[None, :], rtol=1e-12)
    for s in range(2):
        v, k, fy = curves.story_drift[:, s], STIFFNESS[s], YIELD_FORCE[s]
        backbone = np.where(v <= fy / k, k * v, fy + HARDENING * k * (v - fy / k))
        assert np.allclose(curves.story_shear[:, s], backbone, rtol=1e-6, atol=1e-3)
    assert np.allclose(curves.initial_stiffness, STIFFNESS, rtol=1e-9)


def test_cyclic_pushover_follows_the_kinematic_hardening_loops(springs):
    protocol = cyclic_protocol([0.004, 0.012], points_per_cycle=40)
    curves = springs.story_pushover(protocol, np.array([1.0, 1.0]))
    assert curves.stopped == "" and np.allclose(curves.pattern, [0.5, 0.5])
    assert curves.story_shear[:, 0].min() < -YIELD_FORCE[0]  # yielded both ways
    for s in range(2):
        expected = kinematic_bilinear(curves.story_drift[:, s], STIFFNESS[s], YIELD_FORCE[s])
        assert np.allclose(curves.story_shear[:, s], expected, rtol=1e-6, atol=1e-3)


def test_a_pushover_stops_where_the_structure_loses_its_strength(tmp_path):
    softening = springs_model(tmp_path, rayleigh=True, hardening=-0.05)
    protocol = monotonic_protocol(0.03, 61)
    curves = softening.story_pushover(protocol)
    assert curves.stopped.startswith("lost 20% of its strength")
    base = curves.story_shear[:, 0]
    n = len(base)
    assert 2 < n < len(protocol) and np.array_equal(curves.roof_drift_ratio, protocol[:n])
    assert base[-1] < 0.8 * base.max() <= base[-2]  # the first point past the loss ends it
    assert 0.95 * YIELD_FORCE[0] < base.max() <= YIELD_FORCE[0] * (1 + 1e-9)  # story 1 yields


def test_a_pattern_of_the_wrong_length_is_refused(springs):
    with pytest.raises(InputError, match="lateral load pattern needs 2 values"):
        springs.story_pushover(monotonic_protocol(0.01, 5), np.ones(3))


def test_the_stick_finds_the_springs_and_follows_the_model(springs):
    stick = Stick(**FAST).fit(springs)
    calibration = stick.calibration_
    assert calibration.law == "bilinear"
    found = calibration.fits["bilinear"].parameters
    assert np.allclose(found["alpha"], HARDENING, rtol=1e-3)
    assert np.allclose(found["yield_displacement"], YIELD_FORCE / STIFFNESS, rtol=1e-3)
    assert np.allclose(calibration.stiffness, STIFFNESS, rtol=1e-6)
    # Rayleigh damping at both modes of a two-story model is 5 % in each: classical
    assert calibration.rayleigh_modes is None
    assert calibration.damping_ratio == pytest.approx(0.05, rel=1e-9)
    motions = records(n=2, n_steps=801, dt=0.005, peak=15.0).resample(0.001)
    u = springs.simulate(motions).displacement
    drift = np.abs(np.diff(u, axis=2, prepend=0.0)).max(axis=(0, 1))
    assert np.all(drift > 1.5 * YIELD_FORCE / STIFFNESS)
    # the model integrates with Newmark's average acceleration rule, the stick with
    # Runge-Kutta: at dt = 1 ms they differ by about 2e-3 (4e-2 at 5 ms)
    assert relative_l2(stick.transform(motions), u).max() < 0.01


def test_damping_the_stick_cannot_follow_is_named(tmp_path):
    mass_damped = springs_model(tmp_path, rayleigh=False)  # ratios 0.05 and 0.05 T2 / T1
    with pytest.warns(CphysfnoWarning, match=r"damping ratios .* modes \[2\] differ by more"):
        Stick(**FAST, laws=("bilinear",)).fit(mass_damped)
