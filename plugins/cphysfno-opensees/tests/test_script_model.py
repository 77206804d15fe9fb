"""``opensees-model``: a user's OpenSeesPy script as a structure, against OpenSeesPy run
directly on the same script (script_models.direct_run), OpenSees' eigen analysis, the
same model in other units, and the preprocessors."""

from __future__ import annotations

import numpy as np
import pytest
import script_models as sm

import cphysfno_core as cp
from cphysfno_core import GroundMotions
from cphysfno_core.plugin import LinearSystem, Stories
from cphysfno_core.testing import check_structure
from cphysfno_core.testing.physics import linear_response

FLOORS = [[11, 1], [21, 1]]


@pytest.fixture(scope="module")
def frame(frame_script):
    """The two-story frame with its gravity loads, 5 % Rayleigh damping in modes 1 and 2."""
    return cp.create(
        "structure", "opensees-model", script=str(frame_script), outputs=FLOORS,
        gravity="gravity", output_names=["floor-1", "floor-2"],
    )  # fmt: skip


@pytest.fixture(scope="module")
def strong():
    """Two records that take the frame's columns well past yield (peak 4 m/s^2)."""
    return sm.records(n=2, peak=4.0)


def test_the_structure_is_opensees_run_directly_on_the_script(frame, frame_script, strong):
    """Measured: 2e-15 relative L2 (the same analysis, step for step), displacements and
    absolute floor accelerations."""
    responses = frame.simulate(strong)
    u = responses.displacement
    absolute = responses.extras[cp.edp.ACCELERATION_EXTRA]
    assert u.shape == absolute.shape == (2, strong.n_steps, 2) and not responses.failures
    for i, record in enumerate(strong.acceleration):
        direct = sm.direct_run(frame_script, [(11, 1), (21, 1)], record, strong.dt,
                               gravity=True)  # fmt: skip
        assert np.all(sm.relative_l2(u[i], direct.displacement) < 1e-3)
        assert np.all(sm.relative_l2(absolute[i], direct.absolute_acceleration) < 1e-6)
    # the floors' absolute acceleration, not the relative one: PFA above the ground's
    pfa = cp.edp.compute(responses, frame, strong).pfa
    np.testing.assert_allclose(pfa[:, 1:], np.abs(absolute).max(axis=1))
    linear = cp.create("preprocessor", "els").fit(frame).transform(strong)
    assert np.all(sm.relative_l2(linear, u) > 0.2)  # the columns yield
    assert frame.constraints_handler == "Transformation"
    assert frame.output_names == ("floor-1", "floor-2")


def test_periods_are_opensees_eigen_at_the_gravity_state(frame, frame_script):
    expected = sm.eigen_periods(frame_script, 2, gravity=True)
    np.testing.assert_allclose(frame.periods(), expected, rtol=1e-3)
    np.testing.assert_allclose(frame.periods(), expected, rtol=1e-9)  # measured: round-off
    unloaded = sm.eigen_periods(frame_script, 2)
    assert frame.periods()[0] > unloaded[0] * 1.005  # the gravity loads soften it (P-Delta)


def test_at_one_percent_amplitude_els_is_the_simulation_within_its_time_step_error(frame, strong):
    """Measured on these records: ELS (the exact linear response) is 3.4 % and 2.1 %
    (relative L2, per floor) from the simulation at dt = 0.01 s, which is itself 3.4 % and
    2.0 % from the simulation of the same records at dt / 16 (Newmark's rule, and the
    analysis starting with zero relative acceleration); from that finer simulation, ELS is
    0.09 %."""
    small = GroundMotions(0.01 * strong.acceleration, strong.dt)
    z = cp.create("preprocessor", "els").fit(frame).transform(small)
    u = frame.simulate(small).displacement
    fine = frame.simulate(sm.finer(small, 16)).displacement[:, ::16]
    integration = sm.relative_l2(u, fine)
    assert np.all(sm.relative_l2(z, u) <= 1.1 * integration + 1e-3)
    assert np.all(integration < 0.05)
    assert np.all(sm.relative_l2(z, fine) < 0.2 * integration)


def test_the_relaxed_preprocessor_runs_the_model_on_a_coarse_grid(frame, strong):
    relaxed = cp.create("preprocessor", "relaxed", factor=5).fit(frame)
    z = relaxed.transform(strong)
    u = frame.simulate(strong).displacement
    assert z.shape == u.shape
    assert np.all(sm.relative_l2(z, u) < 0.5)
    coarse = frame.simulate(strong, dt=0.05)
    assert coarse.dt == 0.05 and coarse.displacement.shape == (2, 81, 2)


def test_modal_reduction_of_a_script_model_is_its_linear_modal_truncation(frame, strong):
    """Without a restoring force, all modes are the ELS; the first mode alone is not."""
    n_dof = frame.linear_system().n_dof
    full = cp.create("preprocessor", "modal", modes=n_dof).fit(frame).transform(strong)
    linear = cp.create("preprocessor", "els").fit(frame).transform(strong)
    assert np.all(sm.relative_l2(full, linear) < 1e-8)
    first = cp.create("preprocessor", "modal", modes=1).fit(frame).transform(strong)
    assert np.all(sm.relative_l2(first, linear) > 1e-4)


def test_check_structure_passes(frame):
    check_structure(frame)


def test_the_model_in_kips_and_inches_gives_the_model_in_metres(folder, frame, strong):
    """Measured: 2e-15 relative L2; the linear system is the same in m, its forces in kip."""
    script = sm.frame(folder, "frame_kip_in", length=1.0 / sm.METRES_PER_INCH,
                      force=1.0 / sm.NEWTONS_PER_KIP)  # fmt: skip
    us = cp.create(
        "structure", "opensees-model", script=str(script), outputs=FLOORS, gravity="gravity",
        length_unit="in",
    )  # fmt: skip
    expected, found = frame.simulate(strong), us.simulate(strong)
    assert np.all(sm.relative_l2(found.displacement, expected.displacement) < 1e-3)
    accelerations = [r.extras[cp.edp.ACCELERATION_EXTRA] for r in (found, expected)]
    assert np.all(sm.relative_l2(*accelerations) < 1e-6)  # m/s^2 from a model in inches
    np.testing.assert_allclose(us.periods(), frame.periods(), rtol=1e-9)
    theirs, ours = us.linear_system(), frame.linear_system()
    np.testing.assert_allclose(theirs.stiffness * sm.NEWTONS_PER_KIP, ours.stiffness, rtol=1e-9)
    np.testing.assert_allclose(theirs.mass * sm.NEWTONS_PER_KIP, ours.mass, rtol=1e-9)
    np.testing.assert_allclose(theirs.influence, ours.influence)
    np.testing.assert_allclose(theirs.output_map, ours.output_map)


def test_a_leaning_column_tied_in_chains_works_where_transformation_does_not(folder, strong):
    """The leaning column's nodes are tied to floor joints that are tied themselves:
    OpenSees' Transformation handler then ties the wrong DOFs (its gravity state and
    eigenvalues are another model's), so auto takes Penalty. The twin script ties them to
    the joints that carry the ties (no chain), which Transformation handles: measured
    2e-11 relative L2 between the two, and the twin's eigen periods to 1e-10."""
    chained = sm.frame(folder, "leaning_chain", leaning="chain")
    twin = sm.frame(folder, "leaning_direct", leaning="direct")
    model = cp.create(
        "structure", "opensees-model", script=str(chained), outputs=FLOORS, gravity="gravity"
    )
    assert model.constraints_handler == "Penalty"
    findings = dict(model.summary.checks)
    assert "gravity state differs" in findings["Transformation"]
    u = model.simulate(strong).displacement
    for i, record in enumerate(strong.acceleration):
        direct, periods, _ = sm.direct_run(twin, [(11, 1), (21, 1)], record, strong.dt,
                                        gravity=True)  # fmt: skip
        assert np.all(sm.relative_l2(u[i], direct) < 1e-3)
    np.testing.assert_allclose(model.periods(), periods, rtol=1e-3)
    unloaded = sm.eigen_periods(twin, 1)
    assert model.periods()[0] > 1.03 * unloaded[0]  # the leaning column's P-Delta
    with pytest.raises(cp.ConfigError, match="constraints = 'Transformation' does not work"):
        cp.create("structure", "opensees-model", script=str(chained), outputs=FLOORS,
                  gravity="gravity", constraints="Transformation").periods()  # fmt: skip


def test_massless_dofs_are_condensed_and_the_periods_are_opensees_eigen(folder, strong):
    """Rotations, vertical DOFs and the beams' hinge nodes carry no mass: the linear
    system keeps the four horizontal joint DOFs. The hinges are zeroLength springs, which
    OpenSees leaves out of the stiffness-proportional damping: the damping read from
    OpenSees is not a0 M + a1 K of the condensed system, and the simulation follows it."""
    script = sm.hinged(folder)
    model = cp.create("structure", "opensees-model", script=str(script), outputs=FLOORS)
    system = model.linear_system()
    assert model.summary.dofs == ((11, 1), (12, 1), (21, 1), (22, 1))
    np.testing.assert_allclose(model.periods(), sm.eigen_periods(script, 4), rtol=1e-3)
    direct = sm.direct_run(script, [(11, 1), (21, 1)], strong.acceleration[0], strong.dt)[0]
    assert np.all(sm.relative_l2(model.simulate(strong).displacement[0], direct) < 1e-3)
    factors = model.summary.damping_setup.rayleigh
    naive = factors.mass_factor * system.mass + factors.stiffness_factor * system.stiffness
    assert np.abs(system.damping - naive).max() > 1e-3 * np.abs(naive).max()
    small = GroundMotions(0.01 * strong.acceleration, strong.dt)
    fine = model.simulate(sm.finer(small, 16)).displacement[:, ::16]
    ours = sm.relative_l2(linear_response(system, small), fine)
    other = LinearSystem(system.mass, naive, system.stiffness, system.influence,
                            system.output_map)  # fmt: skip
    theirs = sm.relative_l2(linear_response(other, small), fine)
    assert np.all(ours < 0.2 * theirs), (ours, theirs)


RIGID = (
    sm.UNITS
    + '''
def build():
    """A cantilever whose tip carries, through a rigid arm, an eccentric mass with
    rotational inertia: the mass's horizontal and vertical motion follow the tip's
    rotation."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 0.0, 4.0)
    ops.node(3, 1.5, 4.5)
    ops.fix(1, 1, 1, 1)
    ops.geomTransf("Linear", 1)
    ops.element("elasticBeamColumn", 1, 1, 2, 0.02, 2.0e11, 5.0e-5, 1)
    ops.mass(3, 5.0e3, 5.0e3, 2.0e3)
    ops.rigidLink("beam", 2, 3)
'''
)


def test_a_rigid_link_is_eliminated_exactly(folder):
    script = sm.write(folder, "rigid", RIGID)
    model = cp.create("structure", "opensees-model", script=str(script),
                      outputs=[[3, 1], [3, 2]])  # fmt: skip
    assert model.constraints_handler == "Transformation"
    np.testing.assert_allclose(model.periods(), sm.eigen_periods(script, 3), rtol=1e-6)
    system = model.linear_system()
    assert system.n_dof == 3
    motion = sm.records(n=1, peak=1.0)
    direct = sm.direct_run(script, [(3, 1), (3, 2)], motion.acceleration[0], motion.dt)[0]
    u = model.simulate(motion).displacement[0]
    assert np.all(sm.relative_l2(u, direct) < 1e-3)


HELD_GRAVITY = '''

def gravity_held():
    """The eccentric mass's weight, analysed here with a Penalty handler and held with the
    time reset, as the OpenSees examples do."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(3, 0.0, -5.0e3 * 9.81, 0.0)
    ops.constraints("Penalty", 1.0e12, 1.0e12)
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-10, 25)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 0.1)
    ops.analysis("Static")
    assert ops.analyze(10) == 0
    ops.loadConst("-time", 0.0)
'''


@pytest.mark.parametrize("handler", ["Penalty", "Transformation"])
def test_a_gravity_state_analysed_and_held_by_the_script_is_not_analysed_again(folder, handler):
    """The idiom of the OpenSees examples (analyse, then loadConst -time 0.0) leaves the
    clock at 0: the held state is told by the model having moved, and a second analysis,
    which does not converge here under Penalty with the rigid link, is not run."""
    script = sm.write(folder, "rigid_held", RIGID + HELD_GRAVITY)
    model = cp.create("structure", "opensees-model", script=str(script),
                      outputs=[[3, 1], [3, 2]], gravity="gravity_held",
                      constraints=handler)  # fmt: skip
    motion = sm.records(n=1, peak=1.0)
    direct = sm.direct_run(script, [(3, 1), (3, 2)], motion.acceleration[0], motion.dt,
                           held_gravity="gravity_held").displacement  # fmt: skip
    u = model.simulate(motion).displacement[0]
    assert np.all(sm.relative_l2(u, direct) < 1e-3)


def test_the_stories_default_to_the_floors_over_the_ground(frame):
    stories = frame.stories()
    assert "stories" in frame.capabilities
    assert stories == Stories((None, 0), (0, 1), (3.0, 3.0))


def test_stories_from_heights_in_the_model_unit_or_from_node_pairs(frame_script):
    def stories(**params):
        return cp.create(
            "structure", "opensees-model", script=str(frame_script), outputs=FLOORS, **params
        ).stories()

    in_feet = stories(story_heights=[10.0, 12.0], length_unit="ft")
    assert in_feet.lower == (None, 0) and in_feet.upper == (0, 1)
    np.testing.assert_allclose(in_feet.heights_m, [3.048, 3.6576])
    assert stories(drift_pairs=[[1, 11], [11, 21]]) == Stories((None, 0), (0, 1), (3.0, 3.0))
    assert stories(drift_pairs=[[2, 21]]) == Stories((None,), (1,), (6.0,))
    with pytest.raises(cp.ConfigError, match="node 12 is neither an output"):
        stories(drift_pairs=[[12, 21]])


def test_outputs_at_one_elevation_are_each_a_story_over_the_ground(folder):
    script = sm.hinged(folder)
    model = cp.create(
        "structure", "opensees-model", script=str(script), outputs=[[21, 1], [22, 1], [11, 1]]
    )
    assert model.stories() == Stories((None,) * 3, (0, 1, 2), (6.0, 6.0, 3.0))


SELF_ANALYSED = '''

def gravity_analysed():
    """The gravity loads, analysed here (the time is left at 1)."""
    gravity()
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-10, 25)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 0.25)
    ops.analysis("Static")
    ops.analyze(4)


def gravity_held():
    """The same, held constant here with the time reset."""
    gravity_analysed()
    ops.loadConst("-time", 0.0)
'''


@pytest.mark.parametrize("function", ["gravity_analysed", "gravity_held"])
def test_a_gravity_function_may_analyse_its_loads_itself(folder, frame, strong, function):
    """Whether the function leaves the time at 1 or holds the loads itself, the model
    comes to the same gravity state as when the framework analyses the loads: measured
    4e-15 relative L2, the same periods."""
    script = folder / "frame_self_gravity.py"
    script.write_text(sm.FRAME.format(length=1.0, force=1.0, leaning=None) + SELF_ANALYSED)
    model = cp.create(
        "structure", "opensees-model", script=str(script), outputs=FLOORS, gravity=function
    )
    np.testing.assert_allclose(model.periods(), frame.periods(), rtol=1e-9)
    motion = GroundMotions(strong.acceleration[:1], strong.dt)
    expected = frame.simulate(motion).displacement
    assert np.all(sm.relative_l2(model.simulate(motion).displacement, expected) < 1e-6)


def test_a_record_past_the_collapse_drift_collapsed_and_the_others_are_unchanged(
    frame_script, strong
):
    """Of a batch of two yielding records and one three times as strong, only the strong
    one passes a collapse_drift set between their peak drift ratios: it is marked, holds
    its history up to the first sample past the limit and NaN after; the others are what
    they are alone."""
    params = {"script": str(frame_script), "outputs": FLOORS, "gravity": "gravity"}
    free = cp.create("structure", "opensees-model", collapse_drift=None, **params)
    batch = GroundMotions(
        np.stack([strong.acceleration[0], 3.0 * strong.acceleration[0], strong.acceleration[1]]),
        strong.dt,
    )
    unlimited = free.simulate(batch)
    assert not unlimited.collapsed.any()
    stories = free.stories()
    peaks = np.max(np.abs(stories.drifts(unlimited.displacement)) / stories.heights_m, axis=(1, 2))
    assert peaks[1] > 1.2 * max(peaks[0], peaks[2])
    limit = 0.5 * (peaks[1] + max(peaks[0], peaks[2]))
    limited = cp.create("structure", "opensees-model", collapse_drift=limit, **params)
    responses = limited.simulate(batch)
    assert responses.collapsed.tolist() == [False, True, False] and not responses.failures
    u, reference = responses.displacement, unlimited.displacement
    np.testing.assert_array_equal(u[[0, 2]], reference[[0, 2]])
    first = int(stories.first_past(reference[1:2], limit)[0])
    ratio = np.abs(stories.drifts(reference[1:2])) / np.asarray(stories.heights_m)
    assert ratio[0, first].max() > limit >= ratio[0, :first].max()
    np.testing.assert_array_equal(u[1, : first + 1], reference[1, : first + 1])
    assert np.isnan(u[1, first + 1 :]).all()
