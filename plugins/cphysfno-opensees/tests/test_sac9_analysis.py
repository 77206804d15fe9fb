"""One-record analyses of the SAC frame in this process: elastic interior sections are
exact while the interior stays elastic, and a record that drifts further is analysed with
fibres everywhere."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from cphysfno_opensees.sac9_analysis import (
    INTERIOR_DRIFT_LIMIT,
    Rayleigh,
    SolverConfig,
    analyse_record,
    elastic_start,
    peak_drift_ratio,
    transient_response,
)
from cphysfno_opensees.sac9_model import FrameConfig
from cphysfno_opensees.transient import Abandoned

DT = 0.01
DAMPING = Rayleigh.matching(2.0 * np.pi / 2.37, 2.0 * np.pi / 0.51, 0.03)
ENDS_ONLY = FrameConfig()
EVERYWHERE = dataclasses.replace(ENDS_ONLY, elastic_interior=False)


def pulse(amplitude: float) -> np.ndarray:
    """One sine cycle of 1.5 s and ``amplitude`` m/s^2, then 0.5 s at rest (dt 0.01 s)."""
    t = np.arange(201) * DT
    return amplitude * np.sin(2.0 * np.pi * t / 1.5) * (t < 1.5)


def relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


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


def test_a_record_past_the_drift_limit_is_analysed_with_fibres_everywhere():
    ends, heights = transient_response(ENDS_ONLY, SolverConfig(), DAMPING, pulse(3.0), DT)
    fibres, _ = transient_response(EVERYWHERE, SolverConfig(), DAMPING, pulse(3.0), DT)
    assert peak_drift_ratio(ends, heights) > INTERIOR_DRIFT_LIMIT
    assert relative(ends, fibres) > 1e-4  # the interior yielded: the shortcut is not exact
    answer = analyse_record(ENDS_ONLY, SolverConfig(), DAMPING, pulse(3.0), DT)
    start = elastic_start(ENDS_ONLY, DAMPING, pulse(3.0), DT)
    from_start, _ = transient_response(
        EVERYWHERE, SolverConfig(), DAMPING, pulse(3.0), DT, start=start
    )
    assert np.array_equal(answer, from_start)
    assert relative(answer, fibres) < 1e-5


def test_the_first_analysis_stops_once_the_drift_passes_the_limit():
    ends, heights = transient_response(ENDS_ONLY, SolverConfig(), DAMPING, pulse(3.0), DT)
    drift = np.abs(np.diff(ends, axis=1, prepend=0.0)) / np.diff(heights, prepend=0.0)
    first_past = int(np.argmax(drift.max(axis=1) > INTERIOR_DRIFT_LIMIT))
    with pytest.raises(Abandoned) as raised:
        transient_response(
            ENDS_ONLY, SolverConfig(), DAMPING, pulse(3.0), DT, drift_limit=INTERIOR_DRIFT_LIMIT
        )
    stopped = round(raised.value.time_s / DT)
    assert first_past <= stopped < first_past + 100


def test_tight_newton_agrees_with_the_default_solver():
    tight = SolverConfig(test="NormDispIncr", tolerance=1e-12, algorithm=("Newton",))
    default = analyse_record(ENDS_ONLY, SolverConfig(), DAMPING, pulse(1.0), DT)
    reference = analyse_record(ENDS_ONLY, tight, DAMPING, pulse(1.0), DT)
    assert relative(default, reference) < 1e-5
