"""The shear building's story test and pushover against closed forms and a tight-tolerance
integration of the Bouc-Wen law in the drift."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.integrate
from cphysfno_core import InputError, create
from cphysfno_core.signals import cyclic_protocol, monotonic_protocol

HEIGHTS = np.array([4.0, 3.0, 3.0])
STIFFNESS = np.array([4.0e7, 3.0e7, 2.0e7])
YIELD = np.array([0.008, 0.01, 0.012])
ALPHA = 0.05


def building(law: dict, **extra):
    return create(
        "structure",
        "shear-building",
        masses=(2.0e4, 2.0e4, 1.5e4),
        stiffnesses=tuple(STIFFNESS),
        story_heights=tuple(HEIGHTS),
        story_law=law,
        **extra,
    )


BILINEAR = {"name": "bilinear", "alpha": ALPHA, "yield_displacement": tuple(YIELD)}


def clipped_bilinear(drift: np.ndarray, k: float, u_y: float) -> np.ndarray:
    """Shear (N) of a kinematic-hardening bilinear spring along piecewise-linear drifts: the
    elastic-perfectly-plastic part follows ``z <- clip(z + dv, -u_y, u_y)`` exactly."""
    z = np.zeros_like(drift)
    for i, step in enumerate(np.diff(drift)):
        z[i + 1] = np.clip(z[i] + step, -u_y, u_y)
    return k * (ALPHA * drift + (1.0 - ALPHA) * z)


def test_monotonic_pushover_follows_each_story_backbone():
    protocol = monotonic_protocol(0.02, 41)
    curves = building(BILINEAR).story_pushover(protocol)
    drift = protocol[:, None] * HEIGHTS[None, :]
    assert np.allclose(curves.story_drift, drift, rtol=1e-15)
    backbone = np.where(
        drift <= YIELD, STIFFNESS * drift, STIFFNESS * (YIELD + ALPHA * (drift - YIELD))
    )
    assert np.allclose(curves.story_shear, backbone, rtol=1e-12)
    assert np.allclose(curves.initial_stiffness, STIFFNESS, rtol=1e-12)
    assert np.array_equal(curves.heights, HEIGHTS)
    assert curves.stopped == ""


def test_cyclic_pushover_follows_the_moving_elastic_range():
    protocol = cyclic_protocol([0.002, 0.006, 0.012], points_per_cycle=40)
    curves = building(BILINEAR).story_pushover(protocol)
    for s in range(3):
        expected = clipped_bilinear(curves.story_drift[:, s], STIFFNESS[s], YIELD[s])
        # a corner turned within a Runge-Kutta step (1e-3 of the largest drift) is off by
        # half a step at most
        error = np.abs(curves.story_shear[:, s] - expected).max()
        step = 1e-3 * np.abs(curves.story_drift[:, s]).max()
        assert error <= 0.5 * STIFFNESS[s] * step
    assert curves.story_shear.min() < -STIFFNESS[0] * YIELD[0]  # yielded both ways


def test_bouc_wen_story_test_matches_a_tight_integration_in_the_drift():
    n, u_y, alpha = 2.0, 0.01, 0.1
    law = {"name": "bouc-wen", "alpha": alpha, "exponent": n, "yield_displacement": u_y}
    protocol = cyclic_protocol([0.002, 0.005], points_per_cycle=80)
    curves = building(law).story_pushover(protocol)
    beta = gamma = 0.5 / u_y**n
    for s in range(3):
        drift = curves.story_drift[:, s]
        h = [0.0]
        for a, b in zip(drift[:-1], drift[1:], strict=True):
            sign = np.sign(b - a)

            def slope(v, y, sign=sign):
                return [1.0 - beta * sign * abs(y[0]) ** (n - 1) * y[0] - gamma * abs(y[0]) ** n]

            step = scipy.integrate.solve_ivp(slope, (a, b), [h[-1]], rtol=1e-11, atol=1e-14)
            h.append(step.y[0, -1])
        expected = STIFFNESS[s] * (alpha * drift + (1.0 - alpha) * np.asarray(h))
        error = np.abs(curves.story_shear[:, s] - expected).max()
        assert error < 1e-6 * np.abs(expected).max()


def test_default_pattern_is_the_first_mode_times_the_masses():
    # two equal floors on equal springs: first mode [1, (1 + sqrt 5) / 2]
    twin = create("structure", "shear-building", masses=1e4, stiffnesses=1e7, n_stories=2)
    curves = twin.story_pushover(monotonic_protocol(0.001, 5))
    golden = (1.0 + np.sqrt(5.0)) / 2.0
    assert np.allclose(curves.pattern, np.array([1.0, golden]) / (1.0 + golden), rtol=1e-12)
    assert np.array_equal(curves.masses, [1e4, 1e4])


def test_a_given_pattern_is_kept_scaled_to_one_and_a_bad_one_refused():
    structure = building(BILINEAR)
    curves = structure.story_pushover(monotonic_protocol(0.001, 5), np.array([1.0, 2.0, 5.0]))
    assert np.allclose(curves.pattern, [0.125, 0.25, 0.625])
    with pytest.raises(InputError, match="lateral load pattern needs 3 values"):
        structure.story_pushover(monotonic_protocol(0.001, 5), np.array([1.0, -1.0, 1.0]))
    with pytest.raises(InputError, match=r"drift must be a finite \[p, 3\]"):
        structure.story_shears(np.zeros((4, 2)))


def test_json_round_trip_keeps_the_curves():
    from cphysfno_core.plugin import StoryPushover

    curves = building(BILINEAR).story_pushover(cyclic_protocol([0.004], points_per_cycle=8))
    again = StoryPushover.from_dict(curves.to_dict())
    for name in ("roof_drift_ratio", "story_drift", "story_shear", "masses", "heights"):
        assert np.array_equal(getattr(again, name), getattr(curves, name))
