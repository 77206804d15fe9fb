"""The nonlinear bridge: linear at small amplitude, nonlinear at large, usable by the
preprocessors that its capabilities allow."""

from __future__ import annotations

import logging

import numpy as np
import pytest
from cphysfno_opensees.bridge.analysis import analyse
from cphysfno_opensees.bridge.structure import AuburnRavineBridge

import cphysfno_core as cp
from cphysfno_core import GroundMotions
from cphysfno_core.plugin import PhysicsPreprocessor


def relative_l2(estimate: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per output over records and time."""
    return np.sqrt(((estimate - truth) ** 2).sum((0, 1)) / (truth**2).sum((0, 1)))


@pytest.fixture(scope="module")
def bridge() -> AuburnRavineBridge:
    return cp.create("structure", "auburn-ravine-bridge")


@pytest.fixture(scope="module")
def record() -> GroundMotions:
    """The first 6 s (rise and strong motion) of a default spectrum-compatible record."""
    source = cp.create("ground_motion", "spectrum-compatible")
    motion = source.sample(1, np.random.default_rng(11))
    return GroundMotions(motion.acceleration[:, :601], motion.dt)


@pytest.fixture(scope="module")
def els(bridge) -> PhysicsPreprocessor:
    return cp.create("preprocessor", "els").fit(bridge)


def test_at_one_percent_of_a_record_the_bridge_is_its_linear_system(bridge, record, els):
    small = GroundMotions(0.01 * record.acceleration, record.dt)
    nonlinear = bridge.simulate(small).displacement
    linear = els.transform(small)
    assert np.abs(linear).max() > 1e-5
    error = relative_l2(nonlinear, linear)
    assert np.all(error <= 0.05), error


def test_a_strong_record_takes_the_columns_out_of_their_linear_range(bridge, record, els):
    strong = GroundMotions(3.0 * record.acceleration, record.dt)
    nonlinear = bridge.simulate(strong).displacement
    linear = els.transform(strong)
    assert np.abs(nonlinear).max() > 0.02  # beyond first yield of the middle columns
    assert np.all(relative_l2(nonlinear, linear) > 0.1)


def test_a_coarse_step_is_what_opensees_finds_at_that_step(bridge, record):
    """The compiled engine at dt' = 0.05 s against OpenSees' own analysis of the same model
    under the same motion resampled onto that grid: measured 4e-4 to 7.4e-4 per output,
    the size of the difference the two Newton paths make on the fine grid."""
    coarse = bridge.simulate(record, dt=0.05).displacement[0]
    motion = record.resample(0.05)
    theirs = analyse(bridge.design, bridge.numerics, bridge.damping, "fibre", None,
                     motion.acceleration[0], 0.05)  # fmt: skip
    n = min(len(coarse), len(theirs)) - 1  # OpenSees' last step overshoots the record's end
    error = np.linalg.norm(coarse[:n] - theirs[:n], axis=0) / np.linalg.norm(theirs[:n], axis=0)
    assert error.max() < 2e-3, error


def test_relaxed_at_five_times_the_step_stays_near_the_fine_response(bridge, record):
    """Measured relative L2 from the fine response 0.09 to 0.33 per output on this record
    (the coarse grid filters the motion above 10 Hz and integrates with a longer step)."""
    relaxed = cp.create("preprocessor", "relaxed", factor=5).fit(bridge)
    z = relaxed.transform(record)
    fine = bridge.simulate(record).displacement
    assert z.shape == fine.shape
    error = relative_l2(z, fine)
    assert np.all(error < 0.4), error


def test_modal_reduction_of_the_bridge_is_its_linear_modal_truncation(bridge, record, els):
    """Without a restoring force, all modes are the ELS; three modes are not."""
    n_dof = bridge.linear_system().n_dof
    full = cp.create("preprocessor", "modal", modes=n_dof).fit(bridge).transform(record)
    linear = els.transform(record)
    assert np.all(relative_l2(full, linear) < 1e-8)
    three = cp.create("preprocessor", "modal", modes=3).fit(bridge).transform(record)
    assert np.all(np.isfinite(three)) and np.any(relative_l2(three, linear) > 1e-3)


def test_a_record_that_does_not_converge_below_the_collapse_drift_is_not_a_collapse(record, caplog):
    hopeless = AuburnRavineBridge(tolerance=1e-300)
    motions = GroundMotions(np.vstack([np.zeros(31), record.acceleration[0, :31]]), record.dt)
    with caplog.at_level(logging.INFO, logger="cphysfno_opensees.structure"):
        responses = hopeless.simulate(motions)
    assert responses.failures == {} and responses.collapsed.tolist() == [False, False]
    assert list(responses.non_converged) == [1]
    assert responses.non_converged[1].startswith("did not converge at t = 0.00 s")
    assert "at the stop, below collapse_drift = 0.1" in responses.non_converged[1]
    assert "record 1 did not converge: did not converge at t = 0.00 s" in caplog.text
    assert np.isnan(responses.displacement[1, 1:]).all()
    assert np.array_equal(responses.displacement[0], np.zeros((31, 10)))
    # without a drift criterion, a record that stops converging is the collapse
    responses = AuburnRavineBridge(tolerance=1e-300, collapse_drift=None).simulate(motions)
    assert responses.collapsed.tolist() == [False, True] and responses.non_converged == {}
