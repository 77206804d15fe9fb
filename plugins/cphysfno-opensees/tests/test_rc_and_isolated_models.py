"""The example models examples/models/rc_frame.py (a fibre RC moment frame) and
examples/models/isolated_building.py (a building on bilinear isolators), both in kN, m,
tonne and s, as their configs (examples/rc-frame.toml, examples/isolated-building.toml)
give them to ``opensees-model``: their gravity loads against the weights written in the
scripts, their masses and periods, the structure's conformance checks, and two short
records that take them past yield against OpenSeesPy run directly on the same script.
The second instance of each class (examples/models/rc_frame_5story.py,
examples/models/isolated_building_bouc_wen.py, on which the stick is checked beside the
first) for their weights, periods and the bearings' designed strength."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import script_models as sm

import cphysfno_core as cp
from cphysfno_core.plugin import Structure
from cphysfno_core.signals import monotonic_protocol
from cphysfno_core.testing import check_structure

G = 9.81  # m/s^2, as the scripts take it

MODELS = {
    # config: (total weight on the ground in kN, levels, first period in s at gravity)
    "rc-frame": (3 * 648.0, 3, 0.4482),
    "isolated-building": (4 * 576.0, 4, 0.9346),
    "rc-frame-5story": (5 * 1323.0, 5, 0.9175),
    "isolated-building-bouc-wen": (6 * 1632.0, 6, 1.0862),
}


@functools.cache
def _structure(name: str) -> Structure:
    """The example's structure, built (and its OpenSees model probed) once per session."""
    config = cp.load_config(sm.EXAMPLES / f"{name}.toml").structure
    return cp.create("structure", config.name, **{**config.params, "workers": 1})


def _config_params(name: str) -> dict:
    return cp.load_config(sm.EXAMPLES / f"{name}.toml").structure.params


@pytest.fixture(scope="module", params=list(MODELS))
def model(request) -> tuple[str, Structure]:
    return request.param, _structure(request.param)


def test_the_ground_carries_the_weights_the_script_states(model):
    """The reactions of the gravity state add up to the floors' weight, and the floor
    masses the linear system condenses are those weights over g."""
    from cphysfno_opensees.loader import import_opensees

    name, structure = model
    weight, levels, _ = MODELS[name]
    ops = import_opensees()
    script = sm.load(structure.spec.script)
    ops.wipe()
    script.build()
    script.gravity()
    sm.analyse_gravity(ops, ("Transformation",), 1e-10)
    ops.reactions()
    ground = [node for node in ops.getNodeTags() if node < 10]
    vertical = sum(ops.nodeReaction(node, 2) for node in ground)
    horizontal = sum(ops.nodeReaction(node, 1) for node in ground)
    ops.wipe()
    assert vertical == pytest.approx(weight, rel=1e-9)
    assert abs(horizontal) < 1e-9 * weight
    masses = np.diag(structure.linear_system().mass)
    np.testing.assert_allclose(masses, weight / levels / G, rtol=1e-9)


def test_periods_are_openseess_eigen_periods_at_the_gravity_state(model):
    name, structure = model
    _, levels, first = MODELS[name]
    own = sm.eigen_periods(structure.spec.script, levels, gravity=True)
    np.testing.assert_allclose(structure.periods(), own, rtol=1e-8)
    assert structure.periods()[0] == pytest.approx(first, rel=1e-3)


def test_the_isolators_pushover_is_the_bilinear_law_the_script_designs():
    """Pushed to a roof drift ratio of 3 %, the isolator story's shear against its drift
    is the bilinear curve of the design written in the script: post-yield stiffness
    K2 = M (2 pi / 2.75 s)^2 for the whole mass M on the isolators, K1 = 10 K2, yield at
    6 % of the weight above them (138.24 kN, at 11.3 mm)."""
    structure = _structure("isolated-building")
    pushover = structure.story_pushover(monotonic_protocol(0.03))
    weight = 4 * 576.0
    post_yield = weight / G * (2.0 * math.pi / 2.75) ** 2  # kN/m
    yield_force = 0.06 * weight
    yield_drift = yield_force / (10.0 * post_yield)
    drift = pushover.story_drift[:, 0]
    expected = np.where(
        drift < yield_drift,
        10.0 * post_yield * drift,
        yield_force + post_yield * (drift - yield_drift),
    )
    assert drift.max() > 20 * yield_drift
    np.testing.assert_allclose(
        pushover.story_shear[:, 0], expected, rtol=0, atol=1e-6 * yield_force
    )


def test_the_bearings_pushover_follows_the_bouc_wen_design_the_script_states():
    """Pushed to a roof drift ratio of 3 %, the Bouc-Wen bearings' story saturates on the
    line the script designs: characteristic strength Q = 5 % of the weight above them,
    post-yield stiffness K2 = M (2 pi / 3 s)^2 for the whole mass M on them (shear
    Q + K2 x once x is ten times the 10 mm yield displacement)."""
    structure = _structure("isolated-building-bouc-wen")
    pushover = structure.story_pushover(monotonic_protocol(0.03))
    weight = 6 * 1632.0
    post_yield = weight / G * (2.0 * math.pi / 3.0) ** 2  # kN/m
    strength = 0.05 * weight
    yield_drift = strength / (11.0 * post_yield)  # Q / (K1 - K2), K1 = 12 K2
    drift, shear = pushover.story_drift[:, 0], pushover.story_shear[:, 0]
    saturated = drift > 10.0 * yield_drift
    assert saturated.sum() > 20
    np.testing.assert_allclose(
        shear[saturated], strength + post_yield * drift[saturated], rtol=1e-3
    )


@pytest.mark.parametrize(
    # the five-story frame's Concrete01 carries no tension: its sections crack at any
    # amplitude, so no record is small enough for its response to be its linear system's
    "name",
    ["rc-frame", "isolated-building", "isolated-building-bouc-wen"],
)
def test_the_structures_pass_the_conformance_checks(name):
    check_structure(_structure(name))


@pytest.mark.parametrize(
    # peak of the two smooth random records (m/s^2); how far past yield they go is asserted
    ("name", "peak"),
    [("rc-frame", 8.0), ("isolated-building", 5.0)],
)
def test_two_records_past_yield_match_openseespy_run_directly(name, peak):
    """opensees-model against the same script analysed by hand in OpenSeesPy (gravity,
    eigen analysis, Rayleigh factors, Newmark, Newton): displacements and absolute
    accelerations agree to 1e-6; the records are strong enough that the response is
    nonlinear (the linear system at the gravity state is off by more than 10 %; the
    isolators move past three times their 11 mm yield displacement)."""
    structure = _structure(name)
    params = _config_params(name)
    motions = sm.records(n=2, n_steps=301, dt=0.01, peak=peak, seed=3)
    responses = structure.simulate(motions)
    assert not responses.failures and not np.any(responses.collapsed)
    outputs = [tuple(output) for output in params["outputs"]]
    for k in range(motions.n_records):
        direct = sm.direct_run(
            structure.spec.script, outputs, motions.acceleration[k], motions.dt,
            gravity=True, damping_ratio=params["damping_ratio"],
            modes=tuple(params["rayleigh_modes"]),
        )  # fmt: skip
        u = responses.displacement[k]
        assert sm.relative_l2(u, direct.displacement).max() < 1e-6
        acceleration = responses.extras["absolute_acceleration"][k]
        assert sm.relative_l2(acceleration, direct.absolute_acceleration).max() < 1e-6
    linear = cp.create("preprocessor", "els").fit(structure).transform(motions)
    assert sm.relative_l2(linear, responses.displacement).min() > 0.1
    if name == "isolated-building":
        assert np.abs(responses.displacement[:, :, 0]).max(axis=1).min() > 3 * 0.0113
