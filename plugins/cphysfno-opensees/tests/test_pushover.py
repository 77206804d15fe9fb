"""Pushover and shear building checked against closed forms: a two-story OpenSees model of
bilinear springs, whose story shears and drifts follow from statics and the spring law."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_opensees.loader import import_opensees
from cphysfno_opensees.pushover import (
    PushoverCurve,
    PushoverError,
    plot_pushover,
    run_pushover,
    shear_building,
    triangular_pattern,
)
from scipy.linalg import eigh

from cphysfno_core import InputError

HEIGHTS = np.array([3.0, 6.0])
MASSES = np.array([2.0e4, 1.0e4])
STIFFNESS = np.array([4.0e7, 2.5e7])
YIELD_FORCE = np.array([3.0e5, 1.6e5])
HARDENING = 0.02


def spring_building(ops, bilinear: bool = True) -> list[int]:
    """Two floors joined to the ground and to each other by horizontal springs (all nodes
    at one point, zero-length elements); returns the floor nodes."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for node in (1, 2, 3):
        ops.node(node, 0.0, 0.0)
    ops.fix(1, 1, 1, 1)
    ops.fix(2, 0, 1, 1)
    ops.fix(3, 0, 1, 1)
    for story, (k, fy) in enumerate(zip(STIFFNESS, YIELD_FORCE, strict=True), start=1):
        if bilinear:
            ops.uniaxialMaterial("Steel01", story, float(fy), float(k), HARDENING)
        else:
            ops.uniaxialMaterial("Elastic", story, float(k))
        ops.element("zeroLength", story, story, story + 1, "-mat", story, "-dir", 1)
    return [2, 3]


def bilinear_force(drift: np.ndarray, k: float, fy: float) -> np.ndarray:
    """Spring force of a monotonically loaded bilinear spring, N."""
    yield_drift = fy / k
    return np.where(drift <= yield_drift, k * drift, fy + HARDENING * k * (drift - yield_drift))


@pytest.fixture(scope="module")
def curve() -> PushoverCurve:
    ops = import_opensees()
    floors = spring_building(ops)
    try:
        return run_pushover(ops, floors, HEIGHTS, MASSES, target_drift_ratio=0.03, n_steps=90)
    finally:
        ops.wipe()


def test_triangular_pattern_is_proportional_to_height():
    assert np.allclose(triangular_pattern(HEIGHTS), [1 / 3, 2 / 3])


def test_story_shears_follow_the_load_pattern_and_the_spring_law(curve):
    shares = np.array([1.0, 2.0 / 3.0])
    assert np.allclose(curve.story_shear, curve.base_shear[:, None] * shares[None, :])
    for story in range(2):
        expected = bilinear_force(curve.story_drift[:, story], STIFFNESS[story], YIELD_FORCE[story])
        assert np.allclose(curve.story_shear[:, story], expected, rtol=1e-6, atol=1e-3)
    assert curve.base_shear.max() > YIELD_FORCE[0]  # the first story yielded


def test_elastic_slope_gives_the_spring_stiffnesses(curve):
    assert np.allclose(curve.story_stiffness, STIFFNESS, rtol=1e-9)
    flexibility = 1.0 / STIFFNESS[0] + (2.0 / 3.0) / STIFFNESS[1]
    assert curve.initial_stiffness == pytest.approx(1.0 / flexibility, rel=1e-9)


def test_elastic_range_ends_where_the_first_story_yields(curve):
    # the first story yields at base shear F_y1; the second at 1.5 F_y2 = 2.4e5 < 3e5 N.
    end = curve.elastic_points - 1
    first_yield = 1.5 * YIELD_FORCE[1]
    assert curve.base_shear[end] <= first_yield * (1 + 1e-9)
    assert curve.base_shear[end + 1] > first_yield * (1 - 0.05)


def test_a_pushover_that_stays_elastic_is_an_error():
    ops = import_opensees()
    floors = spring_building(ops, bilinear=False)
    try:
        with pytest.raises(PushoverError, match="stayed elastic"):
            run_pushover(ops, floors, HEIGHTS, MASSES, target_drift_ratio=0.01, n_steps=10)
    finally:
        ops.wipe()


def test_mismatched_floors_are_refused():
    ops = import_opensees()
    with pytest.raises(InputError, match="one height and one mass per floor"):
        run_pushover(ops, [2, 3], HEIGHTS[:1], MASSES)


def test_json_round_trip_keeps_the_curve(curve):
    again = PushoverCurve.from_json(curve.to_json())
    assert np.array_equal(again.base_shear, curve.base_shear)
    assert np.array_equal(again.floor_displacement, curve.floor_displacement)
    assert np.array_equal(again.story_stiffness, curve.story_stiffness)


def test_plot_draws_the_curve_and_the_stiffnesses(curve, tmp_path):
    path = tmp_path / "pushover.png"
    figure = plot_pushover(curve, path)
    assert len(figure.axes) == 2
    assert path.stat().st_size > 0


def test_shear_building_matrices_and_damping():
    masses = np.array([3.0, 2.0, 1.0]) * 1e4
    k = np.array([5.0, 4.0, 2.0]) * 1e7
    system = shear_building(masses, k, 0.03, (1, 3))
    expected = np.array([[9.0, -4.0, 0.0], [-4.0, 6.0, -2.0], [0.0, -2.0, 2.0]]) * 1e7
    assert np.allclose(system.stiffness, expected)
    assert np.allclose(system.mass, np.diag(masses))
    assert np.array_equal(system.influence, np.ones(3))
    assert np.array_equal(system.output_map, np.eye(3))
    squares, modes = eigh(system.stiffness, system.mass)
    ratios = np.diag(modes.T @ system.damping @ modes) / (2.0 * np.sqrt(squares))
    assert ratios[0] == pytest.approx(0.03)
    assert ratios[2] == pytest.approx(0.03)
    assert ratios[1] < 0.03  # Rayleigh damping dips between the matched modes


def test_shear_building_refuses_non_positive_stiffness():
    with pytest.raises(InputError, match="positive story stiffnesses"):
        shear_building(np.ones(2), np.array([1.0, 0.0]), 0.03, (1, 2))
