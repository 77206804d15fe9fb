"""The bridge's linear representation against its elastic OpenSees model."""

from __future__ import annotations

import math

import numpy as np
import pytest
from cphysfno_opensees.bridge.model import build
from cphysfno_opensees.bridge.structure import AuburnRavineBridge
from cphysfno_opensees.loader import import_opensees

from cphysfno_core import ConfigError, GroundMotions
from cphysfno_core.plugin import LinearSystem


@pytest.fixture(scope="module")
def bridge() -> AuburnRavineBridge:
    return AuburnRavineBridge()


@pytest.fixture(scope="module")
def system(bridge) -> LinearSystem:
    return bridge.linear_system()


def newmark(system: LinearSystem, ag: np.ndarray, dt: float) -> np.ndarray:
    """``[T, n_outputs]`` outputs by Newmark's average acceleration rule, from rest with zero
    initial acceleration, as OpenSees starts a transient analysis."""
    m, c, k = system.mass, system.damping, system.stiffness
    effective = k + 2.0 / dt * c + 4.0 / dt**2 * m
    u = np.zeros(system.n_dof)
    v = np.zeros_like(u)
    a = np.zeros_like(u)
    out = [system.output_map @ u]
    for load in ag[1:]:
        rhs = -m @ system.influence * load
        rhs += m @ (4.0 / dt**2 * u + 4.0 / dt * v + a) + c @ (2.0 / dt * u + v)
        u_next = np.linalg.solve(effective, rhs)
        v_next = 2.0 / dt * (u_next - u) - v
        a = 4.0 / dt**2 * (u_next - u) - 4.0 / dt * v - a
        u, v = u_next, v_next
        out.append(system.output_map @ u)
    return np.array(out)


def test_the_linear_system_is_the_elastic_opensees_bridge(bridge, system):
    # The OpenSees elastic model and the condensed matrices, integrated by the same rule,
    # agree: same mass, stiffness (with gravity P-Delta) and Rayleigh damping. A small
    # motion keeps P-Delta's change of axial force with the response negligible.
    rng = np.random.default_rng(4)
    dt, n = 0.01, 301
    t = np.arange(n) * dt
    ag = 0.02 * np.sin(t / t[-1] * np.pi) ** 2 * rng.standard_normal(n).cumsum() / 10.0
    elastic = AuburnRavineBridge(columns="elastic", substeps=1)
    opensees = elastic.simulate(GroundMotions(ag, dt)).displacement[0]
    ours = newmark(system, ag, dt)
    assert np.abs(ours).max() > 1e-6
    error = np.linalg.norm(opensees - ours) / np.linalg.norm(ours)
    assert error < 1e-5, error


def test_periods_are_those_of_opensees_eigen(bridge):
    ops = import_opensees()
    build(ops, bridge.design, bridge.numerics, "elastic", bridge.elastic_section)
    squares = ops.eigen("-fullGenLapack", 6)
    ops.wipe()
    expected = 2.0 * np.pi / np.sqrt(squares)
    np.testing.assert_allclose(bridge.periods(6), expected, rtol=1e-8)
    assert bridge.periods(1)[0] == pytest.approx(0.38, abs=0.02)


def test_the_first_mode_is_transverse(bridge, system):
    import scipy.linalg

    _, modes = scipy.linalg.eigh(system.stiffness, system.mass, subset_by_index=(0, 0))
    participation = (modes[:, 0] @ system.mass @ system.influence) ** 2
    total = system.influence @ system.mass @ system.influence
    assert participation / total > 0.6


def test_the_masses_are_the_girder_diaphragms_and_half_columns(bridge, system):
    d = bridge.design
    columns = sum(0.5 * d.concrete_density * d.gross_area * h for h in d.pier_heights)
    expected = d.deck_mass_per_length * d.length + 5 * d.diaphragm_mass + 2 * columns
    transverse = system.influence @ system.mass @ system.influence
    assert transverse == pytest.approx(expected, rel=1e-12)
    assert system.output_map.shape == (10, system.n_dof)


def test_damping_is_five_percent_at_the_first_period_and_at_a_tenth_of_a_second(bridge, system):
    d = bridge.damping
    first = 2.0 * math.pi / bridge.periods(1)[0]
    for omega in (first, 2.0 * math.pi / 0.1):
        # Rayleigh: zeta = a0 / (2 w) + a1 w / 2 on the initial stiffness.
        zeta = d.mass_factor / (2.0 * omega) + d.stiffness_factor * omega / 2.0
        assert zeta == pytest.approx(0.05, rel=1e-12)


@pytest.mark.parametrize("n", [0, 104, 1.5, True])
def test_bad_numbers_of_periods_are_config_errors(bridge, n):
    with pytest.raises(ConfigError, match="n must be an integer"):
        bridge.periods(n)
