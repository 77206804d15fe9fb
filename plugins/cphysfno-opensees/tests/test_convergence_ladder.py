"""The convergence ladder of OpenSees transients: its order, rung by rung, on a stand-in
for OpenSees; its settings and their errors; a real step that Newton cannot take; and
``opensees-model`` against OpenSeesPy run directly with the same ladder."""

from __future__ import annotations

import numpy as np
import pytest
import script_models as sm
from cphysfno_opensees.convergence import ConvergenceParams
from cphysfno_opensees.loader import import_opensees
from cphysfno_opensees.transient import AnalysisFailed, counting, integrate
from pydantic import ValidationError
from scripted_ops import ScriptedOps

import cphysfno_core as cp
from cphysfno_core import ConfigError

TEST = ("NormDispIncr", 1e-8, 10)
SMALL = ConvergenceParams(splits=(2, 4), algorithms=("Newton", "KrylovNewton", "Broyden"))
NO_LADDER = ConvergenceParams(splits=(), algorithms=(), looser_tolerance=1, looser_iterations=1)


def scripted(fails) -> ScriptedOps:
    """A stand-in for OpenSees with the caller's test :data:`TEST` set."""
    ops = ScriptedOps(fails)
    ops.test(*TEST)
    return ops


def at(time: float, ops: ScriptedOps) -> list[tuple[float, str, float]]:
    """The step, algorithm and tolerance of each attempt at ``time``."""
    return [(a.step, a.algorithm, a.tolerance) for a in ops.attempts if a.time == time]


def test_the_ladder_climbs_substeps_then_other_algorithms_then_a_looser_test():
    ops = scripted(lambda attempt: attempt.time == 0.1)
    with pytest.raises(AnalysisFailed) as caught:
        integrate(ops, 3, 0.1, lambda: [ops.time], test=TEST, convergence=SMALL)
    plain = [(0.05, "Newton"), (0.025, "Newton"),
             (0.1, "KrylovNewton"), (0.1, "Broyden"), (0.05, "KrylovNewton"),
             (0.05, "Broyden"), (0.025, "KrylovNewton"), (0.025, "Broyden")]  # fmt: skip
    looser = [(0.1, "Newton"), *plain]
    assert at(0.1, ops) == [(0.1, "Newton", 1e-8)] + [(*a, 1e-8) for a in plain] + [
        (*a, pytest.approx(1e-7)) for a in looser
    ]
    assert ops.current == ("Newton",) and ops.tested == TEST  # the caller's, set again
    assert caught.value.tried == (
        "Newton at dt = 0.1 s and dt/2, dt/4; KrylovNewton, Broyden at dt and dt/2, dt/4; "
        "all again with a looser test (tolerance x 10, iterations x 2)"
    )


def test_the_looser_test_is_used_only_after_every_other_rung_fails():
    ops = scripted(lambda attempt: attempt.time == 0.2 and attempt.tolerance < 1e-7)
    with counting() as recovery:
        out = integrate(ops, 4, 0.1, lambda: [ops.time], test=TEST, convergence=SMALL)
    np.testing.assert_allclose(out[:, 0], 0.1 * np.arange(5))
    tried = at(0.2, ops)
    assert len(tried) == 1 + 8 + 1  # the step, every rung of the plain test, then a looser
    assert [t[2] for t in tried[:-1]] == [1e-8] * 9 and tried[-1] == (0.1, "Newton", 1e-7)
    assert recovery.hardest == "a looser test"
    assert ops.attempts[-1] == (0.3, 0.1, "Newton", 1e-8)  # the caller's test is back


def test_a_rung_takes_the_step_on_from_where_the_one_before_stopped():
    # at t = 0.1 halves converge, but from 0.15 only quarters: half, then two quarters
    def fails(attempt):
        return (attempt.time == 0.1 and attempt.step > 0.05) or (
            attempt.time in (0.15, 0.175) and attempt.step > 0.025
        )

    ops = scripted(fails)
    with counting() as recovery:
        out = integrate(ops, 2, 0.1, lambda: [ops.time], test=TEST, convergence=SMALL)
    np.testing.assert_allclose(out[:, 0], [0.0, 0.1, 0.2])
    taken = [(a.time, a.step) for a in ops.attempts if not fails(a)]
    assert taken == [(0.0, 0.1), (0.1, 0.05), (0.15, 0.025), (0.175, 0.025)]
    assert {rung.words: n for rung, n in recovery.steps.items()} == {"substeps dt/4": 1}


def test_a_record_counts_each_recovered_step_under_its_rung_and_names_the_hardest():
    def fails(attempt):
        newton = attempt.algorithm == "Newton"
        return (attempt.time == 0.1 and attempt.step > 0.05) or (attempt.time == 0.3 and newton)

    ops = scripted(fails)
    with counting() as recovery:
        integrate(ops, 5, 0.1, lambda: [ops.time], test=TEST, convergence=SMALL)
    assert {rung.words: n for rung, n in recovery.steps.items()} == {
        "substeps dt/2": 1,
        "KrylovNewton": 1,
    }
    assert recovery.hardest == "KrylovNewton"
    with counting() as untouched:
        integrate(scripted(lambda attempt: False), 3, 0.1, lambda: [0.0])
    assert untouched.hardest is None


def test_without_a_ladder_the_first_failed_step_ends_the_analysis():
    ops = scripted(lambda attempt: attempt.time == 0.1)
    with pytest.raises(AnalysisFailed, match=r"after Newton at dt = 0.1 s$"):
        integrate(ops, 3, 0.1, lambda: [ops.time], test=TEST, convergence=NO_LADDER)
    assert len(at(0.1, ops)) == 1


def test_a_looser_test_multiplies_the_tolerances_and_the_iterations_it_has():
    ladder = ConvergenceParams(looser_tolerance=100.0, looser_iterations=3)
    assert ladder.loosened(("NormDispIncr", 1e-8, 10, 0, 2)) == (
        "NormDispIncr", pytest.approx(1e-6), 30, 0, 2)  # fmt: skip
    assert ladder.loosened(("NormDispAndUnbalance", 1e-6, 1e-3, 20)) == (
        "NormDispAndUnbalance", pytest.approx(1e-4), pytest.approx(0.1), 60)  # fmt: skip
    assert ladder.loosened(("FixedNumIter", 5)) == ("FixedNumIter", 15)


def test_an_algorithm_may_come_with_its_flags():
    ladder = ConvergenceParams(splits=(2,), algorithms=("Newton", "Newton -initial"))
    rungs = ladder.rungs(("Newton",), None)  # no test given: no looser rungs
    assert [(rung.algorithm, rung.substeps, rung.words) for rung in rungs] == [
        (("Newton",), 2, "substeps dt/2"),
        (("Newton", "-initial"), 1, "Newton -initial"),
        (("Newton", "-initial"), 2, "Newton -initial at dt/2"),
    ]


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"algorithms": ["Newtn"]}, "'Newtn' is not an iterative OpenSees algorithm"),
        ({"algorithms": ["Linear"]}, "'Linear' is not an iterative OpenSees algorithm"),
        ({"algorithms": ["Newton 2"]}, "after the name give only flags"),
        ({"algorithms": ["Broyden", "Broyden"]}, "each algorithm may appear once"),
        ({"splits": [4, 2]}, r"in increasing order \(2, 4, 10\), got \[4, 2\]"),
        ({"splits": [1, 2]}, "numbers of substeps of at least 2"),
        ({"looser_tolerance": 0.5}, "greater than or equal to 1"),
        ({"looser_iterations": 0}, "greater than or equal to 1"),
    ],
)
def test_a_bad_ladder_is_refused_naming_the_setting(tmp_path, settings, message):
    with pytest.raises(ValidationError, match=message):
        ConvergenceParams(**settings)
    setting = next(iter(settings))
    with pytest.raises(ConfigError, match=rf"opensees-model\.convergence\.{setting}: .*{message}"):
        cp.create("structure", "opensees-model", script=str(tmp_path / "model.py"),
                  outputs=[[2, 1]], convergence=settings)  # fmt: skip


def test_every_opensees_structure_has_the_ladder_in_its_parameters(tmp_path):
    structure = cp.create("structure", "opensees-model", script=str(tmp_path / "model.py"),
                          outputs=[[2, 1]], convergence={"splits": [2, 8]})  # fmt: skip
    assert structure.params.convergence == ConvergenceParams(splits=(2, 8))
    assert structure.get_params()["convergence"]["algorithms"][-1] == "Broyden"
    assert cp.create("structure", "sac9-frame").params.convergence == ConvergenceParams()


SPRINGS = '''
import openseespy.opensees as ops

SNAP = ("ElasticMultiLinear", 1, 0.0,
        "-strain", -1.0, -0.2, -0.025, -0.02, 0.0, 0.02, 0.025, 0.2, 1.0,
        "-stress", -5e5, -5e3, -5e3, -2e4, 0.0, 2e4, 5e3, 5e3, 5e5)


def build():
    """Two masses of 1 t on a chain of two snapping springs at the ground's elevation: each
    stiff (1e6 N/m) to 20 kN at 2 cm, down to 5 kN at 2.5 cm, flat to 20 cm, then
    hardening. Across the snap the tangent is -3e6 N/m, which Newmark's inertia term
    4 m / dt^2 outweighs at dt = 0.025 s but not at 0.05 s: Newton cannot take some steps
    of 0.05 s that it takes in halves."""
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(1, 0.0)
    ops.node(2, 0.0, "-mass", 1.0e3)
    ops.node(3, 0.0, "-mass", 1.0e3)
    ops.fix(1, 1)
    ops.uniaxialMaterial(*SNAP)
    ops.element("zeroLength", 1, 1, 2, "-mat", 1, "-dir", 1)
    ops.element("zeroLength", 2, 2, 3, "-mat", 1, "-dir", 1)
'''

OUTPUTS = [(2, 1), (3, 1)]


@pytest.fixture(scope="module")
def springs(tmp_path_factory):
    return sm.write(tmp_path_factory.mktemp("springs"), "springs", SPRINGS)


@pytest.fixture(scope="module")
def snapping():
    """Three records of 8 s at 0.05 s that take the springs across their snap."""
    return sm.records(n=3, n_steps=161, dt=0.05, peak=6.0)


def test_a_step_newton_cannot_take_in_opensees_is_taken_in_substeps(springs, snapping):
    ops = import_opensees()
    sm.load(springs).build()
    ops.timeSeries("Path", 1, "-dt", snapping.dt, "-values", *snapping.acceleration[0])
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test(*TEST)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    with counting() as recovery:
        u = integrate(ops, snapping.n_steps - 1, snapping.dt, lambda: [ops.nodeDisp(3, 1)],
                      test=TEST)  # fmt: skip
    ops.wipe()
    assert np.abs(u).max() > 0.025  # past the snap
    assert recovery.hardest == "substeps dt/2"
    assert all(rung.words == "substeps dt/2" for rung in recovery.steps)


def test_opensees_model_completes_what_a_direct_run_with_the_ladder_completes(springs, snapping):
    """Measured: round-off (the same analysis, step for step and rung for rung)."""
    ladder = ConvergenceParams(splits=(3, 6))
    structure = cp.create("structure", "opensees-model", script=str(springs),
                          outputs=[list(o) for o in OUTPUTS], collapse_drift=None,
                          convergence=ladder.model_dump())  # fmt: skip
    responses = structure.simulate(snapping)
    assert not responses.collapsed.any() and not responses.non_converged
    assert not responses.failures
    assert set(responses.recoveries.values()) == {"substeps dt/3"}  # the structure's ladder
    for i, record in enumerate(snapping.acceleration):
        with pytest.raises(AnalysisFailed):  # Newton alone does not get through
            sm.direct_run(springs, OUTPUTS, record, snapping.dt, convergence=NO_LADDER)
        with counting() as recovery:
            direct = sm.direct_run(springs, OUTPUTS, record, snapping.dt, convergence=ladder)
        assert responses.recoveries[i] == recovery.hardest
        assert np.all(sm.relative_l2(responses.displacement[i], direct.displacement) < 1e-6)
        assert np.abs(direct.displacement).max() > 0.025  # past the snap


def test_a_force_based_rc_frame_scaled_until_it_fails():
    """The fibre RC frame of examples/models/rc_frame.py (force-based columns, Concrete02
    and Steel02, P-Delta) under one record at 0.02 s scaled 25 and 35 times: the first
    needs substeps of dt/10 and completes past 16 % drift, as a direct run with the same
    ladder does, to round-off; the second stops converging, with or without cphysfno, and
    is a collapse only where a story has drifted past collapse_drift."""
    script = sm.EXAMPLES / "models" / "rc_frame.py"
    outputs = [(11, 1), (21, 1), (31, 1)]
    limit = 0.25
    structure = cp.create("structure", "opensees-model", script=str(script),
                          outputs=[list(o) for o in outputs], gravity="gravity",
                          collapse_drift=limit, workers=2)  # fmt: skip
    record = sm.records(n=1, n_steps=501, dt=0.02, peak=1.0, seed=3).acceleration[0]
    motions = cp.GroundMotions(np.stack([25.0 * record, 35.0 * record]), 0.02)
    responses = structure.simulate(motions)
    assert not responses.collapsed[0] and 0 not in responses.non_converged
    assert responses.recoveries[0] == "substeps dt/10"
    ladder = structure.params.convergence
    with counting() as recovery:
        direct = sm.direct_run(script, outputs, motions.acceleration[0], motions.dt,
                               gravity=True, convergence=ladder)  # fmt: skip
    assert recovery.hardest == responses.recoveries[0]
    assert np.all(sm.relative_l2(responses.displacement[0], direct.displacement) < 1e-6)
    stories = structure.stories()
    drift = stories.drifts(np.nan_to_num(responses.displacement[1:]))[0]
    peak = np.max(np.abs(drift) / np.asarray(stories.heights_m))
    assert responses.collapsed[1] == (peak > limit)
    assert responses.collapsed[1] or 1 in responses.non_converged
    with pytest.raises(AnalysisFailed):
        sm.direct_run(script, outputs, motions.acceleration[1], motions.dt, gravity=True,
                      convergence=ladder)  # fmt: skip
