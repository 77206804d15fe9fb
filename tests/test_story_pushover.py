"""The pushover helpers of the signals layer: protocols, floor masses, load patterns and
the curves' own checks."""

from __future__ import annotations

import numpy as np
import pytest

from cphysfno_core import InputError
from cphysfno_core.plugin import LinearSystem, StoryPushover
from cphysfno_core.signals import (
    cyclic_protocol,
    first_mode_pattern,
    floor_masses,
    lateral_pattern,
    monotonic_protocol,
)


def chain(masses, springs) -> LinearSystem:
    """Masses on a chain of springs from the ground, every DOF an output."""
    k = np.asarray(springs, dtype=float)
    above = np.append(k[1:], 0.0)
    stiffness = np.diag(k + above) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    n = len(masses)
    return LinearSystem(np.diag(masses), np.zeros((n, n)), stiffness, np.ones(n), np.eye(n))


def test_cyclic_protocol_grows_through_whole_cycles():
    protocol = cyclic_protocol([0.01, 0.02], points_per_cycle=8)
    expected = [0, 0.005, 0.01, 0.005, 0, -0.005, -0.01, -0.005, 0]
    assert np.allclose(protocol[:9], expected)
    assert np.allclose(protocol[8:], 2.0 * np.asarray(expected))
    with pytest.raises(InputError, match="multiple of 4"):
        cyclic_protocol([0.01], points_per_cycle=10)


def test_monotonic_protocol_starts_with_a_small_step():
    protocol = monotonic_protocol(0.02, 5)
    assert np.allclose(protocol, [0.0, 2e-6, 0.006668, 0.013334, 0.02])
    with pytest.raises(InputError, match="target > 0"):
        monotonic_protocol(-0.01)


def test_floor_masses_take_a_share_of_the_mass_between_floors():
    # floors at DOFs 0 and 2; DOF 1 between them moves as statics puts it
    k1, k2, k3 = 3.0e7, 2.0e7, 1.0e7
    system = chain([1.0e4, 4.0e3, 2.0e4], [k1, k2, k3])
    share = k2 / (k2 + k3)
    expected = [1.0e4 + 4.0e3 * share, 2.0e4 + 4.0e3 * (1.0 - share)]
    assert np.allclose(floor_masses(system, [0, 2]), expected, rtol=1e-12)
    assert np.allclose(floor_masses(chain([1.0, 2.0], [5.0, 3.0]), [0, 1]), [1.0, 2.0])


def test_first_mode_pattern_of_two_equal_floors():
    golden = (1.0 + np.sqrt(5.0)) / 2.0
    pattern = first_mode_pattern(chain([1.0, 1.0], [1.0, 1.0]), [0, 1], np.ones(2))
    assert np.allclose(pattern, np.array([1.0, golden]) / (1.0 + golden), rtol=1e-12)


def test_lateral_pattern_is_scaled_and_checked():
    assert np.allclose(lateral_pattern([1.0, 3.0], 2), [0.25, 0.75])
    for bad in ([1.0], [0.0, 0.0], [1.0, -1.0], [np.nan, 1.0]):
        with pytest.raises(InputError, match="lateral load pattern"):
            lateral_pattern(bad, 2)


def test_story_pushover_refuses_arrays_of_other_shapes():
    ones = np.ones(2)
    with pytest.raises(InputError, match=r"story_shear must be \[3, 2\]"):
        StoryPushover(np.zeros(3), np.zeros((3, 2)), np.zeros((2, 2)), ones, ones, ones / 2)
