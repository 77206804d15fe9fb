"""Stepping OpenSees transient analyses: the recorded rows, the recovery ladder, the failure."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from cphysfno_opensees.loader import import_opensees
from cphysfno_opensees.transient import LADDER, Abandoned, AnalysisFailed, integrate
from scripted_ops import ScriptedOps


def test_rows_are_read_at_rest_then_after_every_step():
    ops = ScriptedOps(lambda attempt: False)
    out = integrate(ops, 5, 0.1, lambda: [ops.time, 2 * ops.time])
    assert out.shape == (6, 2)
    np.testing.assert_allclose(out[:, 0], 0.1 * np.arange(6))
    np.testing.assert_allclose(out[:, 1], 0.2 * np.arange(6))


def test_a_failed_step_climbs_the_ladder_and_the_callers_algorithm_returns():
    # Newton fails at t = 0.2 only, at any step; KrylovNewton is the first rung that works,
    # after Newton's substeps and NewtonLineSearch.
    def fails(attempt):
        return attempt.time == 0.2 and attempt.algorithm in ("Newton", "NewtonLineSearch")

    ops = ScriptedOps(fails)
    out = integrate(ops, 4, 0.1, lambda: [ops.time])
    np.testing.assert_allclose(out[:, 0], 0.1 * np.arange(5))
    at_failure = [(a.step, a.algorithm) for a in ops.attempts if a.time == 0.2]
    newton = [(step, "Newton") for step in (0.1, 0.05, 0.025, 0.01)]  # the step, its substeps
    assert at_failure == [*newton, (0.1, "NewtonLineSearch"), (0.1, "KrylovNewton")]
    assert ops.attempts[-1][:3] == (0.3, 0.1, "Newton")  # the next step is back on Newton


def test_a_failed_step_is_first_split_into_substeps_with_the_callers_algorithm():
    # Only steps of at most dt/4 converge at t = 0.1; the step is finished in quarters.
    def fails(attempt):
        return 0.1 <= attempt.time < 0.2 - 1e-9 and attempt.step > 0.1 / 4 + 1e-12

    ops = ScriptedOps(fails)
    out = integrate(ops, 3, 0.1, lambda: [ops.time], algorithm=("KrylovNewton",))
    np.testing.assert_allclose(out[:, 0], 0.1 * np.arange(4))
    quarters = [a for a in ops.attempts if a.step == pytest.approx(0.025)]
    assert len(quarters) == 4 and all(a.algorithm == "KrylovNewton" for a in quarters)
    assert ops.current == ("KrylovNewton",)


def test_a_step_nothing_completes_raises_with_time_and_what_was_tried():
    ops = ScriptedOps(lambda attempt: attempt.time >= 0.3 - 1e-9)
    with pytest.raises(AnalysisFailed) as caught:
        integrate(ops, 10, 0.1, lambda: [ops.time])
    failure = caught.value
    assert failure.time_s == pytest.approx(0.3)
    assert "t = 0.30 s" in str(failure)
    for tried in ("NewtonLineSearch", "KrylovNewton", "ModifiedNewton", "Broyden", "dt/10"):
        assert tried in failure.tried
    assert ops.current == ("Newton",)
    restored = pickle.loads(pickle.dumps(failure))  # crosses process boundaries whole
    assert (restored.time_s, restored.tried) == (failure.time_s, failure.tried)


def _oscillator(ops, mass: float, stiffness: float, yield_force: float | None) -> None:
    """A one-DOF oscillator in OpenSees, elastic or elastic-perfectly plastic."""
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(1, 0.0)
    ops.node(2, 0.0, "-mass", mass)
    ops.fix(1, 1)
    if yield_force is None:
        ops.uniaxialMaterial("Elastic", 1, stiffness)
    else:
        ops.uniaxialMaterial("Steel01", 1, yield_force, stiffness, 0.0)
    ops.element("zeroLength", 1, 1, 2, "-mat", 1, "-dir", 1)


def _analysis(ops, ag: np.ndarray, dt: float, tolerance: float, iterations: int):
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *ag)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", tolerance, iterations)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def _newmark_average_acceleration(omega: float, ag: np.ndarray, dt: float) -> np.ndarray:
    """Undamped ``u'' + omega^2 u = -a_g`` by Newmark's average acceleration, from rest."""
    u, v, a = 0.0, 0.0, -ag[0]
    out = [u]
    effective = omega**2 + 4.0 / dt**2
    for load in -ag[1:]:
        u_next = (load + 4.0 / dt**2 * u + 4.0 / dt * v + a) / effective
        a_next = 4.0 / dt**2 * (u_next - u) - 4.0 / dt * v - a
        v = v + 0.5 * dt * (a + a_next)
        u, a = u_next, a_next
        out.append(u)
    return np.array(out)


def test_an_elastic_oscillator_matches_newmark_written_out():
    ops = import_opensees()
    mass, stiffness, dt = 2.0, 800.0, 0.01
    t = np.arange(201) * dt
    ag = 1.5 * np.sin(2 * np.pi * 3.0 * t)
    _oscillator(ops, mass, stiffness, None)
    _analysis(ops, ag, dt, 1e-12, 10)
    out = integrate(ops, 200, dt, lambda: [ops.nodeDisp(2, 1)])
    expected = _newmark_average_acceleration(math.sqrt(stiffness / mass), ag, dt)
    np.testing.assert_allclose(out[:, 0], expected, rtol=0, atol=1e-10 * np.abs(expected).max())


class NewtonFailsAt:
    """Real OpenSees whose Newton iterations are cut to one (so the step fails, after
    changing the trial state) on the steps, and substeps, starting at ``times``."""

    def __init__(self, ops, times: set[float], dt: float) -> None:
        self.ops, self.times, self.dt = ops, times, dt
        self.current = ("Newton",)
        self.failed = 0

    def __getattr__(self, name):
        return getattr(self.ops, name)

    def algorithm(self, *arguments) -> None:
        self.current = arguments
        self.ops.algorithm(*arguments)

    def analyze(self, n: int, step: float) -> int:
        sabotage = self.current == ("Newton",) and round(self.ops.getTime() / self.dt) in self.times
        self.ops.test("NormDispIncr", 1e-10, 1 if sabotage else 50)
        result = self.ops.analyze(n, step)
        self.failed += result != 0
        return result


def test_opensees_retries_start_from_the_last_committed_state():
    # Steps that fail in OpenSees after an iteration and are redone by the ladder give the
    # response of an analysis that never failed.
    ops = import_opensees()
    dt = 0.01
    t = np.arange(301) * dt
    ag = 6.0 * np.sin(2 * np.pi * 2.0 * t) * np.exp(-((t - 1.0) ** 2))
    responses = []
    for sabotaged in (set(), {40, 80, 81, 120, 200}):
        _oscillator(ops, 2.0, 800.0, 4.0)
        _analysis(ops, ag, dt, 1e-10, 50)
        wrapped = NewtonFailsAt(ops, sabotaged, dt)
        responses.append(integrate(wrapped, 300, dt, lambda: [ops.nodeDisp(2, 1)])[:, 0])
        # the step, then its first substep at each split, with Newton
        assert wrapped.failed == len(sabotaged) * (1 + len(LADDER.splits))
    reference, recovered = responses
    assert np.abs(reference).max() > 3 * 4.0 / 800.0  # well past yield
    error = np.linalg.norm(recovered - reference) / np.linalg.norm(reference)
    assert error < 1e-8, error


def test_opensees_that_cannot_converge_raises_analysis_failed():
    ops = import_opensees()
    dt = 0.01
    ag = np.concatenate([np.zeros(5), np.full(50, 60.0)])
    _oscillator(ops, 2.0, 800.0, 4.0)
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *ag)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", -1.0, 3)  # no norm is below a negative tolerance
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    with pytest.raises(AnalysisFailed, match="did not converge at t = "):
        integrate(ops, 54, dt, lambda: [ops.nodeDisp(2, 1)])


def test_abandon_sees_each_block_of_rows_once_and_stops_the_analysis():
    ops = ScriptedOps(lambda attempt: False)
    blocks = []

    def abandon(rows):
        blocks.append(rows[:, 0].copy())
        return rows[-1, 0] > 0.45

    with pytest.raises(Abandoned) as raised:
        integrate(ops, 20, 0.1, lambda: [ops.time], abandon=abandon, check_every=3)
    assert raised.value.time_s == pytest.approx(0.6)
    np.testing.assert_allclose(np.concatenate(blocks), 0.1 * np.arange(1, 7))
    assert ops.time == pytest.approx(0.6)  # no step after the one that was judged


def test_a_leap_fills_the_rows_it_advances_over_and_abandon_sees_them():
    ops = ScriptedOps(lambda attempt: False)
    blocks, asked = [], []

    def leap(steps_done):
        asked.append(steps_done)
        if steps_done != 3:
            return None
        ops.time += 5 * 0.1  # the caller advances the model itself
        return np.array([[ops.time - 0.1 * (4 - i)] for i in range(5)])

    def abandon(rows):
        blocks.append(rows[:, 0].copy())
        return False

    out = integrate(ops, 12, 0.1, lambda: [ops.time], abandon=abandon, leap=leap, check_every=3)
    np.testing.assert_allclose(out[:, 0], 0.1 * np.arange(13))
    assert len(ops.attempts) == 12 - 5  # the leap's steps were not analysed
    assert asked == [3, 9]  # at every multiple of 3 steps done, not at the last step
    np.testing.assert_allclose(np.concatenate(blocks), 0.1 * np.arange(1, 13))
