"""One-record analyses of the SAC frame in this process: elastic interior sections are
exact while the interior stays elastic, and a record that drifts further is analysed with
fibres everywhere."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from cphysfno_opensees.sac9.analysis import (
    INTERIOR_DRIFT_LIMIT,
    SolverConfig,
    analyse_record,
    peak_drift_ratio,
    transient_response,
)
from cphysfno_opensees.sac9.model import FrameConfig
from cphysfno_opensees.sac9.phases import elastic_start
from cphysfno_opensees.transient import Abandoned
from sac9_pulses import DAMPING, DT, pulse, relative

ENDS_ONLY = FrameConfig()
EVERYWHERE = dataclasses.replace(ENDS_ONLY, elastic_interior=False)


def test_peak_drift_ratio_of_two_floors():
    u = np.array([[0.0, 0.0], [0.03, 0.01], [-0.01, -0.05]])
    assert peak_drift_ratio(u, np.array([3.0, 5.0])) == pytest.approx(0.02)


def test_elastic_interior_is_exact_while_the_ends_yield():
    u, heights = transient_response(ENDS_ONLY, SolverConfig(), DAMPING, pulse(1.0), DT)
    fibres, _ = transient_response(EVERYWHERE, SolverConfig(), DAMPING, pulse(1.0), DT)
    small, _ = transient_response(ENDS_ONLY, SolverConfig(), DAMPING, pulse(0.01), DT)
    assert relative(100.0 * small, u) > 0.01  # the frame yielded (measured 0.017)
    assert peak_drift_ratio(u, heights) < INTERIOR_DRIFT_LIMIT
    assert relative(u, fibres) < 1e-12


def test_a_record_that_would_yield_the_interior_is_analysed_with_fibres_everywhere():
    ends, heights = transient_response(ENDS_ONLY, SolverConfig(), DAMPING, pulse(3.0), DT)
    fibres, _ = transient_response(EVERYWHERE, SolverConfig(), DAMPING, pulse(3.0), DT)
    assert peak_drift_ratio(ends, heights) > INTERIOR_DRIFT_LIMIT
    assert relative(ends, fibres) > 1e-4  # the interior yielded: the shortcut is not exact
    with pytest.raises(Abandoned):
        transient_response(ENDS_ONLY, SolverConfig(), DAMPING, pulse(3.0), DT, guard_interior=True)
    answer = analyse_record(ENDS_ONLY, SolverConfig(), DAMPING, pulse(3.0), DT)
    start = elastic_start(ENDS_ONLY, DAMPING, pulse(3.0), DT)
    from_start, _ = transient_response(
        EVERYWHERE, SolverConfig(), DAMPING, pulse(3.0), DT, start=start
    )
    assert np.array_equal(answer, from_start)
    assert relative(answer, fibres) < 1e-5


@pytest.mark.parametrize("amplitude", [1.6, 2.0])
def test_past_the_drift_limit_the_interior_is_checked_not_given_up(amplitude):
    """Stories drift 1.7-1.8 % and the interior stays elastic: the elastic interior is
    exact, and its answer is kept."""
    plain = SolverConfig(elastic_phases=False)
    ends, heights = transient_response(ENDS_ONLY, plain, DAMPING, pulse(amplitude), DT)
    fibres, _ = transient_response(EVERYWHERE, plain, DAMPING, pulse(amplitude), DT)
    assert peak_drift_ratio(ends, heights) > INTERIOR_DRIFT_LIMIT
    assert relative(ends, fibres) < 1e-12
    guarded, _ = transient_response(
        ENDS_ONLY, plain, DAMPING, pulse(amplitude), DT, guard_interior=True
    )
    assert np.array_equal(guarded, ends)
    assert np.array_equal(analyse_record(ENDS_ONLY, plain, DAMPING, pulse(amplitude), DT), ends)


def test_the_first_analysis_stops_at_the_step_the_interior_would_yield():
    """Stopped at the step at which the guard saw an interior fibre at its yield stress:
    up to the step before, fibres everywhere give the same answer; from it on, not."""
    plain = SolverConfig(elastic_phases=False)
    with pytest.raises(Abandoned) as raised:
        transient_response(ENDS_ONLY, plain, DAMPING, pulse(2.4), DT, guard_interior=True)
    stopped = round(raised.value.time_s / DT)
    ends, _ = transient_response(ENDS_ONLY, plain, DAMPING, pulse(2.4), DT)
    fibres, _ = transient_response(EVERYWHERE, plain, DAMPING, pulse(2.4), DT)
    assert relative(ends[:stopped], fibres[:stopped]) < 1e-12
    assert relative(ends[stopped + 1 :], fibres[stopped + 1 :]) > 1e-8


def test_tight_newton_agrees_with_the_default_solver():
    tight = SolverConfig(test="NormDispIncr", tolerance=1e-12, algorithm=("Newton",))
    default = analyse_record(ENDS_ONLY, SolverConfig(), DAMPING, pulse(1.0), DT)
    reference = analyse_record(ENDS_ONLY, tight, DAMPING, pulse(1.0), DT)
    assert relative(default, reference) < 1e-5
